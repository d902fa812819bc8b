//! The scene files of `topple scene` in a Bevy app: one TOML runs in the
//! command line and in a game. [`SceneSpawn`] spawns a
//! [`crate::rapier::scene::Scene`]'s ground, bodies and domino row as
//! entities with bevy_rapier components and [`ToppleMaterial`]s (or native
//! friction and restitution), scaled into the app's units.

use bevy::prelude::*;
use bevy_rapier2d::prelude::*;
use bevy_rapier2d::rapier::prelude::IntegrationParameters;

use super::row::DominoRowState;
use super::world::{ToppleConfig, ToppleMaterial};
use crate::coupling::{PairMaterial, ToppleSettings};
use crate::input::InputError;
use crate::rapier::f32::{integration_parameters, HitTracker};
use crate::rapier::scene::{
    expand_row, pair_material, topple_settings, BodySpec, PairLaw, Scene, SceneError, SceneResult,
    ShapeKind,
};
use crate::rapier::ImpactResponse;

/// How to spawn a scene file into a Bevy app: where, at what scale, with
/// which physics, in which Rapier context.
///
/// A scene is in SI units (m, kg, s). `scale` is the app's world units per
/// metre: 1 for a world in metres, 100 for bevy_rapier's
/// `pixels_per_meter(100)`. Positions, sizes and velocities are multiplied by
/// it and densities divided by its square, so that every body keeps its
/// mass; the app's context keeps its own gravity and time step (use
/// [`SceneSpawn::rapier_configuration`] and
/// [`SceneSpawn::integration_parameters`] to take the scene's, scaled).
///
/// Native physics gives each collider its material's friction and
/// restitution; a scene with a row (or other pair rules) combines them as
/// Table 1's pairs do (friction by Rapier's Max rule, restitution by Min),
/// otherwise by Rapier's default (the average).
///
/// ```
/// use bevy::prelude::*;
/// use topple::bevy::{rapier_plugin, SceneSpawn, TopplePlugin};
/// use topple::rapier::scene::Scene;
/// let scene: Scene = toml::from_str(r#"
///     duration = 1.0
///     [[materials]]
///     name = "wood"
///     stiffness = 1e8
///     restitution = 0.5
///     [ground]
///     material = "wood"
///     [[bodies]]
///     shape = "box"
///     size = [0.2, 0.2]
///     position = [0.0, 0.5]
///     material = "wood"
/// "#).unwrap();
/// let spawn = SceneSpawn::new(&scene).with_scale(100.0); // pixels
/// let mut app = App::new();
/// app.add_plugins((MinimalPlugins, TransformPlugin))
///     .add_plugins((rapier_plugin().with_length_unit(100.0), TopplePlugin::default()));
/// let spawned = spawn.spawn(&mut app.world_mut().commands()).unwrap();
/// app.world_mut().flush();
/// let t = app.world().get::<Transform>(spawned.bodies[0].1).unwrap();
/// assert_eq!(t.translation.y, 50.0);
/// ```
#[derive(Clone, Debug)]
pub struct SceneSpawn<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// World units per metre (1: metres; 100: bevy_rapier's pixel units).
    pub scale: f32,
    /// Where the scene's origin goes (world units).
    pub origin: Vec2,
    /// topple or native bevy_rapier.
    pub physics: ImpactResponse,
    /// The Rapier context (`None`: the default one).
    pub context: Option<Entity>,
}

/// What [`SceneSpawn::spawn`] made.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpawnedScene {
    /// Each body's name (its index when it has none; a row's blocks are
    /// `block1` …) and entity, in scene order.
    pub bodies: Vec<(String, Entity)>,
    /// The ground, if the scene has one.
    pub ground: Option<Entity>,
    /// The row's [`DominoRowState`] entity, if the scene has a row.
    pub row: Option<Entity>,
}

impl<'a> SceneSpawn<'a> {
    /// A scene at the origin of the default context, in metres, with
    /// topple's impacts.
    pub fn new(scene: &'a Scene) -> Self {
        SceneSpawn {
            scene,
            scale: 1.0,
            origin: Vec2::ZERO,
            physics: ImpactResponse::Topple,
            context: None,
        }
    }

    /// In an app whose world has `scale` units per metre.
    pub fn with_scale(mut self, scale: f32) -> Self {
        self.scale = scale;
        self
    }

    /// With native bevy_rapier (or topple).
    pub fn with_physics(mut self, physics: ImpactResponse) -> Self {
        self.physics = physics;
        self
    }

    /// Rapier's parameters for a context that runs this scene as `topple
    /// scene` does: its step, contact stiffness and length unit (a row's
    /// block height by default), the length unit times the scale.
    pub fn integration_parameters(&self) -> IntegrationParameters {
        let s = &self.scene.solver;
        let row_height = self
            .scene
            .row
            .as_ref()
            .and_then(|r| crate::rapier::scene::row_params(r, 9.81).ok())
            .map(|p| p.block.height);
        let length = s.length_unit.or(row_height).unwrap_or(1.0);
        let hertz = s
            .contact_hertz
            .or(row_height.map(|_| crate::rapier::ROW_CONTACT_HERTZ));
        integration_parameters(s, length * f64::from(self.scale), hertz)
    }

    /// bevy_rapier's configuration with the scene's gravity, scaled.
    pub fn rapier_configuration(&self) -> RapierConfiguration {
        let g = self.scene.gravity;
        RapierConfiguration {
            gravity: Vec2::new(g[0] as f32, g[1] as f32) * self.scale,
            ..RapierConfiguration::new(self.integration_parameters().length_unit)
        }
    }

    /// topple's settings of the scene (per length unit, as `topple scene`),
    /// with the scene's work budget (by default a game's bounded step,
    /// [`crate::rapier::scene::WorkBudget`]).
    pub fn topple_settings(&self) -> ToppleSettings {
        let length = f64::from(self.integration_parameters().length_unit);
        topple_settings(&self.scene.solver, length)
    }

    /// Spawns the scene: the ground, the bodies (a row's blocks asleep but
    /// the first, as a row at rest is), a [`DominoRowState`] for a row, and
    /// with topple its pair rules in [`ToppleConfig`]. The scene is checked
    /// first (`topple::rapier::scene::check_scene`); a bad one is refused with its
    /// message and nothing is spawned.
    pub fn spawn(&self, commands: &mut Commands) -> SceneResult<SpawnedScene> {
        crate::rapier::scene::check_scene(self.scene)?;
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(InputError::new(
                "scale",
                self.scale,
                "0 < scale, finite (units per metre)",
            )
            .into());
        }
        let mut scene = self.scene.clone();
        let row = match scene.row.clone() {
            Some(r) => Some(expand_row(&mut scene, &r)?),
            None => None,
        };
        let materials = materials(&scene)?;
        let material = |name: &str| {
            materials
                .iter()
                .find(|(n, _, _)| n == name)
                .map(|(_, m, law)| (*m, law.clone()))
                .ok_or_else(|| SceneError::invalid(format!("unknown material {name:?}")))
        };
        let mut rules = Vec::new();
        for p in &scene.pairs {
            let (a, _) = material(&p.materials[0])?;
            let (b, _) = material(&p.materials[1])?;
            rules.push((a, b, pair_material(&p.law)));
        }
        // everything is checked: spawn
        let table_rules = !scene.pairs.is_empty();
        if self.physics == ImpactResponse::Topple && table_rules {
            commands.queue(move |world: &mut World| {
                let mut config = world.get_resource_or_insert_with(ToppleConfig::default);
                for (a, b, rule) in rules {
                    config.set_pair(a, b, rule);
                }
            });
        }
        let s = self.scale;
        let mut out = SpawnedScene::default();
        if let Some(g) = &scene.ground {
            let (m, law) = material(&g.material)?;
            let mut e = commands.spawn((
                RigidBody::Fixed,
                Collider::cuboid(1.0e3 * s, s),
                Transform::from_translation(
                    (self.origin + Vec2::new(0.0, (g.y as f32 - 1.0) * s)).extend(0.0),
                ),
            ));
            self.add_material(&mut e, m, &law, table_rules);
            out.ground = Some(e.id());
        }
        let first_block = scene.bodies.len() - row.as_ref().map_or(0, |r| r.n);
        for (i, b) in scene.bodies.iter().enumerate() {
            let name = b.name.clone().unwrap_or_else(|| i.to_string());
            let (m, law) = material(&b.material)?;
            let mut e = commands.spawn(self.body(b));
            self.add_material(&mut e, m, &law, table_rules);
            if row.is_some() && i > first_block {
                // standing at rest: asleep until the wave wakes it
                e.insert(Sleeping {
                    sleeping: true,
                    ..Sleeping::default()
                });
            }
            out.bodies.push((name, e.id()));
        }
        if let (Some(spec), Some(ground)) = (row, out.ground) {
            let state = DominoRowState {
                spec,
                physics: self.physics,
                context: self.context,
                blocks: out.bodies[first_block..].iter().map(|b| b.1).collect(),
                ground,
                hits: HitTracker::new(),
                start: None,
            };
            out.row = Some(commands.spawn(state).id());
        }
        Ok(out)
    }

    /// A scene body's components, scaled.
    fn body(&self, b: &BodySpec) -> impl Bundle {
        let s = self.scale;
        let collider = match b.shape {
            ShapeKind::Box => {
                let [w, h] = b.size.unwrap_or([0.0, 0.0]);
                Collider::cuboid(0.5 * w as f32 * s, 0.5 * h as f32 * s)
            }
            ShapeKind::Ball => Collider::ball(b.radius.unwrap_or(0.0) as f32 * s),
        };
        let mass = match (b.mass, b.density) {
            (Some(m), _) => ColliderMassProperties::Mass(m as f32),
            (None, d) => ColliderMassProperties::Density(d.unwrap_or(1000.0) as f32 / (s * s)),
        };
        let v = |x: [f64; 2]| Vec2::new(x[0] as f32, x[1] as f32) * s;
        (
            if b.fixed {
                RigidBody::Fixed
            } else {
                RigidBody::Dynamic
            },
            collider,
            mass,
            Transform::from_translation((self.origin + v(b.position)).extend(0.0))
                .with_rotation(Quat::from_rotation_z(b.angle as f32)),
            Velocity {
                linear: v(b.velocity),
                angular: b.angular_velocity as f32,
            },
        )
    }

    /// topple's material, or Rapier's friction and restitution, and the
    /// context link.
    fn add_material(&self, e: &mut EntityCommands, m: PairMaterial, law: &PairLaw, table: bool) {
        match self.physics {
            ImpactResponse::Topple => {
                e.insert(ToppleMaterial(m));
            }
            ImpactResponse::Native => {
                let (friction, restitution) = if table {
                    (CoefficientCombineRule::Max, CoefficientCombineRule::Min)
                } else {
                    (
                        CoefficientCombineRule::Average,
                        CoefficientCombineRule::Average,
                    )
                };
                e.insert((
                    Friction {
                        coefficient: law.friction as f32,
                        combine_rule: friction,
                    },
                    Restitution {
                        coefficient: law.restitution as f32,
                        combine_rule: restitution,
                    },
                ));
            }
        }
        if let Some(ctx) = self.context {
            e.insert(RapierContextEntityLink(ctx));
        }
    }
}

/// The scene's materials by name, as topple's and as laws.
fn materials(scene: &Scene) -> SceneResult<Vec<(String, PairMaterial, PairLaw)>> {
    let mut out: Vec<(String, PairMaterial, PairLaw)> = Vec::new();
    for m in &scene.materials {
        if out.iter().any(|(n, _, _)| *n == m.name) {
            return Err(SceneError::invalid(format!(
                "material {:?} defined twice",
                m.name
            )));
        }
        let law = m.law();
        out.push((m.name.clone(), pair_material(&law), law));
    }
    Ok(out)
}
