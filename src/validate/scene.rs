//! A TOML scene: one-line parse errors, every number in range, no
//! degenerate shape, no two bodies overlapping at the start.

use super::{check_count, check_open_low, check_range, fmt_value, row, EngineKind, InputError};
use super::{Naming, RunBudget};
use crate::domino::{Preset, RowParams, RowSpec as DominoRow};
use crate::rapier::scene::{BodySpec, PairLaw, RowSpec, Scene, ShapeKind};

/// A file that does not parse: where and why, on one line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct SyntaxError {
    /// The file as named by the user.
    pub file: String,
    /// Line, from 1.
    pub line: usize,
    /// Column (characters), from 1.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

/// Parses TOML text; an error names the file, line and column of its first
/// character, and toml's message, on one line (toml's own display spreads
/// over several lines, with a caret that a one-line report misplaces).
///
/// ```
/// use topple::validate::parse_toml;
/// let e = parse_toml::<topple::rapier::scene::Scene>("duration = 1\nduration = 2\n", "s.toml").unwrap_err();
/// assert!(e.to_string().starts_with("s.toml:2:1: "), "{e}");
/// ```
#[cfg(feature = "scene-files")]
pub fn parse_toml<T: serde::de::DeserializeOwned>(
    text: &str,
    file: &str,
) -> Result<T, SyntaxError> {
    toml::from_str(text).map_err(|e: toml::de::Error| {
        let start = e.span().map(|s| s.start).unwrap_or(0).min(text.len());
        let before = &text[..floor_char(text, start)];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        SyntaxError {
            file: file.to_string(),
            line,
            column,
            message: e.message().trim().replace('\n', " "),
        }
    })
}

#[cfg(feature = "scene-files")]
fn floor_char(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// Largest |coordinate| (m) or |speed| (m/s) in a scene.
const MAX_MAGNITUDE: f64 = 1e6;
/// Bodies in a scene besides its row.
const MAX_BODIES: usize = 100_000;

/// Checks a parsed scene before anything is built. Overlap: two bodies whose
/// shapes intersect by more than 10⁻⁶ of the smaller one's size (touching is
/// fine) are refused, as is a body reaching into the ground.
///
/// ```
/// let scene: topple::rapier::scene::Scene = toml::from_str(r#"
///     duration = 1.0
///     [[materials]]
///     name = "m"
///     stiffness = 1e9
///     [[bodies]]
///     shape = "ball"
///     radius = -0.05
///     position = [0.0, 1.0]
///     material = "m"
/// "#).unwrap();
/// let e = topple::validate::scene(&scene).unwrap_err();
/// assert_eq!(e.to_string(), "bodies[0].radius = -0.05: allowed 1e-6 ≤ bodies[0].radius ≤ 1e4");
/// ```
pub fn scene(s: &Scene) -> Result<(), InputError> {
    check_open_low("duration", s.duration, 0.0, 1e4)?;
    for k in 0..2 {
        check_range(&format!("gravity[{k}]"), s.gravity[k], -1e3, 1e3)?;
    }
    let v = &s.solver;
    check_range("solver.dt", v.dt, 1e-6, 1.0 / 30.0)?;
    let steps = (s.duration / v.dt).ceil();
    if steps > super::row::MAX_RAPIER_STEPS {
        return Err(InputError::new(
            "duration",
            fmt_value(s.duration),
            format!("duration / solver.dt ≤ 1e7 Rapier steps (this scene would take {steps:.3e})"),
        ));
    }
    if let Some(l) = v.length_unit {
        check_open_low("solver.length_unit", l, 0.0, 1e4)?;
    }
    if let Some(h) = v.contact_hertz {
        check_open_low("solver.contact_hertz", h, 0.0, 1e6)?;
    }
    check_count("solver.iterations", v.iterations, 1, 1000)?;
    if let Some(x) = v.impulse_step {
        check_open_low("solver.impulse_step", x, 0.0, 1.0)?;
    }
    if let Some(x) = v.tolerance {
        check_range("solver.tolerance", x, 1e-12, 1e-1)?;
    }
    check_count("solver.lambda", v.lambda, 2, 100)?;
    if let Some(x) = v.min_approach_speed {
        check_range("solver.min_approach_speed", x, 0.0, 1e3)?;
    }
    if let Some(x) = v.max_substep {
        check_range("solver.max_substep", x, 0.0, 1e3)?;
        if x > 0.0 {
            // at most 1,000 sub-steps per step
            check_range("solver.dt / solver.max_substep", v.dt / x, 0.0, 1e3)?;
        }
    }
    check_range("solver.closed_tolerance", v.closed_tolerance, 0.0, 1.0)?;
    for (i, m) in s.materials.iter().enumerate() {
        law(
            &format!("materials[{i}]"),
            &PairLaw {
                stiffness: m.stiffness,
                exponent: m.exponent,
                restitution: m.restitution,
                friction: m.friction,
                stick_friction: m.stick_friction,
                impact_friction_factor: m.impact_friction_factor,
                no_slip: false,
            },
        )?;
    }
    for (i, p) in s.pairs.iter().enumerate() {
        law(&format!("pairs[{i}]"), &p.law)?;
    }
    if let Some(g) = &s.ground {
        check_range("ground.y", g.y, -MAX_MAGNITUDE, MAX_MAGNITUDE)?;
    }
    check_count("bodies (their number)", s.bodies.len(), 0, MAX_BODIES)?;
    let shapes = s
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| body(i, b))
        .collect::<Result<Vec<_>, _>>()?;
    no_overlap(&shapes, s.ground.as_ref().map(|g| g.y))?;
    if let Some(r) = &s.row {
        scene_row(r, s)?;
    }
    Ok(())
}

fn law(at: &str, l: &PairLaw) -> Result<(), InputError> {
    check_open_low(&format!("{at}.stiffness"), l.stiffness, 0.0, 1e18)?;
    check_range(&format!("{at}.exponent"), l.exponent, 1.0, 3.0)?;
    check_range(&format!("{at}.restitution"), l.restitution, 0.0, 1.0)?;
    check_range(&format!("{at}.friction"), l.friction, 0.0, 5.0)?;
    check_range(&format!("{at}.stick_friction"), l.stick_friction, 0.0, 5.0)?;
    check_range(
        &format!("{at}.impact_friction_factor"),
        l.impact_friction_factor,
        0.0,
        1.0,
    )?;
    Ok(())
}

/// A body's shape placed in the plane, for the overlap test.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Placed {
    index: usize,
    centre: [f64; 2],
    angle: f64,
    /// Half extents of a box, or [r, r] of a ball.
    half: [f64; 2],
    ball: bool,
}

impl Placed {
    /// Radius of the circle around the shape.
    fn reach(&self) -> f64 {
        if self.ball {
            self.half[0]
        } else {
            self.half[0].hypot(self.half[1])
        }
    }
    fn size(&self) -> f64 {
        self.half[0].min(self.half[1])
    }
}

fn body(i: usize, b: &BodySpec) -> Result<Placed, InputError> {
    let at = |k: &str| format!("bodies[{i}].{k}");
    let m = MAX_MAGNITUDE;
    for k in 0..2 {
        check_range(&at(&format!("position[{k}]")), b.position[k], -m, m)?;
        check_range(&at(&format!("velocity[{k}]")), b.velocity[k], -m, m)?;
    }
    check_range(&at("angle"), b.angle, -m, m)?;
    check_range(&at("angular_velocity"), b.angular_velocity, -m, m)?;
    if let Some(d) = b.density {
        check_open_low(&at("density"), d, 0.0, 1e6)?;
    }
    if let Some(mass) = b.mass {
        check_open_low(&at("mass"), mass, 0.0, 1e9)?;
    }
    let (half, ball) = match b.shape {
        ShapeKind::Ball => {
            let Some(r) = b.radius else {
                return Err(InputError::new(
                    at("radius"),
                    "missing",
                    "a radius for a ball",
                ));
            };
            let r = check_range(&at("radius"), r, 1e-6, 1e4)?;
            ([r, r], true)
        }
        ShapeKind::Box => {
            let Some(size) = b.size else {
                return Err(InputError::new(
                    at("size"),
                    "missing",
                    "[width, height] for a box",
                ));
            };
            for (k, v) in size.iter().enumerate() {
                check_range(&at(&format!("size[{k}]")), *v, 1e-6, 1e4)?;
            }
            ([0.5 * size[0], 0.5 * size[1]], false)
        }
    };
    Ok(Placed {
        index: i,
        centre: b.position,
        angle: b.angle,
        half,
        ball,
    })
}

/// Depth (m) by which two shapes overlap; ≤ 0 when they do not.
fn overlap(a: &Placed, b: &Placed) -> f64 {
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

/// Refuses overlapping bodies (sweep over x by bounding circles) and bodies
/// below the ground's top face.
fn no_overlap(shapes: &[Placed], ground: Option<f64>) -> Result<(), InputError> {
    let mut order: Vec<&Placed> = shapes.iter().collect();
    order.sort_by(|a, b| (a.centre[0] - a.reach()).total_cmp(&(b.centre[0] - b.reach())));
    for (k, a) in order.iter().enumerate() {
        let right = a.centre[0] + a.reach();
        for b in order[k + 1..].iter() {
            if b.centre[0] - b.reach() > right {
                break;
            }
            let depth = overlap(a, b);
            if depth > 1e-6 * a.size().min(b.size()) {
                let (i, j) = (a.index.min(b.index), a.index.max(b.index));
                return Err(InputError::new(
                    format!("bodies[{i}] and bodies[{j}]"),
                    format!("overlapping by {} m", fmt_value(depth)),
                    "bodies that at most touch at the start",
                ));
            }
        }
        if let Some(y) = ground {
            let lowest = if a.ball {
                a.centre[1] - a.half[0]
            } else {
                let (s, c) = a.angle.sin_cos();
                a.centre[1] - a.half[0] * s.abs() - a.half[1] * c.abs()
            };
            if y - lowest > 1e-6 * a.size() {
                return Err(InputError::new(
                    format!("bodies[{}]", a.index),
                    format!("{} m below the ground's top face", fmt_value(y - lowest)),
                    "bodies at or above the ground (ground.y)",
                ));
            }
        }
    }
    Ok(())
}

/// The row of a scene: its preset and every override in the ranges of
/// [`super::row()`], named by their scene keys.
fn scene_row(r: &RowSpec, s: &Scene) -> Result<(), InputError> {
    let preset = match r.preset.to_ascii_uppercase().as_str() {
        "X" => Preset::X,
        "T" => Preset::T,
        "P" => Preset::P,
        _ => {
            return Err(InputError::new(
                "row.preset",
                format!("{:?}", r.preset),
                "\"X\", \"T\" or \"P\"",
            ))
        }
    };
    let mut p: RowParams = preset.params();
    if r.ideal {
        p = p.ideal();
    }
    let o = &r.overrides;
    let set = |x: &mut f64, v: Option<f64>| {
        if let Some(v) = v {
            *x = v;
        }
    };
    set(&mut p.block.height, o.height);
    set(&mut p.block.thickness, o.thickness);
    if let Some(mu) = o.mu1 {
        p.mu1 = mu;
        p.mu1_stick = o.mu1_stick.unwrap_or(mu);
    }
    set(&mut p.mu1_stick, o.mu1_stick);
    if let Some(mu) = o.mu2 {
        p.mu2 = mu;
        p.mu2_stick = o.mu2_stick.unwrap_or(mu);
    }
    set(&mut p.mu2_stick, o.mu2_stick);
    set(&mut p.e1, o.e1);
    set(&mut p.e2, o.e2);
    set(&mut p.k1, o.k1);
    set(&mut p.k2, o.k2);
    set(&mut p.alpha, o.alpha);
    set(&mut p.impact_friction_factor, o.impact_friction_factor);
    p.lambda_points = s.solver.lambda;
    check_open_low("row.density", r.density, 0.0, 1e6)?;
    p.block.mass = match r.mass {
        Some(m) => m,
        None => r.density * p.block.height * p.block.thickness,
    };
    if !(p.block.mass.is_finite() && p.block.mass > 0.0 && p.block.mass <= 1e6) {
        return Err(InputError::new(
            "row.mass",
            fmt_value(p.block.mass),
            "0 < row.mass ≤ 1e6 kg",
        ));
    }
    p.gravity = s.gravity[0].hypot(s.gravity[1]);
    if p.gravity.is_nan() || p.gravity <= 0.0 {
        return Err(InputError::new(
            "gravity",
            "[0, 0]",
            "a non-zero gravity for a domino row",
        ));
    }
    let spec = DominoRow::new(p, r.spacing * p.block.height, r.n, r.push);
    let budget = RunBudget {
        engine: EngineKind::Rapier,
        dt: Some(s.solver.dt),
        tolerance: None,
        max_time: Some(s.duration),
        wall_limit: None,
    };
    row(&spec, &budget, Naming::Scene)
}
