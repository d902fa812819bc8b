//! The `[row]` of a scene: a domino row of [`crate::domino`] (Table 1
//! presets, the ideal material, overrides, the ground model) expanded into
//! materials, pair rules, a ground and boxes.

use crate::domino::{Ground, Preset, RowParams, RowSpec as DominoRow};

use super::error::{SceneError, SceneResult};
use super::format::{
    BodySpec, GroundSpec, MaterialSpec, PairLaw, PairSpec, RowSection, Scene, ShapeKind,
};
use crate::input::InputError;

/// Friction coefficient that stands for "never slips" in Rapier's smooth
/// phase on a [`Ground::NoSlip`] row (inside topple's impacts the friction
/// is unbounded, [`crate::impact::ContactMaterial::no_slip`]). The ratio of
/// tangential to normal force at the pivot of a toppling block is of order 1
/// (at most (s + d)/h-ish while it leans on its neighbour), so a bound of
/// 10³ is never reached: the contact sticks whenever it is closed.
pub const NO_SLIP_FRICTION: f64 = 1e3;

/// The row's parameters: the Table 1 preset of [`crate::domino::Preset`],
/// then `ideal` (Sec. 3.2), then the overrides, the scene's gravity (m/s²)
/// and the block mass (the row's `mass`, else `density` × h × d).
///
/// ```
/// use topple::rapier::scene::{row_params, RowSection};
/// let row: RowSection = toml::from_str("preset = \"T\"\nn = 3\nspacing = 0.3\nideal = true").unwrap();
/// let p = row_params(&row, 9.81).unwrap();
/// assert_eq!((p.mu1, p.e1, p.mu2), (0.0, 0.0, 0.9));
/// assert_eq!(p.block.height, 0.08);
/// ```
pub fn row_params(row: &RowSection, gravity: f64) -> SceneResult<RowParams> {
    let mut p = row
        .preset
        .parse::<Preset>()
        .map_err(|e| SceneError::Invalid(InputError::new("row.preset", e.value, e.allowed)))?
        .params();
    if row.ideal {
        p = p.ideal();
    }
    let o = &row.overrides;
    let set = |x: &mut f64, v: Option<f64>| {
        if let Some(v) = v {
            *x = v;
        }
    };
    set(&mut p.block.height, o.height);
    set(&mut p.block.thickness, o.thickness);
    set(&mut p.mu1, o.mu1);
    set(&mut p.mu1_stick, o.mu1_stick.or(o.mu1));
    set(&mut p.e1, o.e1);
    set(&mut p.k1, o.k1);
    set(&mut p.mu2, o.mu2);
    set(&mut p.mu2_stick, o.mu2_stick.or(o.mu2));
    set(&mut p.e2, o.e2);
    set(&mut p.k2, o.k2);
    set(&mut p.alpha, o.alpha);
    set(&mut p.impact_friction_factor, o.impact_friction_factor);
    p.block.mass = row
        .mass
        .unwrap_or(row.density * p.block.height * p.block.thickness);
    p.gravity = gravity;
    p.ground = row.ground;
    Ok(p)
}

/// Adds the row's materials ("block", "ground"), pair rules, ground and
/// blocks ("block1" …) to a scene; returns the row as the domino layer
/// sees it ([`row_params`] and the scene's spacing, n and push). Blocks
/// stand on the ground at y = 0, block i (from 1) centred at
/// x = (i − 1)(s + d); block 1 rotates clockwise about its front bottom edge
/// at θ̇ = push/t̄. A [`Ground::NoSlip`] row's block–ground pair is
/// `no_slip`.
pub fn expand_row(scene: &mut Scene, row: &RowSection) -> SceneResult<DominoRow> {
    let g = scene.gravity[0].hypot(scene.gravity[1]);
    let p = row_params(row, g)?;
    let domino = DominoRow::new(p, row.spacing * p.block.height, row.n, row.push);
    let law = |mu, mus, e, k, factor| PairLaw {
        stiffness: k,
        exponent: p.alpha,
        restitution: e,
        friction: mu,
        stick_friction: mus,
        impact_friction_factor: factor,
        no_slip: false,
    };
    let factor = p.impact_friction_factor;
    let block = law(p.mu1, p.mu1_stick, p.e1, p.k1, factor);
    let ground = match p.ground {
        Ground::Coulomb => law(p.mu2, p.mu2_stick, p.e2, p.k2, factor),
        Ground::NoSlip => PairLaw {
            no_slip: true,
            ..law(NO_SLIP_FRICTION, NO_SLIP_FRICTION, p.e2, p.k2, 1.0)
        },
    };
    let material = |name: &str, l: &PairLaw| MaterialSpec {
        name: name.into(),
        stiffness: l.stiffness,
        exponent: l.exponent,
        restitution: l.restitution,
        friction: l.friction,
        stick_friction: l.stick_friction,
        impact_friction_factor: l.impact_friction_factor,
    };
    scene.materials.push(material("block", &block));
    scene.materials.push(material("ground", &ground));
    scene.pairs.push(PairSpec {
        materials: ["block".into(), "block".into()],
        law: block,
    });
    scene.pairs.push(PairSpec {
        materials: ["block".into(), "ground".into()],
        law: ground,
    });
    scene.ground = Some(GroundSpec {
        y: 0.0,
        material: "ground".into(),
    });
    let (h, d) = (p.block.height, p.block.thickness);
    for i in 0..row.n {
        let (velocity, angular_velocity) = if i == 0 {
            domino.initial_velocity()
        } else {
            ([0.0, 0.0], 0.0)
        };
        scene.bodies.push(BodySpec {
            name: Some(format!("block{}", i + 1)),
            shape: ShapeKind::Box,
            size: Some([d, h]),
            radius: None,
            position: domino.centre(i),
            angle: 0.0,
            velocity,
            angular_velocity,
            density: None,
            mass: Some(p.block.mass),
            fixed: false,
            material: "block".into(),
        });
    }
    Ok(domino)
}
