//! The checks of a parsed scene: every number in range, no degenerate
//! shape, no two bodies overlapping at the start (the errors name the field,
//! the value and the range, as [`crate::validate`]'s).

use super::{BodySpec, PairLaw, RowSection, Scene, ShapeKind};
use crate::domino::{Preset, RowParams, RowSpec as DominoRow};
use crate::validate::overlap::{overlap, Placed};
use crate::validate::{check_count, check_open_low, check_range, fmt_value, row, EngineKind};
use crate::validate::{InputError, Naming, RunBudget};

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
/// let e = topple::rapier::scene::check_scene(&scene).unwrap_err();
/// assert_eq!(e.to_string(), "bodies[0].radius = -0.05: allowed 1e-6 ≤ bodies[0].radius ≤ 1e4");
/// ```
pub fn check_scene(s: &Scene) -> Result<(), InputError> {
    check_open_low("duration", s.duration, 0.0, 1e4)?;
    for k in 0..2 {
        check_range(&format!("gravity[{k}]"), s.gravity[k], -1e3, 1e3)?;
    }
    let v = &s.solver;
    check_range("solver.dt", v.dt, 1e-6, 1.0 / 30.0)?;
    let steps = (s.duration / v.dt).ceil();
    if steps > crate::validate::row::MAX_RAPIER_STEPS {
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
    if let Some(x) = v.rest_fraction {
        // above 1 the impact would end before it resolved what it started on
        check_range("solver.rest_fraction", x, 0.0, 1.0)?;
    }
    check_range("solver.closed_tolerance", v.closed_tolerance, 0.0, 1.0)?;
    for (i, m) in s.materials.iter().enumerate() {
        law(&format!("materials[{i}]"), &m.law())?;
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
/// [`crate::validate::row()`], named by their scene keys.
fn scene_row(r: &RowSection, s: &Scene) -> Result<(), InputError> {
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
