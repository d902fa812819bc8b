//! A domino row in a few lines: Table 1 blocks on their ground, with topple's
//! impacts or plain Rapier, and the wave's measures as the row runs.

use bevy::prelude::*;
use bevy_rapier2d::prelude::*;
use bevy_rapier2d::rapier::prelude::IntegrationParameters;

use super::events::ToppleImpact;
use super::world::{PhysicsClock, ToppleConfig, ToppleMaterial};
use crate::coupling::PairMaterial;
use crate::coupling::ToppleSettings;
use crate::domino::{ChainReport, RowSpec};
use crate::input::InputError;
use crate::rapier::f32::{integration_parameters, signed_gap, HitTracker};
use crate::rapier::scene::{
    expand_row, pair_material, row_scene, topple_settings, PairLaw, SolverSpec,
};
use crate::rapier::ImpactResponse;

/// The engine name `topple chain` reports for a Bevy row.
fn engine_name(physics: ImpactResponse) -> &'static str {
    match physics {
        ImpactResponse::Topple => "bevy-topple",
        ImpactResponse::Native => "bevy-native",
    }
}

/// A domino row to spawn: blocks 1…n standing at `origin` + the row's
/// centres (m), block 1 pushed, on a ground of the row's material.
///
/// ```
/// use topple::bevy::{DominoRow, ImpactResponse};
/// use topple::domino::{Preset, RowSpec};
/// let p = Preset::T.params().ideal();
/// let row = DominoRow::new(RowSpec::new(p, 0.45 * p.block.height, 30, 1.0));
/// assert_eq!(row.physics, ImpactResponse::Topple);
/// assert_eq!(row.spec.n, 30);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct DominoRow {
    /// Blocks, materials, spacing, count and push (Table 1 presets:
    /// [`crate::domino::Preset`]).
    pub spec: RowSpec,
    /// Where block 1's bottom centre stands (m).
    pub origin: Vec2,
    /// topple or plain Rapier.
    pub physics: ImpactResponse,
    /// The Rapier context of the row (`None`: the default context).
    pub context: Option<Entity>,
}

impl DominoRow {
    /// A topple row at the origin of the default context.
    pub fn new(spec: RowSpec) -> Self {
        DominoRow {
            spec,
            origin: Vec2::ZERO,
            physics: ImpactResponse::Topple,
            context: None,
        }
    }

    /// Rapier's parameters for a context that runs rows like this one at step
    /// `dt` (s): the length unit is the block height and contacts are stiff
    /// ([`crate::rapier::ROW_CONTACT_HERTZ`]), as in `topple chain`.
    pub fn integration_parameters(&self, dt: f64) -> IntegrationParameters {
        let solver = SolverSpec {
            dt,
            ..SolverSpec::default()
        };
        integration_parameters(
            &solver,
            self.spec.params.block.height,
            Some(crate::rapier::ROW_CONTACT_HERTZ),
        )
    }

    /// topple's settings for such a context at step `dt` (s), as `topple
    /// chain` sets them (impact threshold 2 g dt, the approach a resting
    /// contact picks up in one step; tolerances in the row's length unit),
    /// with the default work budget of [`ToppleSettings`].
    pub fn topple_settings(&self, dt: f64) -> ToppleSettings {
        let solver = SolverSpec {
            dt,
            ..SolverSpec::default()
        };
        ToppleSettings {
            fallback: ToppleSettings::default().fallback,
            ..topple_settings(&solver, self.spec.params.block.height)
        }
    }

    /// bevy_rapier's configuration for such a context: the row's gravity
    /// (m/s², not scaled by the length unit).
    pub fn rapier_configuration(&self) -> RapierConfiguration {
        RapierConfiguration {
            gravity: Vec2::new(0.0, -self.spec.params.gravity as f32),
            ..RapierConfiguration::new(self.spec.params.block.height as f32)
        }
    }

    /// The block–block and block–ground laws of the row (the same expansion
    /// `topple chain` and scene files use).
    fn laws(&self) -> (PairLaw, PairLaw) {
        let mut scene = row_scene(&self.spec, SolverSpec::default(), 0.0);
        let generator = scene.row.take().expect("row_scene makes a row");
        expand_row(&mut scene, &generator).expect("a valid RowSpec expands");
        (scene.pairs[0].law.clone(), scene.pairs[1].law.clone())
    }

    /// Spawns the ground and the blocks (all but the pushed one asleep, as a
    /// row standing at rest is after Rapier's sleep delay: the first contact
    /// wakes each one), and an entity carrying
    /// [`DominoRowState`] that measures the wave; returns that entity.
    /// A topple row also adds its pair rules to [`ToppleConfig`]. The row
    /// must be valid ([`RowSpec::validate`]); an invalid one is refused with
    /// its message and nothing is spawned.
    pub fn spawn(&self, commands: &mut Commands) -> Result<Entity, InputError> {
        self.spec.validate()?;
        let (block_law, ground_law) = self.laws();
        let (block, ground) = (pair_material(&block_law), pair_material(&ground_law));
        if self.physics == ImpactResponse::Topple {
            commands.queue(move |world: &mut World| {
                let mut config = world.get_resource_or_insert_with(ToppleConfig::default);
                config.set_pair(block, block, block);
                config.set_pair(block, ground, ground);
            });
        }
        let b = &self.spec.params.block;
        let length = self.spec.pitch() * self.spec.n as f64 + b.height;
        let ground_centre = self.origin + Vec2::new((0.5 * length) as f32 - b.height as f32, -1.0);
        let mut ground_entity = commands.spawn((
            RigidBody::Fixed,
            Collider::cuboid((0.5 * length) as f32 + b.height as f32, 1.0),
            Transform::from_translation(ground_centre.extend(0.0)),
        ));
        self.add_material(&mut ground_entity, ground, &ground_law);
        let ground_entity = ground_entity.id();
        let mut blocks = Vec::with_capacity(self.spec.n);
        for i in 0..self.spec.n {
            let c = self.spec.centre(i);
            let (v, w) = if i == 0 {
                self.spec.initial_velocity()
            } else {
                ([0.0, 0.0], 0.0)
            };
            let mut e = commands.spawn((
                RigidBody::Dynamic,
                Collider::cuboid((0.5 * b.thickness) as f32, (0.5 * b.height) as f32),
                ColliderMassProperties::Mass(b.mass as f32),
                Transform::from_translation(
                    (self.origin + Vec2::new(c[0] as f32, c[1] as f32)).extend(0.0),
                ),
                Velocity {
                    linear: Vec2::new(v[0] as f32, v[1] as f32),
                    angular: w as f32,
                },
            ));
            if i > 0 {
                // standing at rest: asleep until the wave wakes it
                e.insert(Sleeping {
                    sleeping: true,
                    ..Sleeping::default()
                });
            }
            self.add_material(&mut e, block, &block_law);
            blocks.push(e.id());
        }
        let state = DominoRowState {
            spec: self.spec,
            physics: self.physics,
            context: self.context,
            blocks,
            ground: ground_entity,
            hits: HitTracker::new(),
            start: None,
        };
        Ok(commands.spawn(state).id())
    }

    /// topple's material, or Rapier's friction and restitution for a native
    /// row, and the context link.
    fn add_material(&self, e: &mut EntityCommands, m: PairMaterial, law: &PairLaw) {
        match self.physics {
            ImpactResponse::Topple => {
                e.insert(ToppleMaterial(m));
            }
            ImpactResponse::Native => {
                e.insert((
                    Friction {
                        coefficient: law.friction as f32,
                        combine_rule: CoefficientCombineRule::Max,
                    },
                    Restitution {
                        coefficient: law.restitution as f32,
                        combine_rule: CoefficientCombineRule::Min,
                    },
                ));
            }
        }
        if let Some(ctx) = self.context {
            e.insert(RapierContextEntityLink(ctx));
        }
    }
}

/// A spawned row and its wave measures so far (updated every frame by
/// [`crate::bevy::TopplePlugin`] after the physics step).
#[derive(Component, Clone, Debug)]
pub struct DominoRowState {
    /// The row as spawned.
    pub spec: RowSpec,
    /// topple or plain Rapier.
    pub physics: ImpactResponse,
    /// Its Rapier context (`None`: the default one).
    pub context: Option<Entity>,
    /// The blocks, in row order.
    pub blocks: Vec<Entity>,
    /// The ground under them.
    pub ground: Entity,
    pub(crate) hits: HitTracker,
    /// Simulated time of the context when the row's first step began (s).
    pub(crate) start: Option<f64>,
}

impl DominoRowState {
    /// Instants T_i (s) at which block i was hit, T_1 = 0 (the push).
    pub fn hit_times(&self) -> &[f64] {
        &self.hits.hit_times
    }

    /// True once the wave reached the last block.
    pub fn finished(&self) -> bool {
        self.hits.hit_times.len() >= self.spec.n
    }

    /// The row's measures with the keys of `topple chain --json` (v̂_i,
    /// v̂_na over the steady blocks: [`crate::domino::WaveMeasures`]).
    pub fn report(&self) -> ChainReport {
        ChainReport::new(
            engine_name(self.physics),
            &self.spec,
            self.hits.hit_times.clone(),
        )
    }
}

/// Advances every row's hit tracker after the physics step: a block counts
/// as hit at topple's impact instant with its predecessor when there is one,
/// else where their gap closes (the one definition `topple chain` uses).
pub(crate) fn track_rows(
    mut rows: Query<&mut DominoRowState>,
    contexts: Query<(
        &PhysicsClock,
        &RapierRigidBodySet,
        &RapierContextColliders,
        Has<DefaultRapierContext>,
    )>,
    mut impacts: MessageReader<ToppleImpact>,
) {
    let impacts: Vec<&ToppleImpact> = impacts.read().collect();
    for mut row in &mut rows {
        if row.finished() {
            continue;
        }
        let ctx = row
            .context
            .and_then(|c| contexts.get(c).ok().map(|x| (c, x)));
        let Some((clock, bodies, colliders)) =
            ctx.map(|(_, (c, b, co, _))| (c, b, co)).or_else(|| {
                contexts
                    .iter()
                    .find(|x| x.3)
                    .map(|(c, b, co, _)| (c, b, co))
            })
        else {
            continue;
        };
        let row = &mut *row;
        let start = *row.start.get_or_insert(clock.time - clock.last_frame);
        let blocks = &row.blocks;
        let n = blocks.len();
        let collider = |e: &Entity| colliders.entity2collider().get(e).copied();
        row.hits
            .update_with(n, clock.time - start, clock.last_frame, |k| {
                // only the front pair is looked at; a block Rapier has not
                // created yet is not hit
                let (Some(a), Some(b)) = (collider(&blocks[k - 1]), collider(&blocks[k])) else {
                    return (f64::INFINITY, None);
                };
                let gap = signed_gap(&bodies.bodies, &colliders.colliders, a, b);
                let struck = impacts
                    .iter()
                    .filter(|ev| ev.involves_pair(blocks[k - 1], blocks[k]))
                    .map(|ev| ev.time_in_frame)
                    .min_by(f64::total_cmp);
                (gap, struck)
            });
    }
}
