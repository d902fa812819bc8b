//! The rapier2d-f64 adapter: reads the current state of a Rapier world into
//! plain data, lets [`ImpactGroups`] resolve the impacts, writes velocities
//! back. Everything physical lives in the engine-agnostic modules.

use rapier2d_f64::parry::query::{
    ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher,
};
use rapier2d_f64::prelude::{
    ActiveHooks, ColliderHandle, ColliderSet, NarrowPhase, PhysicsWorld, RigidBody,
    RigidBodyHandle, RigidBodySet, Vector,
};

use crate::impact::{Body, ImpactError};

use super::group::{seed_approach, ImpactGroups, ImpactReport, PointContact, ToppleSettings};
use super::hooks::{HookMode, ToppleHooks};
use super::material::{MaterialId, PairMaterial};
use super::patch::{for_each_contact_point, ManifoldPoint};

/// Running totals over all resolve passes.
///
/// ```
/// use topple::rapier::{ToppleRapier, ToppleSettings};
/// assert_eq!(ToppleRapier::new(ToppleSettings::default()).stats().impacts, 0);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ToppleStats {
    /// Candidate pairs queried at the current positions.
    pub pairs_queried: u64,
    /// Closed contact points found (λ points counted one by one).
    pub contact_points: u64,
    /// Impacts resolved.
    pub impacts: u64,
    /// Resolver impulse steps, summed.
    pub impulse_steps: u64,
}

/// LZB impacts for a rapier2d-f64 world.
///
/// Register the colliders topple manages with a material; step the world
/// with [`ToppleRapier::step`] (or run your own `PhysicsPipeline::step` with
/// [`ToppleRapier::hooks`] and call [`ToppleRapier::resolve_impacts`] after
/// it). Pairs of managed colliders get their impacts from the LZB resolver;
/// everything else is plain Rapier.
///
/// ```
/// use rapier2d_f64::prelude::*;
/// use topple::impact::ContactMaterial;
/// use topple::rapier::{PairMaterial, ToppleRapier, ToppleSettings};
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
/// topple.step(&mut world).unwrap();
/// assert!(world.bodies[balls[0]].linvel().x.abs() < 1e-3);
/// assert!((world.bodies[balls[1]].linvel().x - 1.0).abs() < 1e-3);
/// ```
#[derive(Debug)]
pub struct ToppleRapier {
    hooks: ToppleHooks,
    settings: ToppleSettings,
    groups: ImpactGroups,
    bodies: Vec<Body>,
    handles: Vec<RigidBodyHandle>,
    slot: Vec<u32>,
    contacts: Vec<PointContact>,
    manifold: ContactManifold<(), ()>,
    points: Vec<ManifoldPoint>,
    closed_now: Vec<u64>,
    /// Sleeping bodies given a slot in this pass (only they need expanding).
    sleeping_slots: usize,
    reports: Vec<ImpactReport>,
    stats: ToppleStats,
}

const NO_SLOT: u32 = u32::MAX;

/// A collider pair as one number (arena indices, smaller first).
pub(crate) fn pair_key(a: ColliderHandle, b: ColliderHandle) -> u64 {
    let (a, b) = (a.into_raw_parts().0 as u64, b.into_raw_parts().0 as u64);
    (a.min(b) << 32) | a.max(b)
}

/// A dynamic body Rapier integrates this step.
fn is_awake(rb: &RigidBody) -> bool {
    rb.is_dynamic() && !rb.is_sleeping()
}

fn v2(v: Vector) -> [f64; 2] {
    [v.x, v.y]
}

impl ToppleRapier {
    /// topple resolving impacts with the given settings.
    pub fn new(settings: ToppleSettings) -> Self {
        Self::with_mode(settings, HookMode::Topple)
    }

    /// A native-Rapier twin: the same per-pair friction and restitution, but
    /// Rapier resolves impacts and [`ToppleRapier::resolve_impacts`] does
    /// nothing. For comparisons.
    pub fn native() -> Self {
        Self::with_mode(ToppleSettings::default(), HookMode::Native)
    }

    fn with_mode(settings: ToppleSettings, mode: HookMode) -> Self {
        ToppleRapier {
            hooks: ToppleHooks::new(mode),
            settings: ToppleSettings::default(),
            groups: ImpactGroups::default(),
            bodies: Vec::new(),
            handles: Vec::new(),
            slot: Vec::new(),
            contacts: Vec::new(),
            manifold: ContactManifold::new(),
            points: Vec::new(),
            closed_now: Vec::new(),
            sleeping_slots: 0,
            reports: Vec::new(),
            stats: ToppleStats::default(),
        }
        .with_settings(settings)
    }

    fn with_settings(mut self, settings: ToppleSettings) -> Self {
        self.set_settings(settings);
        self
    }

    /// The settings of the impact pass.
    pub fn settings(&self) -> &ToppleSettings {
        &self.settings
    }

    /// Changes the settings (between steps).
    pub fn set_settings(&mut self, settings: ToppleSettings) {
        self.settings = settings;
        self.hooks.min_approach_speed = settings.min_approach_speed;
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
    /// the collider's contact-modification hook).
    pub fn manage(
        &mut self,
        colliders: &mut ColliderSet,
        collider: ColliderHandle,
        material: MaterialId,
    ) {
        assert!(
            (material.0 as usize) < self.hooks.table.len(),
            "unknown material"
        );
        self.hooks.set(collider, material);
        let co = &mut colliders[collider];
        co.set_active_hooks(co.active_hooks() | ActiveHooks::MODIFY_SOLVER_CONTACTS);
    }

    /// The hooks to hand to `PhysicsPipeline::step`.
    pub fn hooks(&self) -> &ToppleHooks {
        &self.hooks
    }

    /// Impacts resolved by the last [`ToppleRapier::resolve_impacts`].
    pub fn last_impacts(&self) -> &[ImpactReport] {
        &self.reports
    }

    /// The grouping stage (e.g. [`ImpactGroups::last_group`] after an error).
    pub fn impact_groups(&self) -> &ImpactGroups {
        &self.groups
    }

    /// Totals since creation.
    pub fn stats(&self) -> ToppleStats {
        self.stats
    }

    /// One step of a [`PhysicsWorld`]: Rapier steps with topple's hooks (which
    /// keep Rapier's solver off approaching contacts of managed pairs), then
    /// the impacts at the new positions are resolved. Returns the number of
    /// impacts resolved.
    pub fn step(&mut self, world: &mut PhysicsWorld) -> Result<usize, ImpactError> {
        world.step_with_events(&self.hooks, &());
        self.resolve_impacts(&mut world.bodies, &world.colliders, &world.narrow_phase)
    }

    fn slot_of(&mut self, bodies: &RigidBodySet, handle: Option<RigidBodyHandle>) -> Option<usize> {
        let h = handle?;
        let rb = &bodies[h];
        if !rb.is_dynamic() {
            return None; // fixed and kinematic bodies act as the fixed world
        }
        let i = h.into_raw_parts().0 as usize;
        if self.slot.len() <= i {
            self.slot.resize(i + 1, NO_SLOT);
        }
        if self.slot[i] == NO_SLOT {
            self.slot[i] = self.bodies.len() as u32;
            self.sleeping_slots += rb.is_sleeping() as usize;
            let inv_i = rb.mass_properties().effective_world_inv_inertia;
            self.bodies.push(Body {
                mass: rb.mass(),
                inertia: if inv_i > 0.0 {
                    1.0 / inv_i
                } else {
                    f64::INFINITY
                },
                position: v2(rb.center_of_mass()),
                angle: rb.rotation().angle(),
                velocity: v2(rb.linvel()),
                angular_velocity: rb.angvel(),
                fixed: false,
            });
            self.handles.push(h);
        }
        Some(self.slot[i] as usize)
    }

    /// Queries the pairs of the `k`-th body (if it sleeps) with bodies that
    /// are not awake (fixed, or sleeping and not expanded yet).
    fn expand_sleeping(
        &mut self,
        k: usize,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
    ) {
        let Some(rb) = bodies.get(self.handles[k]) else {
            return;
        };
        if !rb.is_sleeping() {
            return;
        }
        for &collider in rb.colliders() {
            for pair in narrow_phase.contact_pairs_with(collider) {
                let other = if pair.collider1 == collider {
                    pair.collider2
                } else {
                    pair.collider1
                };
                let other_body = colliders
                    .get(other)
                    .and_then(|co| co.parent())
                    .and_then(|h| bodies.get(h).map(|rb| (h, rb)));
                let skip = other_body.is_some_and(|(h, rb)| {
                    let slot = self
                        .slot
                        .get(h.into_raw_parts().0 as usize)
                        .copied()
                        .unwrap_or(NO_SLOT);
                    // awake: queried in the first pass; expanded: queried then
                    is_awake(rb) || (slot != NO_SLOT && (slot as usize) < k)
                });
                if !skip {
                    self.query_pair(pair.collider1, pair.collider2, bodies, colliders);
                }
            }
        }
    }

    /// Queries one candidate pair of managed convex colliders at the current
    /// positions; its closed points become [`PointContact`]s (λ points on a
    /// flat patch) and the pair is recorded as closed.
    fn query_pair(
        &mut self,
        collider1: ColliderHandle,
        collider2: ColliderHandle,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
    ) {
        let Some(material) = self.hooks.pair(collider1, collider2).map(|m| m.impact) else {
            return;
        };
        let (Some(co1), Some(co2)) = (colliders.get(collider1), colliders.get(collider2)) else {
            return;
        };
        if !(co1.shape().is_convex() && co2.shape().is_convex()) {
            return;
        }
        let rule = self.settings.patch;
        self.stats.pairs_queried += 1;
        let (pos1, pos2) = (co1.position(), co2.position());
        let pos12 = pos1.inv_mul(pos2);
        self.manifold.clear();
        if DefaultQueryDispatcher
            .contact_manifold_convex_convex(
                &pos12,
                co1.shape(),
                co2.shape(),
                None,
                None,
                rule.closed_tolerance.max(0.0),
                &mut self.manifold,
            )
            .is_err()
            || self.manifold.points.is_empty()
        {
            return;
        }
        let normal = v2(pos1.transform_vector(self.manifold.local_n1).normalize());
        self.points.clear();
        for p in &self.manifold.points {
            let a = pos1.transform_point(p.local_p1);
            let b = pos2.transform_point(p.local_p2);
            self.points.push(ManifoldPoint {
                point: [0.5 * (a.x + b.x), 0.5 * (a.y + b.y)],
                dist: p.dist,
            });
        }
        if !self.points.iter().any(|p| p.dist <= rule.closed_tolerance) {
            return;
        }
        let b1 = self.slot_of(bodies, co1.parent());
        let b2 = self.slot_of(bodies, co2.parent());
        if b1.is_none() && b2.is_none() {
            return;
        }
        let key = pair_key(collider1, collider2);
        let persistent = self.hooks.was_closed(key);
        self.closed_now.push(key);
        let contacts = &mut self.contacts;
        for_each_contact_point(&self.points, &rule, |point, dist| {
            contacts.push(PointContact {
                bodies: [b1, b2],
                point,
                normal,
                dist,
                material,
                persistent,
            })
        });
    }

    /// Resolves the impacts at the current positions of a Rapier world and
    /// writes the post-impact velocities back (waking the bodies). Only pairs
    /// in Rapier's contact graph with both colliders managed are queried: those
    /// with at least one awake dynamic body, and the pairs of a sleeping body
    /// that such a pair touches (so a struck sleeping body keeps its
    /// supports); pairs of non-convex shapes are skipped. Returns the number
    /// of impacts resolved.
    pub fn resolve_impacts(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
    ) -> Result<usize, ImpactError> {
        self.reports.clear();
        if self.hooks.mode == HookMode::Native {
            return Ok(0);
        }
        self.bodies.clear();
        self.handles.clear();
        self.contacts.clear();
        self.closed_now.clear();
        self.sleeping_slots = 0;
        let awake =
            |h: Option<RigidBodyHandle>| h.and_then(|h| bodies.get(h)).is_some_and(is_awake);
        for pair in narrow_phase.contact_pairs() {
            let (Some(co1), Some(co2)) =
                (colliders.get(pair.collider1), colliders.get(pair.collider2))
            else {
                continue;
            };
            if awake(co1.parent()) || awake(co2.parent()) {
                self.query_pair(pair.collider1, pair.collider2, bodies, colliders);
            }
        }
        // A sleeping body that an impact reaches brings its own closed
        // contacts (its support, the stack it sits in), which the pass above
        // skipped: Rapier has not moved it. Only when there is an impact, and
        // breadth first by generations: the sleeping bodies found so far,
        // then those they touch, as far as the impact window reaches; a pair
        // of two sleeping bodies is queried once, by the one expanded first.
        // Sleeping bodies found beyond the window stay where they are (fixed).
        // (The seed scan is repeated by `ImpactGroups::resolve`; it is done
        // here only when a sleeping body was touched, which is rare.)
        let expand = self.sleeping_slots > 0
            && self
                .contacts
                .iter()
                .any(|c| seed_approach(&self.bodies, c, &self.settings).is_some());
        if expand {
            let generations = self.settings.max_group_hops.map_or(usize::MAX, |h| h + 1);
            let (mut next, mut generation) = (0, 0);
            while next < self.handles.len() && generation < generations {
                let end = self.handles.len();
                for k in next..end {
                    self.expand_sleeping(k, bodies, colliders, narrow_phase);
                }
                next = end;
                generation += 1;
            }
            for k in next..self.handles.len() {
                if bodies
                    .get(self.handles[k])
                    .is_some_and(|rb| rb.is_sleeping())
                {
                    self.bodies[k].fixed = true;
                }
            }
        }
        self.stats.contact_points += self.contacts.len() as u64;
        let result = self.groups.resolve(
            &mut self.bodies,
            &self.contacts,
            &self.settings,
            &mut self.reports,
        );
        // The closed pairs of this pass are the persistent ones of the next.
        // Pairs of sleeping bodies were not queried: keep them from before.
        self.hooks
            .keep_sleeping_closed(&mut self.closed_now, |key| {
                let c = |i: u32| colliders.get_unknown_gen(i).map(|(c, _)| c);
                let (a, b) = ((key >> 32) as u32, key as u32);
                let asleep = |co: Option<&rapier2d_f64::prelude::Collider>| {
                    co.and_then(|co| co.parent())
                        .and_then(|h| bodies.get(h))
                        .is_none_or(|rb| !is_awake(rb))
                };
                asleep(c(a)) && asleep(c(b))
            });
        // Reset the slot map (only the entries used), then write back.
        for h in &self.handles {
            self.slot[h.into_raw_parts().0 as usize] = NO_SLOT;
        }
        let groups = result?;
        if groups > 0 {
            for (h, b) in self.handles.iter().zip(&self.bodies) {
                let (v, w) = (
                    Vector::new(b.velocity[0], b.velocity[1]),
                    b.angular_velocity,
                );
                // Compare through a shared borrow: `IndexMut` records the body
                // in Rapier's modified list (work and, after each step, an
                // allocation), which only bodies the impact changed need.
                let unchanged = bodies
                    .get(*h)
                    .is_some_and(|rb| rb.linvel() == v && rb.angvel() == w);
                if !unchanged {
                    let rb = &mut bodies[*h];
                    rb.set_linvel(v, true);
                    rb.set_angvel(w, true);
                }
            }
            self.stats.impacts += groups as u64;
            self.stats.impulse_steps += self.reports.iter().map(|r| r.steps as u64).sum::<u64>();
        }
        Ok(groups)
    }
}
