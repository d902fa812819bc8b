//! The physics step of every Rapier context, in bevy_rapier's
//! [`PhysicsSet::StepSimulation`]: contexts with a [`ToppleWorld`] are
//! stepped by topple's adapter (impacts at their instant, sub-steps, the LZB
//! resolver), the others exactly as bevy_rapier steps them.

use std::time::Instant;

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_rapier2d::plugin::context::SimulationToRenderTime;
use bevy_rapier2d::prelude::*;
use bevy_rapier2d::rapier::math::Real;

use super::events::{collect, CollisionCollector, ToppleImpact, ToppleNotice};
use super::world::{PhysicsClock, ToppleConfig, ToppleFrameStats, ToppleMaterial, ToppleWorld};
use crate::coupling::Resolution;
use crate::rapier::f32::{StepParts, ToppleRapier};
use crate::rapier::ImpactResponse;
use crate::rapier::ToppleStats;

/// The Rapier steps of one frame for a timestep mode, as bevy_rapier takes
/// them: `steps` steps of `substeps` pieces of `piece` seconds each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FramePlan {
    pub steps: usize,
    pub substeps: usize,
    /// Length of one piece (s), time scale included.
    pub piece: Real,
}

impl FramePlan {
    /// The plan of a frame; for [`TimestepMode::Interpolated`], `pending` is
    /// the simulation time still owed to the render clock (s), updated.
    pub fn of(mode: TimestepMode, delta: Real, pending: &mut Real) -> FramePlan {
        match mode {
            TimestepMode::Fixed { dt, substeps } => FramePlan {
                steps: 1,
                substeps,
                piece: dt / substeps.max(1) as Real,
            },
            TimestepMode::Variable {
                max_dt,
                time_scale,
                substeps,
            } => FramePlan {
                steps: 1,
                substeps,
                piece: (delta * time_scale).min(max_dt) / substeps.max(1) as Real,
            },
            TimestepMode::Interpolated {
                dt,
                time_scale,
                substeps,
            } => {
                // bevy_rapier's loop: step while the render clock is ahead
                // (none for a step that is not positive: it would never
                // catch up)
                *pending += delta;
                let mut steps = 0;
                while dt > 0.0 && *pending > 0.0 {
                    steps += 1;
                    *pending -= dt;
                }
                FramePlan {
                    steps,
                    substeps,
                    piece: dt / substeps.max(1) as Real * time_scale,
                }
            }
        }
    }

    /// Simulated time of the whole frame (s).
    pub fn length(&self) -> f64 {
        f64::from(self.piece) * (self.steps * self.substeps) as f64
    }
}

/// The messages the step writes.
#[derive(SystemParam)]
pub(crate) struct StepMessages<'w> {
    collisions: MessageWriter<'w, CollisionEvent>,
    forces: MessageWriter<'w, ContactForceEvent>,
    impacts: MessageWriter<'w, ToppleImpact>,
    notices: MessageWriter<'w, ToppleNotice>,
}

/// A Rapier context's parts, as one query item.
type ContextItem<'a> = (
    Entity,
    &'a mut RapierContextSimulation,
    &'a mut RapierContextColliders,
    &'a mut RapierContextJoints,
    &'a mut RapierRigidBodySet,
    &'a RapierConfiguration,
    &'a mut SimulationToRenderTime,
    Option<&'a mut ToppleWorld>,
    &'a mut PhysicsClock,
);

/// Steps every Rapier context one frame (replaces bevy_rapier's
/// `step_simulation`, which [`crate::bevy::rapier_plugin`] leaves out).
#[allow(clippy::too_many_arguments)]
pub(crate) fn step_contexts(
    mut contexts: Query<ContextItem<'_>>,
    mode: Res<TimestepMode>,
    time: Res<Time>,
    mut messages: StepMessages,
    mut stats: ResMut<ToppleFrameStats>,
    mut interpolation: Query<(&RapierRigidBodyHandle, &mut TransformInterpolation)>,
) {
    let start = Instant::now();
    let mut frame = ToppleFrameStats {
        totals: ToppleStats::default(),
        ..ToppleFrameStats::default()
    };
    for (
        entity,
        mut sim,
        mut colliders,
        mut joints,
        mut bodies,
        config,
        mut s2r,
        world,
        mut clock,
    ) in contexts.iter_mut()
    {
        if !config.physics_pipeline_active {
            bodies.propagate_modified_body_positions_to_colliders(&mut colliders);
            continue;
        }
        let mut pending = s2r.diff;
        let plan = FramePlan::of(*mode, time.delta_secs(), &mut pending);
        clock.frames += 1;
        clock.last_frame = plan.length();
        clock.time += clock.last_frame;
        let Some(mut world) = world else {
            // not topple's: bevy_rapier's own step, unchanged
            sim.step_simulation(
                &mut colliders,
                &mut joints,
                &mut bodies,
                config.gravity,
                *mode,
                Some((&messages.collisions, &messages.forces)),
                &(),
                &time,
                &mut s2r,
                Some(&mut interpolation),
            );
            sim.send_bevy_events(&mut messages.collisions, &mut messages.forces);
            continue;
        };
        s2r.diff = pending;
        let before = world.adapter.stats();
        let collector = CollisionCollector::default();
        let mut impacts = Vec::new();
        let mut offset = 0.0;
        for step in 0..plan.steps {
            if step + 1 == plan.steps {
                mark_interpolation_start(&bodies, &mut interpolation);
            }
            for _ in 0..plan.substeps {
                if plan.piece <= 0.0 {
                    continue;
                }
                let mut params = sim.integration_parameters;
                params.dt = plan.piece;
                let sim = &mut *sim;
                let joints = &mut *joints;
                let parts = StepParts {
                    pipeline: &mut sim.pipeline,
                    gravity: config.gravity,
                    integration_parameters: &params,
                    islands: &mut sim.islands,
                    broad_phase: &mut sim.broad_phase,
                    narrow_phase: &mut sim.narrow_phase,
                    bodies: &mut bodies.bodies,
                    colliders: &mut colliders.colliders,
                    impulse_joints: &mut joints.impulse_joints,
                    multibody_joints: &mut joints.multibody_joints,
                    ccd_solver: &mut sim.ccd_solver,
                };
                world.adapter.step_parts(parts, &(), &collector);
                collect(
                    &world.adapter,
                    &bodies.bodies,
                    entity,
                    clock.frames,
                    offset,
                    &mut impacts,
                );
                frame.large_group_fallbacks += large_group_fallbacks(&world.adapter);
                offset += f64::from(plan.piece);
            }
        }
        let after = world.adapter.stats();
        add_frame(&mut frame, &before, &after);
        warn_left(entity, &mut world, &colliders, &mut messages.notices);
        if let Ok(mut events) = collector.events.lock() {
            messages.collisions.write_batch(events.drain(..));
        }
        messages.impacts.write_batch(impacts);
    }
    frame.step_seconds = start.elapsed().as_secs_f64();
    *stats = frame;
}

/// bevy_rapier's interpolation: the pose before the frame's last step.
fn mark_interpolation_start(
    bodies: &RapierRigidBodySet,
    interpolation: &mut Query<(&RapierRigidBodyHandle, &mut TransformInterpolation)>,
) {
    for (handle, mut interp) in interpolation.iter_mut() {
        if let Some(body) = bodies.bodies.get(handle.0) {
            interp.start = Some(*body.position());
            interp.end = None;
        }
    }
}

/// Impacts of the adapter's last step that were large groups under its
/// policy ([`crate::coupling::FallbackPolicy::large_group`]) and did not
/// finish by the law.
fn large_group_fallbacks(adapter: &ToppleRapier) -> u64 {
    adapter
        .last_impacts()
        .iter()
        .filter(|r| r.large_group && r.resolution != Resolution::Lzb)
        .count() as u64
}

/// Adds what one context's adapter did between two readings of its totals.
fn add_frame(frame: &mut ToppleFrameStats, before: &ToppleStats, after: &ToppleStats) {
    let fallbacks = |s: &ToppleStats| s.held_impacts + s.plastic_fallbacks + s.rejected_impacts;
    frame.impacts += after.impacts - before.impacts;
    frame.lzb_steps += after.impulse_steps - before.impulse_steps;
    frame.fallbacks += fallbacks(after) - fallbacks(before);
    frame.rapier_steps += after.rapier_steps - before.rapier_steps;
    frame.topple_seconds += after.topple_seconds - before.topple_seconds;
    frame.work += after.work - before.work;
    frame.budget_spent += after.budget_spent - before.budget_spent;
    frame.native_impacts += after.native_impacts - before.native_impacts;
    frame.batched_impacts += after.batched_impacts - before.batched_impacts;
    let t = &mut frame.totals;
    t.pairs_queried += after.pairs_queried;
    t.contact_points += after.contact_points;
    t.impacts += after.impacts;
    t.impulse_steps += after.impulse_steps;
    t.held_impacts += after.held_impacts;
    t.plastic_fallbacks += after.plastic_fallbacks;
    t.rejected_impacts += after.rejected_impacts;
    t.split_steps += after.split_steps;
    t.rapier_steps += after.rapier_steps;
    t.topple_seconds += after.topple_seconds;
    t.work += after.work;
    t.budget_spent += after.budget_spent;
    t.native_impacts += after.native_impacts;
    t.batched_impacts += after.batched_impacts;
    t.batch_resolves += after.batch_resolves;
}

/// One warning and one [`ToppleNotice`] per collider topple leaves to
/// Rapier, naming its entity, shape and why.
fn warn_left(
    context: Entity,
    world: &mut ToppleWorld,
    colliders: &RapierContextColliders,
    out: &mut MessageWriter<ToppleNotice>,
) {
    for n in world.adapter.take_notices() {
        let entity = colliders
            .colliders
            .get(n.collider)
            .map(|co| Entity::from_bits(co.user_data as u64));
        out.write(ToppleNotice {
            context,
            entity,
            shape: n.shape,
            reason: n.reason,
        });
        match entity {
            Some(e) => warn!(
                "topple: the {} collider of entity {e} gets Rapier's impacts, not topple's: {}",
                n.shape, n.reason
            ),
            None => warn!(
                "topple: a {} collider gets Rapier's impacts, not topple's: {}",
                n.shape, n.reason
            ),
        }
    }
}

/// Gives every new Rapier context a [`PhysicsClock`], and the default one a
/// [`ToppleWorld`] with the configured settings.
pub(crate) fn attach_to_contexts(
    mut commands: Commands,
    config: Res<ToppleConfig>,
    who: Res<ImpactResponse>,
    clockless: Query<Entity, (With<RapierContextSimulation>, Without<PhysicsClock>)>,
    default: Query<Entity, (With<DefaultRapierContext>, Without<ToppleWorld>)>,
    attached: Local<bool>,
) {
    let mut attached = attached;
    for e in &clockless {
        commands.entity(e).insert(PhysicsClock::default());
    }
    if !*attached && *who == ImpactResponse::Topple {
        for e in &default {
            commands.entity(e).insert(ToppleWorld::new(config.settings));
            *attached = true;
        }
    }
}

/// Lets topple manage the colliders of entities given a [`ToppleMaterial`]
/// (and gives back those that lost it), after bevy_rapier created them.
pub(crate) fn manage_colliders(
    config: Res<ToppleConfig>,
    mut worlds: Query<(Entity, &mut ToppleWorld, &mut RapierContextColliders)>,
    default: Query<Entity, With<DefaultRapierContext>>,
    changed: Query<(Entity, Option<&RapierContextEntityLink>), Changed<ToppleMaterial>>,
    materials: Query<&ToppleMaterial>,
    mut removed: RemovedComponents<ToppleMaterial>,
) {
    let fallback_context = default.iter().next();
    for (e, link) in &changed {
        let target = link.map(|l| l.0).or(fallback_context);
        if let Some(Ok((_, mut world, _))) = target.map(|t| worlds.get_mut(t)) {
            world.pending.push(e);
        }
    }
    for e in removed.read() {
        for (_, mut world, _) in worlds.iter_mut() {
            if let Some(h) = world.managed.remove(&e) {
                world.adapter.unmanage(h);
            }
        }
    }
    for (_, mut world, mut colliders) in worlds.iter_mut() {
        let world = &mut *world;
        world.apply_config(&config);
        let pending = std::mem::take(&mut world.pending);
        for e in pending {
            let Ok(material) = materials.get(e) else {
                continue; // despawned or the material was removed
            };
            match colliders.entity2collider().get(&e).copied() {
                Some(h) => {
                    let id = world.material_id(material.0);
                    if let Some(old) = world.managed.insert(e, h) {
                        world.adapter.unmanage(old);
                    }
                    world.adapter.manage(&mut colliders.colliders, h, id);
                }
                None => world.pending.push(e), // Rapier has not created it yet
            }
        }
    }
}
