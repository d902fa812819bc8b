//! The Rapier adapter (one source for rapier2d-f64 and rapier2d): Rapier's
//! step with topple's hook, then the impact pass ([`super::pass`]) that
//! resolves each impact at the instant its pair closes inside the step.
//! Everything physical lives in the engine-agnostic [`crate::coupling`].

use std::time::Instant;

use super::backend::math::Real;
use super::backend::prelude::{
    ActiveHooks, BroadPhaseBvh, CCDSolver, ColliderHandle, ColliderSet, EventHandler,
    ImpulseJointSet, IntegrationParameters, IslandManager, MultibodyJointSet, NarrowPhase,
    PhysicsHooks, PhysicsPipeline, PhysicsWorld, RigidBodyHandle, RigidBodySet, Vector,
};

use super::cadence::Cadence;
use super::hooks::{ChainedHooks, ToppleHooks};
use super::pass::{ImpactContact, ImpactEvent, ImpactPass, Prediction, World};
use super::scale;
use super::support::{self, Notice};
use crate::coupling::{ImpactGroups, ImpactReport, MaterialId, PairMaterial, ToppleSettings};
use crate::rapier::{ImpactResponse, ToppleStats};

/// The world's length unit (Rapier's; 1 if it is not a positive number).
fn length_unit(params: &IntegrationParameters) -> f64 {
    let l = f64::from(params.length_unit);
    if l.is_finite() && l > 0.0 {
        l
    } else {
        1.0
    }
}

/// The parts of a Rapier simulation one step needs, borrowed from wherever
/// the app keeps them (a [`PhysicsWorld`], or bevy_rapier's components).
pub struct StepParts<'a> {
    /// Rapier's pipeline.
    pub pipeline: &'a mut PhysicsPipeline,
    /// Gravity (m/s²).
    pub gravity: Vector,
    /// Rapier's parameters; `dt` is the step (s).
    pub integration_parameters: &'a IntegrationParameters,
    /// Rapier's island manager.
    pub islands: &'a mut IslandManager,
    /// Rapier's broad phase.
    pub broad_phase: &'a mut BroadPhaseBvh,
    /// Rapier's narrow phase.
    pub narrow_phase: &'a mut NarrowPhase,
    /// The bodies.
    pub bodies: &'a mut RigidBodySet,
    /// The colliders.
    pub colliders: &'a mut ColliderSet,
    /// Impulse joints.
    pub impulse_joints: &'a mut ImpulseJointSet,
    /// Multibody joints.
    pub multibody_joints: &'a mut MultibodyJointSet,
    /// Rapier's CCD solver.
    pub ccd_solver: &'a mut CCDSolver,
}

impl<'a> StepParts<'a> {
    /// The parts of a [`PhysicsWorld`].
    pub fn of(world: &'a mut PhysicsWorld) -> Self {
        StepParts {
            pipeline: &mut world.physics_pipeline,
            gravity: world.gravity,
            integration_parameters: &world.integration_parameters,
            islands: &mut world.islands,
            broad_phase: &mut world.broad_phase,
            narrow_phase: &mut world.narrow_phase,
            bodies: &mut world.bodies,
            colliders: &mut world.colliders,
            impulse_joints: &mut world.impulse_joints,
            multibody_joints: &mut world.multibody_joints,
            ccd_solver: &mut world.ccd_solver,
        }
    }
}

/// LZB impacts for a Rapier world.
///
/// Register the colliders topple manages with a material and step the world
/// with [`ToppleRapier::step`] (a [`PhysicsWorld`]) or
/// [`ToppleRapier::step_parts`] (the parts of a simulation kept elsewhere,
/// as bevy_rapier does). Pairs of managed colliders get their impacts from
/// the LZB resolver, at the instant the pair closes inside the step;
/// everything else is plain Rapier.
///
/// ```
/// use topple::rapier2d_f64::prelude::*;
/// use topple::coupling::{PairMaterial, ToppleSettings};
/// use topple::impact::ContactMaterial;
/// use topple::rapier::f64::ToppleRapier;
///
/// let mut world = PhysicsWorld::default();
/// world.gravity = Vector::ZERO;
/// let mut topple = ToppleRapier::new(ToppleSettings::default());
/// let steel = topple.add_material(PairMaterial {
///     impact: ContactMaterial::hertz(1e10),
///     smooth_friction: 0.0,
/// });
/// // a cradle of two touching balls, the first moving at 1 m/s
/// let mut balls = Vec::new();
/// for (x, v) in [(0.0, 1.0), (0.2, 0.0)] {
///     let (body, collider) = world.insert(
///         RigidBodyBuilder::dynamic().translation(Vector::new(x, 0.0)).linvel(Vector::new(v, 0.0)),
///         ColliderBuilder::ball(0.1),
///     );
///     topple.manage(&mut world.colliders, collider, steel);
///     balls.push(body);
/// }
/// topple.step(&mut world);
/// assert!(world.bodies[balls[0]].linvel().x.abs() < 1e-3);
/// assert!((world.bodies[balls[1]].linvel().x - 1.0).abs() < 1e-3);
/// ```
#[derive(Debug)]
pub struct ToppleRapier {
    hooks: ToppleHooks,
    settings: ToppleSettings,
    /// The settings of the current step in the world's units.
    effective: ToppleSettings,
    /// Colliders left to Rapier, not taken by the app yet.
    notices: Vec<Notice>,
    pass: ImpactPass,
    stats: ToppleStats,
    /// Colliders managed since the last step: Rapier's broad phase holds
    /// them only after its next step, too late for the sweep of that step.
    fresh: Vec<ColliderHandle>,
    /// Their bodies, recorded at every split of the step they join in.
    added: Vec<RigidBodyHandle>,
    /// Rapier's substep inside the pieces of a step.
    cadence: Cadence,
}

impl ToppleRapier {
    /// topple resolving impacts with the given settings.
    pub fn new(settings: ToppleSettings) -> Self {
        Self::with_mode(settings, ImpactResponse::Topple)
    }

    /// A native-Rapier twin: the same per-pair friction and restitution, but
    /// Rapier resolves impacts and the impact pass does nothing. For
    /// comparisons.
    pub fn native() -> Self {
        Self::with_mode(ToppleSettings::default(), ImpactResponse::Native)
    }

    fn with_mode(settings: ToppleSettings, mode: ImpactResponse) -> Self {
        let mut topple = ToppleRapier {
            hooks: ToppleHooks::new(mode),
            settings,
            effective: settings,
            notices: Vec::new(),
            pass: ImpactPass::default(),
            stats: ToppleStats::default(),
            fresh: Vec::new(),
            added: Vec::new(),
            cadence: Cadence::default(),
        };
        topple.set_settings(settings);
        topple
    }

    /// The settings of the impact pass.
    pub fn settings(&self) -> &ToppleSettings {
        &self.settings
    }

    /// Changes the settings (between steps).
    pub fn set_settings(&mut self, settings: ToppleSettings) {
        self.settings = settings;
        self.effective = settings;
        self.hooks
            .begin_frame(settings.min_approach_speed, settings.min_approach_speed);
    }

    /// The settings of the last step in the world's units: the impact
    /// threshold and tolerances derived from its length unit, gravity and
    /// step (docs/bevy.md, "Settings follow the scene").
    pub fn step_settings(&self) -> &ToppleSettings {
        &self.effective
    }

    /// The managed colliders topple left to Rapier since the last call, each
    /// reported once per reason (see [`LeftToRapier`](crate::rapier::LeftToRapier)).
    pub fn take_notices(&mut self) -> Vec<Notice> {
        std::mem::take(&mut self.notices)
    }

    /// Adds a material; returns its id.
    pub fn add_material(&mut self, material: PairMaterial) -> MaterialId {
        self.hooks.table.add(material)
    }

    /// Sets the material between colliders of materials `a` and `b`.
    pub fn set_pair_material(&mut self, a: MaterialId, b: MaterialId, material: PairMaterial) {
        self.hooks.table.set_pair(a, b, material);
    }

    /// Lets topple manage a collider with the given material (and turns on
    /// the collider's contact-modification hook). An unknown material id is
    /// ignored (the collider stays native) and reported as `false`.
    pub fn manage(
        &mut self,
        colliders: &mut ColliderSet,
        collider: ColliderHandle,
        material: MaterialId,
    ) -> bool {
        let Some(co) = colliders.get_mut(collider) else {
            return false;
        };
        if (material.0 as usize) >= self.hooks.table.len() {
            return false;
        }
        let reason = match support::geometry(co.shape()) {
            Err(reason) => Some(reason),
            Ok(_) if co.is_sensor() => Some(crate::rapier::LeftToRapier::Sensor),
            Ok(_) => None,
        };
        if let Some(reason) = reason {
            let notice = Notice {
                collider,
                shape: support::shape_name(co.shape()),
                reason,
            };
            if self.hooks.reported.insert(notice) {
                self.notices.push(notice);
            }
        }
        self.hooks.set(collider, Some(material));
        co.set_active_hooks(co.active_hooks() | ActiveHooks::MODIFY_SOLVER_CONTACTS);
        self.fresh.push(collider);
        true
    }

    /// Gives a collider back to Rapier (its hook flag is left as it is: the
    /// hook leaves unmanaged pairs alone).
    pub fn unmanage(&mut self, collider: ColliderHandle) {
        self.hooks.set(collider, None);
    }

    /// The hook to hand to `PhysicsPipeline::step` when the app steps
    /// Rapier itself (then call [`ToppleRapier::step_parts`] instead, which
    /// does both).
    pub fn hooks(&self) -> &ToppleHooks {
        &self.hooks
    }

    /// The impacts resolved in the last step, one report per group.
    pub fn last_impacts(&self) -> &[ImpactReport] {
        &self.pass.reports
    }

    /// The impact groups of the last step with their instants; their bodies
    /// and contacts are in [`ToppleRapier::event_bodies`] and
    /// [`ToppleRapier::event_contacts`].
    pub fn last_events(&self) -> &[ImpactEvent] {
        &self.pass.events
    }

    /// The bodies of an event of the last step.
    pub fn event_bodies(&self, event: &ImpactEvent) -> &[RigidBodyHandle] {
        &self.pass.event_bodies[event.bodies.0..event.bodies.1]
    }

    /// The contacts of an event of the last step, with their impulses.
    pub fn event_contacts(&self, event: &ImpactEvent) -> &[ImpactContact] {
        &self.pass.event_contacts[event.contacts.0..event.contacts.1]
    }

    /// The grouping stage (its last group in the input form of `topple
    /// impact`).
    pub fn impact_groups(&self) -> &ImpactGroups {
        self.pass.groups()
    }

    /// Totals since creation.
    pub fn stats(&self) -> ToppleStats {
        let mut s = self.stats;
        s.pairs_queried = self.pass.pairs_queried;
        s.contact_points = self.pass.contact_points;
        s.batched_impacts = self.pass.batched;
        s.batch_resolves = self.pass.solved_again;
        s
    }

    /// Whether a step's independent impacts are solved in batches, side by
    /// side (on rayon's threads with the `parallel` feature), or one instant
    /// at a time. Both give the same bits (docs/bevy.md, "Independent
    /// impacts side by side"); batches are on by default. For tests and
    /// measurements.
    ///
    /// ```
    /// use topple::coupling::ToppleSettings;
    /// use topple::rapier::f64::ToppleRapier;
    /// let mut topple = ToppleRapier::new(ToppleSettings::default());
    /// topple.set_impact_batches(false);
    /// assert_eq!(topple.stats().batched_impacts, 0);
    /// ```
    pub fn set_impact_batches(&mut self, on: bool) {
        self.pass.one_at_a_time = !on;
    }

    /// One step of a [`PhysicsWorld`] (see [`ToppleRapier::step_parts`]).
    pub fn step(&mut self, world: &mut PhysicsWorld) -> usize {
        self.step_parts(StepParts::of(world), &(), &())
    }

    /// One step of length `integration_parameters.dt`: Rapier with topple's
    /// hook in front of `user_hooks`, followed by the impact pass: every
    /// impact of a managed pair is resolved at the instant the pair closed,
    /// the bodies it changed move on from there. While a managed pair is
    /// predicted to close before the step ends, Rapier is stepped in equal
    /// sub-steps no longer than [`ToppleSettings::max_substep`], each split
    /// at the predicted instant (at most [`ToppleSettings::max_splits`]
    /// times); otherwise the rest of the step is one Rapier step, so a world
    /// at rest or between impacts costs one Rapier step as in native Rapier.
    /// The impacts of one step share the work budget
    /// [`crate::coupling::FallbackPolicy::max_work`]; once it is spent, the
    /// impact that ran out is finished by the fallback policy and the rest
    /// of the step is native Rapier (counted in [`ToppleStats`]). Lengths
    /// and speeds of the settings are per length unit (docs/bevy.md, "Settings follow the scene").
    /// Returns the number of impact groups resolved. Never fails. An app
    /// that calls Rapier's step itself uses [`ToppleRapier::begin_step`],
    /// Rapier's step with [`ToppleRapier::hooks`], then
    /// [`ToppleRapier::end_step`] instead (one piece, no splitting).
    pub fn step_parts(
        &mut self,
        mut parts: StepParts<'_>,
        user_hooks: &dyn PhysicsHooks,
        events: &dyn EventHandler,
    ) -> usize {
        self.pass.clear_step();
        let dt = parts.integration_parameters.dt;
        let n = self.substeps(f64::from(dt));
        self.prepare(parts.gravity, parts.integration_parameters, n);
        self.insert_fresh(&mut parts);
        // the sub-step boundaries; the last one is exactly dt
        let boundary = |k: usize| {
            if k >= n {
                dt
            } else {
                dt * (k as Real) / (n as Real)
            }
        };
        let mut params = *parts.integration_parameters;
        let (mut now, mut k, mut splits, mut groups): (Real, usize, usize, usize) = (0.0, 0, 0, 0);
        loop {
            self.begin_piece(&parts, now > 0.0);
            let piece_end = boundary(k + 1);
            let ahead = self.predict(&parts, dt - now);
            let sub_step = ahead.moving_contact;
            let end = match ahead.closing {
                // nothing closes before the step ends: one Rapier step,
                // unless managed bodies move in contact
                None if sub_step => piece_end,
                None => dt,
                Some(t) => {
                    let piece = f64::from(piece_end - now);
                    if splits < self.settings.max_splits
                        && t > piece / 64.0
                        && t < piece * (1.0 - 1.0 / 64.0)
                    {
                        splits += 1;
                        self.stats.split_steps += 1;
                        now + t as Real
                    } else {
                        piece_end
                    }
                }
            };
            params.dt = end - now;
            params.num_solver_iterations = self.piece_cadence(&mut parts, params.dt);
            self.stats.rapier_steps += 1;
            let hooks = ChainedHooks {
                topple: &self.hooks,
                user: user_hooks,
            };
            parts.pipeline.step(
                parts.gravity,
                &params,
                parts.islands,
                parts.broad_phase,
                parts.narrow_phase,
                parts.bodies,
                parts.colliders,
                parts.impulse_joints,
                parts.multibody_joints,
                parts.ccd_solver,
                &hooks,
                events,
            );
            groups += self.pass_after(
                parts.bodies,
                parts.colliders,
                parts.narrow_phase,
                parts.broad_phase,
                &params,
                f64::from(now),
            );
            let struck = self.pass.motion.changed().map(|(h, _)| h);
            self.cadence.note_struck(struck);
            now = end;
            if now >= dt || params.dt <= 0.0 {
                break;
            }
            if now >= piece_end {
                while k + 1 < n && boundary(k + 1) <= now {
                    k += 1;
                }
                splits = 0;
            }
        }
        self.cadence.end_step(parts.bodies);
        self.finish_step();
        groups
    }

    /// Rapier's substeps for a piece of `piece` (s) of the step: native
    /// Rapier's substep, with the bodies that turn fast kept at the frame's
    /// count per piece ([`Cadence`]).
    fn piece_cadence(&mut self, parts: &mut StepParts<'_>, piece: Real) -> usize {
        let frame = parts.integration_parameters;
        let n = frame.num_solver_iterations;
        let kept = Cadence::piece_iterations(n, f64::from(piece), f64::from(frame.dt));
        self.cadence.begin_piece(
            parts.islands,
            &self.added,
            parts.bodies,
            parts.colliders,
            n,
            kept,
            Cadence::TURNING_SHARE * self.effective.min_approach_speed,
        );
        kept
    }

    /// How many equal sub-steps a step of `dt` (s) may take
    /// ([`ToppleSettings::max_substep`], at most 1,000; native Rapier never
    /// sub-steps).
    fn substeps(&self, dt: f64) -> usize {
        if self.hooks.mode == ImpactResponse::Topple {
            self.settings.substeps(dt)
        } else {
            1
        }
    }

    /// Before a step: the settings in the world's units, the work budget,
    /// the hook's threshold.
    fn prepare(&mut self, gravity: Vector, params: &IntegrationParameters, substeps: usize) {
        self.effective = scale::effective(&self.settings, gravity, params);
        let rebound = scale::rebound_threshold(&self.settings, gravity, params, substeps);
        self.hooks
            .begin_frame(self.effective.min_approach_speed, rebound);
        self.hooks.stand_aside = false;
        self.pass.work_left = self.settings.fallback.max_work;
    }

    /// After a step: the notices of colliders left to Rapier, once each.
    fn finish_step(&mut self) {
        let first = self.notices.len();
        self.hooks.take_left(&mut self.notices);
        let mut k = first;
        while k < self.notices.len() {
            if self.hooks.reported.insert(self.notices[k]) {
                k += 1;
            } else {
                self.notices.swap_remove(k);
            }
        }
        self.stats.native_impacts = self.hooks.native_impacts();
    }

    /// Records the start poses of a piece of the step (the awake bodies, and
    /// the bodies added since the last step).
    /// `later`: not the step's first piece (the poses the last pass read
    /// are carried over).
    fn begin_piece(&mut self, parts: &StepParts<'_>, later: bool) {
        self.record_start(parts.islands, parts.bodies, later);
        if self.hooks.mode == ImpactResponse::Topple {
            for &b in &self.added {
                self.pass.motion.record_added(parts.bodies, b);
            }
        }
    }

    /// Puts the colliders managed since the last step into Rapier's broad
    /// phase at their bodies' present poses, and notes their bodies, so that
    /// the sweep of this step finds them: Rapier lists a new body as awake
    /// and a new collider in its broad phase only after its next step, and a
    /// world's first step used to miss every impact in it (a block pushed
    /// into its neighbour within the first 1/60 s went 0.23 h deep, as in
    /// native Rapier). Rapier's own update of the broad phase then finds
    /// them in place.
    fn insert_fresh(&mut self, parts: &mut StepParts<'_>) {
        self.added.clear();
        for h in self.fresh.drain(..) {
            let Some(co) = parts.colliders.get(h) else {
                continue;
            };
            self.added.extend(co.parent());
            let pose = match (
                co.parent().and_then(|b| parts.bodies.get(b)),
                co.position_wrt_parent(),
            ) {
                (Some(rb), Some(offset)) => *rb.position() * *offset,
                _ => *co.position(),
            };
            let aabb = co.shape().compute_aabb(&pose);
            parts
                .broad_phase
                .set_aabb(parts.integration_parameters, h, aabb);
        }
    }

    /// The predicted instant (s from now, within `horizon`) at which the
    /// next managed pair closes, if any: none in native mode or once the
    /// step's budget is spent.
    fn predict(&mut self, parts: &StepParts<'_>, horizon: Real) -> Prediction {
        if self.hooks.mode != ImpactResponse::Topple || self.hooks.stand_aside || horizon <= 0.0 {
            return Prediction::default();
        }
        let start = Instant::now();
        let params = parts.integration_parameters;
        let world = World {
            bodies: parts.bodies,
            colliders: parts.colliders,
            narrow_phase: parts.narrow_phase,
            broad_phase: parts.broad_phase,
            prediction: f64::from(params.prediction_distance()),
            allowed: f64::from(params.allowed_linear_error()),
            length_unit: length_unit(params),
        };
        let predicted = self
            .pass
            .predict(&world, &self.hooks, &self.effective, f64::from(horizon));
        self.stats.topple_seconds += start.elapsed().as_secs_f64();
        predicted
    }

    /// Before Rapier's step of the given gravity and parameters (an app
    /// that steps Rapier itself): the step's settings in the world's units,
    /// and where the awake bodies start from.
    pub fn begin_step(
        &mut self,
        gravity: Vector,
        integration_parameters: &IntegrationParameters,
        islands: &IslandManager,
        bodies: &RigidBodySet,
    ) {
        self.pass.clear_step();
        self.prepare(gravity, integration_parameters, 1);
        self.record_start(islands, bodies, false);
    }

    fn record_start(&mut self, islands: &IslandManager, bodies: &RigidBodySet, carry: bool) {
        if self.hooks.mode == ImpactResponse::Topple {
            let start = Instant::now();
            self.pass.motion.record_start(islands, bodies, carry);
            self.stats.topple_seconds += start.elapsed().as_secs_f64();
        }
    }

    /// After Rapier's step (run with [`ToppleRapier::hooks`]): the impact
    /// pass and the new velocities and poses written back. Returns the
    /// number of impact groups resolved.
    pub fn end_step(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
        broad_phase: &BroadPhaseBvh,
        integration_parameters: &IntegrationParameters,
    ) -> usize {
        let groups = self.pass_after(
            bodies,
            colliders,
            narrow_phase,
            broad_phase,
            integration_parameters,
            0.0,
        );
        self.finish_step();
        groups
    }

    /// The impact pass after one Rapier step that started `offset` (s) into
    /// the caller's step.
    fn pass_after(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
        broad_phase: &BroadPhaseBvh,
        integration_parameters: &IntegrationParameters,
        offset: f64,
    ) -> usize {
        if self.hooks.mode != ImpactResponse::Topple || self.hooks.stand_aside {
            return 0;
        }
        let start = Instant::now();
        let world = World {
            bodies,
            colliders,
            narrow_phase,
            broad_phase,
            prediction: f64::from(integration_parameters.prediction_distance()),
            allowed: f64::from(integration_parameters.allowed_linear_error()),
            length_unit: length_unit(integration_parameters),
        };
        let first = self.pass.reports.len();
        let work = self.pass.work;
        let dt: Real = integration_parameters.dt;
        let groups = self
            .pass
            .run(&world, &self.hooks, &self.effective, dt, offset);
        self.pass.write_back(bodies);
        self.stats.record(&self.pass.reports[first..]);
        self.stats.work += self.pass.work - work;
        if self.pass.work_left == Some(0) {
            // the budget is spent: Rapier's own response to the end of the step
            self.hooks.stand_aside = true;
            self.stats.budget_spent += 1;
        }
        self.stats.topple_seconds += start.elapsed().as_secs_f64();
        groups
    }
}
