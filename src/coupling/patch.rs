//! λ-point line contact (paper Sec. 2.1, Eq. 10 as corrected in docs/model.md §5),
//! engine-agnostic.
//!
//! A collision library describes a flat face resting on a flat face by a
//! two-point manifold: the ends of the overlap of the two faces. The impact
//! model instead spreads λ equidistant points across that patch, end to end
//! (x_p = (p−1)/(λ−1)·L from one end, p = 1..λ), each with the pair's full
//! contact law, as the paper does for the base of a standing block.

/// One point of a contact manifold at the current positions (world frame, m).
///
/// ```
/// use topple::coupling::ManifoldPoint;
/// let p = ManifoldPoint { point: [0.0, 0.0], dist: -1e-6 }; // penetrating by 1 µm
/// assert!(p.dist < 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ManifoldPoint {
    /// Contact point (m), e.g. the midpoint of the two bodies' witness points.
    pub point: [f64; 2],
    /// Signed gap along the manifold normal (m); negative when penetrating.
    pub dist: f64,
}

/// How a manifold becomes resolver contact points.
///
/// ```
/// use topple::coupling::PatchRule;
/// let paper = PatchRule { lambda: 9, ..PatchRule::default() };
/// assert!(paper.closed_tolerance >= 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchRule {
    /// A point is closed (takes part in impacts) when its gap is at most this (m).
    pub closed_tolerance: f64,
    /// Number of λ points across a flat patch (≥ 2; the paper uses 9).
    pub lambda: usize,
    /// Two closed points closer than this (m) are one point, not a patch.
    pub min_patch_length: f64,
    /// Two closed points are a flat patch only if their gaps differ by at
    /// most this (m); a face tilted further touches with one corner.
    pub flat_tolerance: f64,
}

impl Default for PatchRule {
    fn default() -> Self {
        PatchRule {
            closed_tolerance: 1e-9,
            lambda: 9,
            min_patch_length: 1e-9,
            flat_tolerance: 1e-6,
        }
    }
}

/// Calls `emit(point, gap)` for each closed contact point of a manifold of up
/// to two points sharing one normal: λ points spread from the first to the
/// second point, gaps interpolated linearly, when both are closed, apart and
/// level (a flat face on a flat face); else every closed point on its own (a
/// corner, a ball). Open points (gap > tolerance) take no part.
///
/// ```
/// use topple::coupling::{for_each_contact_point, ManifoldPoint, PatchRule};
/// // the bottom face of a block 0.01 m thick resting on the ground
/// let face = [
///     ManifoldPoint { point: [-0.005, 0.0], dist: -1e-6 },
///     ManifoldPoint { point: [0.005, 0.0], dist: -1e-6 },
/// ];
/// let mut xs = Vec::new();
/// for_each_contact_point(&face, &PatchRule::default(), |p, _| xs.push(p[0]));
/// assert_eq!(xs.len(), 9);
/// assert!((xs[1] - xs[0] - 0.00125).abs() < 1e-15);
/// // a tilted block touches with its corner only
/// let corner = [face[0], ManifoldPoint { point: [0.005, 0.001], dist: 0.001 }];
/// let mut n = 0;
/// for_each_contact_point(&corner, &PatchRule::default(), |_, _| n += 1);
/// assert_eq!(n, 1);
/// ```
#[inline]
pub fn for_each_contact_point(
    points: &[ManifoldPoint],
    rule: &PatchRule,
    mut emit: impl FnMut([f64; 2], f64),
) {
    let closed = |p: &ManifoldPoint| p.dist <= rule.closed_tolerance;
    if let [a, b] = points {
        let len = (b.point[0] - a.point[0]).hypot(b.point[1] - a.point[1]);
        let level = (a.dist - b.dist).abs() <= rule.flat_tolerance;
        if closed(a) && closed(b) && level && len > rule.min_patch_length && rule.lambda >= 2 {
            let last = (rule.lambda - 1) as f64;
            for p in 0..rule.lambda {
                let s = p as f64 / last;
                emit(
                    [
                        a.point[0] + s * (b.point[0] - a.point[0]),
                        a.point[1] + s * (b.point[1] - a.point[1]),
                    ],
                    a.dist + s * (b.dist - a.dist),
                );
            }
            return;
        }
    }
    let mut first: Option<[f64; 2]> = None;
    for p in points.iter().filter(|p| closed(p)) {
        // Two coincident closed points are one contact.
        if let Some(q) = first
            && (p.point[0] - q[0]).hypot(p.point[1] - q[1]) <= rule.min_patch_length
        {
            continue;
        }
        first = Some(p.point);
        emit(p.point, p.dist);
    }
}
