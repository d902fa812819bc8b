//! From a [`Scene`] to a Rapier world with topple (or its native twin).

use std::collections::HashMap;

use anyhow::{bail, Context};
use rapier2d_f64::prelude::{
    ColliderBuilder, ColliderHandle, IntegrationParameters, PhysicsWorld, RigidBodyBuilder,
    RigidBodyHandle, Vector,
};

use crate::impact::{ContactMaterial, ImpactSettings};
use crate::rapier::{ImpactReport, PairMaterial, PatchRule, ToppleRapier, ToppleSettings};

use super::format::{PairLaw, Scene, ShapeKind, SolverSpec};
use super::row::{expand_row, Preset};

/// Who resolves impacts.
///
/// ```
/// use topple::rapier::scene::Engine;
/// assert_eq!(Engine::RapierNative.name(), "rapier-native");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Engine {
    /// Rapier with topple's LZB impacts and λ-point contact.
    #[default]
    Rapier,
    /// Rapier alone (same materials per pair, Rapier's own restitution).
    RapierNative,
}

impl Engine {
    /// The name used on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Rapier => "rapier",
            Engine::RapierNative => "rapier-native",
        }
    }
}

/// A row's geometry, kept for the wave measures.
#[derive(Clone, Debug)]
pub struct RowInfo {
    /// The preset used.
    pub preset: Preset,
    /// Gap between faces s (m).
    pub spacing: f64,
    /// The blocks' colliders, in row order.
    pub colliders: Vec<ColliderHandle>,
}

/// A built scene, ready to step.
pub struct SceneWorld {
    /// The Rapier world.
    pub world: PhysicsWorld,
    /// topple (in native mode it only supplies per-pair materials).
    pub topple: ToppleRapier,
    /// Body names, handles and colliders in scene order (ground excluded).
    pub bodies: Vec<(String, RigidBodyHandle, ColliderHandle)>,
    /// The row, if the scene has one.
    pub row: Option<RowInfo>,
    /// Engine.
    pub engine: Engine,
    /// Simulated time (s).
    pub time: f64,
}

fn pair_material(l: &PairLaw) -> PairMaterial {
    PairMaterial::from_table(
        ContactMaterial {
            stiffness: l.stiffness,
            exponent: l.exponent,
            restitution: l.restitution,
            friction: l.friction,
            stick_friction: l.stick_friction,
        },
        l.friction,
        l.stick_friction,
        l.restitution,
        l.impact_friction_factor,
    )
}

/// topple's settings from a scene's solver section and gravity (m/s²).
pub fn topple_settings(s: &SolverSpec, gravity: [f64; 2]) -> ToppleSettings {
    let g = gravity[0].hypot(gravity[1]);
    ToppleSettings {
        impact: match s.tolerance {
            Some(t) => ImpactSettings::adaptive(t),
            None => ImpactSettings::fixed(s.impulse_step),
        },
        patch: PatchRule {
            closed_tolerance: s.closed_tolerance,
            lambda: s.lambda,
            ..PatchRule::default()
        },
        min_approach_speed: s.min_approach_speed.unwrap_or((2.0 * g * s.dt).max(1e-3)),
        max_group_hops: s.max_group_hops,
    }
}

/// Builds the world of a scene for an engine.
///
/// ```
/// use topple::rapier::scene::{build, Engine, Scene};
/// let scene: Scene = toml::from_str(r#"
///     duration = 0.1
///     [row]
///     preset = "T"
///     n = 3
///     spacing = 0.35
/// "#).unwrap();
/// let mut sw = build(&scene, Engine::Rapier).unwrap();
/// assert_eq!(sw.bodies.len(), 3);
/// sw.step().unwrap();
/// assert!(sw.kinetic_energy() > 0.0); // block 1 is pushed
/// ```
pub fn build(scene: &Scene, engine: Engine) -> anyhow::Result<SceneWorld> {
    let mut scene = scene.clone();
    let row = match scene.row.clone() {
        Some(r) => Some((expand_row(&mut scene, &r)?, r)),
        None => None,
    };
    let s = &scene.solver;
    if !(s.dt > 0.0 && s.length_unit > 0.0 && scene.duration >= 0.0) {
        bail!("dt and length_unit must be > 0 and duration >= 0");
    }
    let mut world = PhysicsWorld {
        gravity: Vector::new(scene.gravity[0], scene.gravity[1]),
        integration_parameters: IntegrationParameters {
            dt: s.dt,
            length_unit: s.length_unit,
            num_solver_iterations: s.iterations.max(1),
            contact_recycling: s.contact_recycling,
            ..IntegrationParameters::default()
        },
        ..PhysicsWorld::default()
    };
    let mut topple = match engine {
        Engine::Rapier => ToppleRapier::new(topple_settings(s, scene.gravity)),
        Engine::RapierNative => ToppleRapier::native(),
    };
    let mut ids = HashMap::new();
    for m in &scene.materials {
        let law = PairLaw {
            stiffness: m.stiffness,
            exponent: m.exponent,
            restitution: m.restitution,
            friction: m.friction,
            stick_friction: m.stick_friction,
            impact_friction_factor: m.impact_friction_factor,
        };
        if !(0.0..=1.0).contains(&m.restitution) || m.stiffness <= 0.0 || m.friction < 0.0 {
            bail!(
                "material {:?}: need stiffness > 0, restitution in [0, 1], friction >= 0",
                m.name
            );
        }
        if ids
            .insert(m.name.clone(), topple.add_material(pair_material(&law)))
            .is_some()
        {
            bail!("material {:?} defined twice", m.name);
        }
    }
    let id = |name: &str| {
        ids.get(name)
            .copied()
            .with_context(|| format!("unknown material {name:?}"))
    };
    for p in &scene.pairs {
        topple.set_pair_material(
            id(&p.materials[0])?,
            id(&p.materials[1])?,
            pair_material(&p.law),
        );
    }
    if let Some(g) = &scene.ground {
        let m = id(&g.material)?;
        let (_, c) = world.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, g.y - 1.0)),
            ColliderBuilder::cuboid(1.0e3, 1.0),
        );
        topple.manage(&mut world.colliders, c, m);
    }
    let mut bodies = Vec::new();
    for (i, b) in scene.bodies.iter().enumerate() {
        let name = b.name.clone().unwrap_or_else(|| i.to_string());
        let m = id(&b.material)?;
        let mut collider = match b.shape {
            ShapeKind::Box => {
                let [w, h] = b
                    .size
                    .with_context(|| format!("body {name}: a box needs size"))?;
                ColliderBuilder::cuboid(0.5 * w, 0.5 * h)
            }
            ShapeKind::Ball => {
                let r = b
                    .radius
                    .with_context(|| format!("body {name}: a ball needs radius"))?;
                ColliderBuilder::ball(r)
            }
        };
        collider = match (b.mass, b.density) {
            (Some(mass), _) => collider.mass(mass),
            (None, d) => collider.density(d.unwrap_or(1000.0)),
        };
        let body = if b.fixed {
            RigidBodyBuilder::fixed()
        } else {
            RigidBodyBuilder::dynamic()
        }
        .translation(Vector::new(b.position[0], b.position[1]))
        .rotation(b.angle)
        .linvel(Vector::new(b.velocity[0], b.velocity[1]))
        .angvel(b.angular_velocity);
        let (h, c) = world.insert(body, collider);
        topple.manage(&mut world.colliders, c, m);
        bodies.push((name, h, c));
    }
    let row = row.map(|(preset, r)| RowInfo {
        preset,
        spacing: r.spacing * preset.height,
        colliders: bodies.iter().map(|b| b.2).collect(),
    });
    Ok(SceneWorld {
        world,
        topple,
        bodies,
        row,
        engine,
        time: 0.0,
    })
}

impl SceneWorld {
    /// One time step; returns the impacts topple resolved after it.
    pub fn step(&mut self) -> anyhow::Result<&[ImpactReport]> {
        self.topple.step(&mut self.world)?;
        self.time += self.world.integration_parameters.dt;
        Ok(self.topple.last_impacts())
    }

    /// Kinetic energy of all bodies (J per unit depth).
    pub fn kinetic_energy(&self) -> f64 {
        self.bodies
            .iter()
            .map(|b| self.world.bodies[b.1].kinetic_energy())
            .sum()
    }
}
