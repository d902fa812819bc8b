//! Candidates: the pairs that may close during the step.

use super::super::backend::math::{Pose, Real};
use super::super::backend::parry::bounding_volume::BoundingVolume;
use super::super::backend::parry::query::DefaultQueryDispatcher;
use super::super::backend::prelude::{ColliderHandle, QueryFilter, RigidBody, RigidBodyHandle};
use super::super::hooks::{pair_key, ToppleHooks};
use super::super::support;
use super::{body_index, body_pose, Candidate, ImpactPass, World};

/// colliders.
fn body_radius(world: &World, rb: &RigidBody) -> f64 {
    let com = rb.local_center_of_mass();
    rb.colliders()
        .iter()
        .filter_map(|&c| world.colliders.get(c))
        .map(|co| {
            let sphere = co.shape().compute_local_bounding_sphere();
            let offset = co.position_wrt_parent().copied().unwrap_or(Pose::IDENTITY);
            let centre = offset.transform_point(sphere.center()) - com;
            f64::from(centre.length()) + f64::from(sphere.radius())
        })
        .fold(0.0, f64::max)
}

/// The impact threshold of a managed pair (world units/s), as the hook
/// sets it ([`ToppleHooks::threshold_of`]): the frame's if Rapier held any
/// of its manifolds lately (the stamp the hook leaves) or the pair is
/// plastic, the rebound threshold otherwise, also for a pair not in
/// Rapier's narrow phase (docs/bevy.md, "Rebounds and chatter").
fn pair_threshold(world: &World, hooks: &ToppleHooks, a: ColliderHandle, b: ColliderHandle) -> f64 {
    let restitution = hooks.pair(a, b).map_or(0.0, |m| m.impact.restitution);
    let stamp = world.narrow_phase.contact_pair(a, b).and_then(|pair| {
        pair.manifolds
            .iter()
            .map(|m| m.data.user_data)
            .find(|&s| hooks.held_lately(s))
    });
    hooks.threshold_of(stamp.unwrap_or(0), restitution)
}

impl ImpactPass {
    /// The bounding radius of a body (m), cached: computed again only when
    /// its number of colliders changes (a collider whose shape is replaced in
    /// place keeps the old radius; the hook still notes the pairs it closes
    /// within Rapier's prediction distance).
    pub(super) fn radius(&mut self, world: &World, h: RigidBodyHandle, rb: &RigidBody) -> f64 {
        let i = body_index(h);
        if self.radii.len() <= i {
            self.radii.resize(i + 1, (0.0, usize::MAX, None));
        }
        let count = rb.colliders().len();
        if self.radii[i].1 != count || self.radii[i].2 != Some(h) {
            self.radii[i] = (body_radius(world, rb), count, Some(h));
        }
        self.radii[i].0
    }

    /// A cheap bound on how far a point of body `h` travels over the pass's
    /// span: from its recorded start pose when there is one, else from its
    /// velocity (m).
    pub(super) fn rough_reach(
        &mut self,
        world: &World,
        h: RigidBodyHandle,
        start: Option<([f64; 2], f64)>,
    ) -> f64 {
        let Some(rb) = world.bodies.get(h) else {
            return 0.0;
        };
        let radius = self.radius(world, h, rb);
        let (v, w) = (rb.linvel(), f64::from(rb.angvel()).abs());
        let by_velocity = (f64::from(v.length()) + w * radius) * self.motion.dt;
        match start {
            Some((com0, angle0)) => {
                let (com, angle) = super::super::motion::com_and_angle(rb);
                self.motion.note_end(h, com, angle);
                let moved =
                    (com[0] - com0[0]).hypot(com[1] - com0[1]) + (angle - angle0).abs() * radius;
                moved.max(by_velocity)
            }
            None => by_velocity,
        }
    }

    pub(super) fn managed(
        &self,
        hooks: &ToppleHooks,
        a: ColliderHandle,
        b: ColliderHandle,
    ) -> bool {
        hooks.pair(a, b).is_some()
    }

    pub(super) fn add_candidate(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        a: ColliderHandle,
        b: ColliderHandle,
    ) {
        let key = pair_key(a, b);
        if !self.managed(hooks, a, b) || self.candidates.iter().any(|c| c.key == key) {
            return;
        }
        // pairs topple leaves to Rapier are never candidates (the hook
        // leaves their points to Rapier's solver)
        let Ok(geometry) = support::pair(world.bodies, world.colliders, a, b) else {
            return;
        };
        self.candidates.push(Candidate {
            colliders: [a, b],
            geometry,
            key,
            toi: f64::INFINITY,
            done: false,
            threshold: match geometry {
                // as the hook: composite shapes keep the frame's threshold
                support::Geometry::Convex => pair_threshold(world, hooks, a, b),
                support::Geometry::Composite => hooks.min_approach_speed,
            },
        });
    }

    /// Adds the pairs body `h` sweeps into over the rest of the step, if it
    /// travels further than half Rapier's prediction distance (closer pairs
    /// are in Rapier's narrow phase, and the hook notes those).
    pub(super) fn sweep(&mut self, world: &World, hooks: &ToppleHooks, h: RigidBodyHandle) {
        let Some(rb) = world.bodies.get(h) else {
            return;
        };
        if !rb
            .colliders()
            .iter()
            .any(|&c| hooks.material_of(c).is_some())
        {
            return;
        }
        let radius = self.radius(world, h, rb);
        let path = *self.motion.path(h, rb);
        if path.reach(radius) <= 0.5 * world.prediction {
            return;
        }
        let dt = self.motion.dt;
        let (start, end) = (path.at(path.t0, dt), path.at(dt, dt));
        // a turning body's points leave the chord by at most r·|Δθ|/2
        let bulge = (0.5 * radius * (path.angle1 - path.angle0).abs()).min(radius);
        self.found.clear();
        for &c in rb.colliders() {
            let Some(co) = world.colliders.get(c) else {
                continue;
            };
            let offset = co.position_wrt_parent().copied().unwrap_or(Pose::IDENTITY);
            let pose = |(com, angle): ([f64; 2], f64)| body_pose(rb, com, angle) * offset;
            let swept = co
                .shape()
                .compute_aabb(&pose(start))
                .merged(&co.shape().compute_aabb(&pose(end)))
                .loosened(bulge as Real);
            let query = world.broad_phase.as_query_pipeline(
                &DefaultQueryDispatcher,
                world.bodies,
                world.colliders,
                QueryFilter::default().exclude_rigid_body(h),
            );
            self.found.extend(
                query
                    .intersect_aabb_conservative(swept)
                    .map(|(o, _)| (o, false)),
            );
            for k in 0..self.found.len() {
                let other = self.found[k].0;
                self.add_candidate(world, hooks, c, other);
            }
            self.found.clear();
        }
    }
}
