//! Overlap depth of placed balls and boxes (m): the scene check's "no two
//! bodies overlap at the start" and the stress sweep's penetration check.
//! Separating axes for box against box, the distance to the box for a ball.

/// A body's shape placed in the plane, for the overlap test.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Placed {
    pub(crate) index: usize,
    pub(crate) centre: [f64; 2],
    pub(crate) angle: f64,
    /// Half extents of a box, or [r, r] of a ball.
    pub(crate) half: [f64; 2],
    pub(crate) ball: bool,
}

impl Placed {
    /// Radius of the circle around the shape.
    pub(crate) fn reach(&self) -> f64 {
        if self.ball {
            self.half[0]
        } else {
            self.half[0].hypot(self.half[1])
        }
    }
    pub(crate) fn size(&self) -> f64 {
        self.half[0].min(self.half[1])
    }
}

/// Depth (m) by which two shapes overlap; ≤ 0 when they do not.
pub(crate) fn overlap(a: &Placed, b: &Placed) -> f64 {
    let d = [b.centre[0] - a.centre[0], b.centre[1] - a.centre[1]];
    match (a.ball, b.ball) {
        (true, true) => a.half[0] + b.half[0] - d[0].hypot(d[1]),
        (true, false) => ball_box(a, b),
        (false, true) => ball_box(b, a),
        (false, false) => box_box(a, b),
    }
}

/// Ball against box: radius minus the distance from the ball's centre to the
/// box (negative distance inside the box).
fn ball_box(ball: &Placed, bx: &Placed) -> f64 {
    let (s, c) = bx.angle.sin_cos();
    let d = [ball.centre[0] - bx.centre[0], ball.centre[1] - bx.centre[1]];
    // the ball's centre in the box's frame
    let p = [c * d[0] + s * d[1], -s * d[0] + c * d[1]];
    let q = [p[0].abs() - bx.half[0], p[1].abs() - bx.half[1]];
    let outside = q[0].max(0.0).hypot(q[1].max(0.0));
    let inside = q[0].max(q[1]).min(0.0);
    ball.half[0] - (outside + inside)
}

/// Depth (m) by which two boxes (centre, angle, half extents) overlap, ≤ 0
/// when they do not (the stress sweep's penetration check).
#[cfg_attr(not(all(feature = "f32", feature = "f64")), allow(dead_code))]
pub(crate) fn box_overlap(a: ([f64; 2], f64), b: ([f64; 2], f64), half: [f64; 2]) -> f64 {
    let placed = |(centre, angle): ([f64; 2], f64)| Placed {
        index: 0,
        centre,
        angle,
        half,
        ball: false,
    };
    box_box(&placed(a), &placed(b))
}

/// Box against box by separating axes: the least overlap of their
/// projections on the four face normals (≤ 0 if some axis separates them).
fn box_box(a: &Placed, b: &Placed) -> f64 {
    let axes = |p: &Placed| {
        let (s, c) = p.angle.sin_cos();
        [[c, s], [-s, c]]
    };
    let (aa, ba) = (axes(a), axes(b));
    let radius = |p: &Placed, ax: &[[f64; 2]; 2], n: [f64; 2]| {
        p.half[0] * (ax[0][0] * n[0] + ax[0][1] * n[1]).abs()
            + p.half[1] * (ax[1][0] * n[0] + ax[1][1] * n[1]).abs()
    };
    let d = [b.centre[0] - a.centre[0], b.centre[1] - a.centre[1]];
    let mut least = f64::INFINITY;
    for n in aa.iter().chain(ba.iter()) {
        let depth = radius(a, &aa, *n) + radius(b, &ba, *n) - (d[0] * n[0] + d[1] * n[1]).abs();
        least = least.min(depth);
    }
    least
}
