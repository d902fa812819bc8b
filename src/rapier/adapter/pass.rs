//! The impact pass after Rapier's step: impacts at the instant their pair
//! closes, inside the step (see the design notes of [`crate::rapier`]).
//!
//! | stage | what |
//! | --- | --- |
//! | candidates | pairs the hook took approaching points from, and pairs a fast body sweeps into (a swept box against Rapier's broad phase) |
//! | time of impact | for each candidate that is closed at the end of the step, the first instant τ its gap closes along the bodies' straight paths (bracketed, then regula falsi) |
//! | group | at the earliest τ: the bodies connected to the closing pair through closed contacts (breadth first, within the impact window), their contacts from parry at the poses of τ, λ points on flat patches |
//! | resolve | [`ImpactGroups`]: the LZB resolver with the fallback policy |
//! | continue | each body whose velocity changed moves on from τ with its new velocity; its pairs get new times of impact; repeat to the end of the step |
//! | write back | new velocities, and the poses at the end of the step, into Rapier |

use super::backend::math::{Pose, Real, Vector};
use super::backend::parry::bounding_volume::BoundingVolume;
use super::backend::parry::query::{
    ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher,
};
use super::backend::parry::shape::{Shape, ShapeType};
use super::backend::prelude::{
    BroadPhaseBvh, Collider, ColliderHandle, ColliderSet, NarrowPhase, QueryFilter, RigidBody,
    RigidBodyHandle, RigidBodySet,
};

use super::hooks::{pair_key, ToppleHooks};
use super::motion::{Motion, Path};
use super::support::{self, Geometry, Role, LOCKED_INERTIA};
use crate::coupling::{
    for_each_contact_point, FallbackPolicy, ImpactGroups, ImpactReport, ManifoldPoint,
    PointContact, ToppleSettings,
};
use crate::impact::Body;

/// A pair that may close during the step.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    colliders: [ColliderHandle; 2],
    geometry: Geometry,
    key: u64,
    /// Time of impact within the step (s), `f64::INFINITY` if it does not close.
    toi: f64,
    /// Resolved (or found not to approach) in this step.
    done: bool,
}

/// One group of bodies resolved at one instant of the step.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ImpactEvent {
    /// Instant of the impact, from the start of the step (s).
    pub time_in_step: f64,
    /// What the resolver did.
    pub report: ImpactReport,
    /// Range of [`super::ToppleRapier::event_bodies`] holding its bodies.
    pub bodies: (usize, usize),
    /// Range of [`super::ToppleRapier::event_contacts`] holding its contacts.
    pub contacts: (usize, usize),
}

/// One contact of a resolved impact, with the impulse it carried.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpactContact {
    /// The two bodies (`None`: a fixed or kinematic body, the world).
    pub bodies: [Option<RigidBodyHandle>; 2],
    /// Contact point, world frame (m).
    pub point: [f64; 2],
    /// Unit normal from the first body to the second.
    pub normal: [f64; 2],
    /// Normal impulse on the second body (N·s), ≥ 0.
    pub normal_impulse: f64,
    /// Tangential impulse on the second body along (−n_y, n_x) (N·s).
    pub tangent_impulse: f64,
}

/// What the pass reads from Rapier.
pub(crate) struct World<'a> {
    pub bodies: &'a RigidBodySet,
    pub colliders: &'a ColliderSet,
    pub narrow_phase: &'a NarrowPhase,
    pub broad_phase: &'a BroadPhaseBvh,
    /// Rapier's prediction distance (m): pairs closer at the start of the
    /// step are in its narrow phase.
    pub prediction: f64,
    /// Rapier's allowed penetration (m): a gap this small counts as touching.
    pub allowed: f64,
    /// Rapier's length unit (world units): the scale of the world.
    pub length_unit: f64,
}

/// What [`ImpactPass::predict`] sees ahead.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Prediction {
    /// The earliest instant (s from now) at which a managed pair that is
    /// open now closes along straight paths at the present velocities.
    pub closing: Option<f64>,
    /// A managed body that moves (further than half Rapier's prediction
    /// distance over the horizon) touches another managed collider: smooth
    /// contact dynamics such as a leaning domino train.
    pub moving_contact: bool,
}

/// Impacts resolved at one instant at most per step and pass: a safety net
/// against a pass that would never end; later ones wait for the next step.
const MAX_EVENTS: usize = 64;

/// Iterations of the time-of-impact search at most.
const TOI_ITERATIONS: usize = 64;

/// The pass's buffers, kept between steps.
#[derive(Debug, Default)]
pub(crate) struct ImpactPass {
    pub motion: Motion,
    noted: Vec<u64>,
    candidates: Vec<Candidate>,
    groups: ImpactGroups,
    bodies: Vec<Body>,
    handles: Vec<RigidBodyHandle>,
    depth: Vec<usize>,
    slot: Vec<u32>,
    contacts: Vec<PointContact>,
    /// The manifolds of the pair being queried: one for two convex shapes,
    /// one per pair of sub-shapes for a composite shape.
    manifolds: Vec<ContactManifold<(), ()>>,
    /// The same pair queried the other way round (see `manifolds_of`).
    spare: Vec<ContactManifold<(), ()>>,
    points: Vec<ManifoldPoint>,
    found: Vec<(ColliderHandle, bool)>,
    /// Pairs queried for the group being built.
    queried: Vec<u64>,
    /// Bounding radius (m) about the centre of mass of each body swept so
    /// far, by arena index, with the body and collider count it was taken
    /// for.
    radii: Vec<(f64, usize, Option<RigidBodyHandle>)>,
    pub reports: Vec<ImpactReport>,
    pub events: Vec<ImpactEvent>,
    pub event_bodies: Vec<RigidBodyHandle>,
    pub event_contacts: Vec<ImpactContact>,
    pub pairs_queried: u64,
    pub contact_points: u64,
    /// Work of the resolver so far ([`FallbackPolicy::max_work`]).
    pub work: u64,
    /// What is left of the step's work budget (`None`: no budget).
    pub work_left: Option<u64>,
}

const NO_SLOT: u32 = u32::MAX;

#[inline]
fn body_index(h: RigidBodyHandle) -> usize {
    h.into_raw_parts().0 as usize
}

fn vector(v: [f64; 2]) -> Vector {
    Vector::new(v[0] as Real, v[1] as Real)
}

fn v2(v: Vector) -> [f64; 2] {
    [f64::from(v.x), f64::from(v.y)]
}

/// `n` made unit in f64. The f32 build's normalised vectors are unit only
/// to f32 rounding (|n| − 1 up to about 10⁻⁷): the impact resolver makes
/// them unit again (`Contact::frame`), but the contact and its impulses
/// are reported with the f32 length, so velocities rebuilt from them miss
/// by that fraction of the gross impulse (3·10⁻⁴ of the speed scale for a
/// 10 g body between 10–35 kg ones). An f64 unit vector is left as it is.
fn unit(n: [f64; 2]) -> [f64; 2] {
    let len = n[0].hypot(n[1]);
    if (len - 1.0).abs() <= 4.0 * f64::EPSILON {
        n
    } else {
        [n[0] / len, n[1] / len]
    }
}

/// The body a collider is attached to if an impact moves it (a free body:
/// [`support::role`]); walls and bodies left to Rapier give `None`.
fn dynamic_parent(world: &World, co: &Collider) -> Option<RigidBodyHandle> {
    co.parent().filter(|&h| {
        world
            .bodies
            .get(h)
            .is_some_and(|rb| support::role(rb) == Role::Free)
    })
}

/// Largest distance (m) from a body's centre of mass to a point of its
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

impl ImpactPass {
    /// The bounding radius of a body (m), cached: computed again only when
    /// its number of colliders changes (a collider whose shape is replaced in
    /// place keeps the old radius; the hook still notes the pairs it closes
    /// within Rapier's prediction distance).
    fn radius(&mut self, world: &World, h: RigidBodyHandle, rb: &RigidBody) -> f64 {
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
    fn rough_reach(
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
                let (com, angle) = super::motion::com_and_angle(rb);
                let moved =
                    (com[0] - com0[0]).hypot(com[1] - com0[1]) + (angle - angle0).abs() * radius;
                moved.max(by_velocity)
            }
            None => by_velocity,
        }
    }

    /// The grouping stage.
    pub fn groups(&self) -> &ImpactGroups {
        &self.groups
    }

    /// Forgets the impacts of the last step (a step may run several passes
    /// when it is split).
    pub fn clear_step(&mut self) {
        self.reports.clear();
        self.events.clear();
        self.event_bodies.clear();
        self.event_contacts.clear();
    }

    /// Runs the pass over one Rapier step of length `dt` (s) that started
    /// `offset` (s) into the caller's step; returns the number of impact
    /// groups resolved. `bodies` is written at the end only.
    pub fn run(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        settings: &ToppleSettings,
        dt: Real,
        offset: f64,
    ) -> usize {
        self.motion.begin_pass(dt);
        self.candidates.clear();
        self.noted.clear();
        hooks.take_noted(&mut self.noted);
        self.noted.sort_unstable();
        self.noted.dedup();
        for k in 0..self.noted.len() {
            let key = self.noted[k];
            let c = |i: u64| world.colliders.get_unknown_gen(i as u32).map(|(_, h)| h);
            if let (Some(a), Some(b)) = (c(key >> 32), c(key & 0xffff_ffff)) {
                self.add_candidate(world, hooks, a, b);
            }
        }
        for s in 0..self.motion.starts().len() {
            let (h, com0, angle0) = self.motion.starts()[s];
            if self.rough_reach(world, h, Some((com0, angle0))) > 0.5 * world.prediction {
                self.sweep(world, hooks, h);
            }
        }
        for k in 0..self.candidates.len() {
            self.candidates[k].toi = self.time_of_impact(world, settings, k);
        }
        let mut groups = 0;
        for _ in 0..MAX_EVENTS {
            let Some(t) = self.earliest() else { break };
            groups += self.resolve_at(world, hooks, settings, t, offset);
        }
        groups
    }

    /// What the next `horizon` (s) holds if every awake body keeps its
    /// velocity ([`Prediction`]): where the caller splits Rapier's step, so
    /// that an impact is resolved near its instant and the smooth forces
    /// after it act on the post-impact velocities, and whether it sub-steps.
    /// Only bodies that move further than half Rapier's prediction distance
    /// are swept; slower closings are left to the pass after the step.
    pub fn predict(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        settings: &ToppleSettings,
        horizon: f64,
    ) -> Prediction {
        self.motion.begin_prediction(horizon);
        self.candidates.clear();
        for s in 0..self.motion.starts().len() {
            let h = self.motion.starts()[s].0;
            if self.rough_reach(world, h, None) > 0.5 * world.prediction {
                self.sweep(world, hooks, h);
            }
        }
        let mut out = Prediction::default();
        let touch = closed_tolerance(settings).max(world.allowed);
        for k in 0..self.candidates.len() {
            if self.gap(world, k, 0.0, touch).is_some() {
                // touching now: Rapier's, or an impact at once
                out.moving_contact = true;
                continue;
            }
            let t = self.time_of_impact(world, settings, k);
            if t.is_finite() && out.closing.is_none_or(|f| t < f) {
                out.closing = Some(t);
            }
        }
        self.candidates.clear();
        out
    }

    /// Writes the new velocities and end poses of every body an impact
    /// changed into Rapier (waking them).
    pub fn write_back(&mut self, bodies: &mut RigidBodySet) {
        for (h, path) in self.motion.changed() {
            let Some(rb) = bodies.get_mut(h) else {
                continue;
            };
            let angle = path.angle1 as Real;
            let local_com = rb.local_center_of_mass();
            let rotation = Pose::rotation(angle);
            let origin = vector(path.com1) - rotation.transform_vector(local_com);
            rb.set_position(Pose::new(origin, angle), true);
            rb.set_linvel(vector(path.velocity), true);
            // a body that cannot turn keeps its angular velocity (the
            // resolver's LOCKED_INERTIA leaves it a change below 10⁻¹²)
            if rb.mass_properties().effective_world_inv_inertia > 0.0 {
                rb.set_angvel(path.angular_velocity as Real, true);
            }
        }
    }

    fn managed(&self, hooks: &ToppleHooks, a: ColliderHandle, b: ColliderHandle) -> bool {
        hooks.pair(a, b).is_some()
    }

    fn add_candidate(
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
        });
    }

    /// Adds the pairs body `h` sweeps into over the rest of the step, if it
    /// travels further than half Rapier's prediction distance (closer pairs
    /// are in Rapier's narrow phase, and the hook notes those).
    fn sweep(&mut self, world: &World, hooks: &ToppleHooks, h: RigidBodyHandle) {
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

    /// Pose of collider `c` at time `t` of the step.
    fn collider_pose(&mut self, world: &World, c: ColliderHandle, t: f64) -> Option<Pose> {
        let co = world.colliders.get(c)?;
        match co
            .parent()
            .and_then(|h| world.bodies.get(h).map(|rb| (h, rb)))
        {
            Some((h, rb)) if rb.is_dynamic() => {
                let dt = self.motion.dt;
                let (com, angle) = self.motion.path(h, rb).at(t, dt);
                let offset = co.position_wrt_parent().copied().unwrap_or(Pose::IDENTITY);
                Some(body_pose(rb, com, angle) * offset)
            }
            _ => Some(*co.position()),
        }
    }

    /// Signed gap (m) of a candidate's pair at time `t`; `None` if beyond
    /// `reach` (m).
    fn gap(&mut self, world: &World, k: usize, t: f64, reach: f64) -> Option<f64> {
        let Candidate {
            colliders: [a, b],
            geometry,
            ..
        } = self.candidates[k];
        let pa = self.collider_pose(world, a, t)?;
        let pb = self.collider_pose(world, b, t)?;
        let (sa, sb) = (
            world.colliders.get(a)?.shape(),
            world.colliders.get(b)?.shape(),
        );
        self.pairs_queried += 1;
        // A composite shape is queried sub-shape by sub-shape within the
        // reach: only gaps near zero matter to the search.
        let reach = match geometry {
            Geometry::Convex => reach,
            Geometry::Composite => reach.min(4.0 * world.prediction.max(world.allowed)),
        };
        let count = self.manifolds_of(geometry, &pa, sa, &pb, sb, reach as Real);
        self.manifolds[..count]
            .iter()
            .flat_map(|m| m.points.iter().map(|p| f64::from(p.dist)))
            .min_by(f64::total_cmp)
    }

    /// Fills `manifolds` with the contact manifolds of two shapes at poses
    /// `pa` and `pb`, points within `reach`; returns how many there are.
    /// The manifold query (clipping for polygons) keeps its buffers; the
    /// plain contact query runs EPA when the pair penetrates, which
    /// allocates. Composite shapes allocate their sub-shape workspace.
    fn manifolds_of(
        &mut self,
        geometry: Geometry,
        pa: &Pose,
        sa: &dyn Shape,
        pb: &Pose,
        sb: &dyn Shape,
        reach: Real,
    ) -> usize {
        match geometry {
            Geometry::Convex => {
                // parry's GJK misses a segment touching a box flat at gaps
                // near 10⁻⁹ when the segment is the first shape (normal along
                // the segment, no points): the segment goes second, and the
                // manifold is flipped back.
                let swap = segment_like(sa) && !segment_like(sb);
                let (pos12, s1, s2) = if swap {
                    (pb.inv_mul(pa), sb, sa)
                } else {
                    (pa.inv_mul(pb), sa, sb)
                };
                if self.manifolds.is_empty() {
                    self.manifolds.push(ContactManifold::new());
                }
                let m = &mut self.manifolds[0];
                m.clear();
                let ok = DefaultQueryDispatcher
                    .contact_manifold_convex_convex(&pos12, s1, s2, None, None, reach, m);
                if swap {
                    flip_manifold(m);
                }
                usize::from(ok.is_ok())
            }
            Geometry::Composite => {
                let count =
                    composite_manifolds(&pa.inv_mul(pb), sa, sb, reach, &mut self.manifolds);
                // The same GJK miss for a sub-shape, in either order: when
                // some sub-shapes touch and others have no points, the pair
                // is queried again the other way round and each empty
                // manifold takes the other query's points.
                let partial = |ms: &[ContactManifold<(), ()>]| {
                    ms.iter().any(|m| m.points.is_empty())
                        && ms.iter().any(|m| !m.points.is_empty())
                };
                if partial(&self.manifolds[..count]) {
                    let other =
                        composite_manifolds(&pb.inv_mul(pa), sb, sa, reach, &mut self.spare);
                    for m in &mut self.spare[..other] {
                        flip_manifold(m);
                        if m.points.is_empty() {
                            continue;
                        }
                        let same = self.manifolds[..count]
                            .iter_mut()
                            .find(|k| k.subshape1 == m.subshape1 && k.subshape2 == m.subshape2);
                        if let Some(k) = same.filter(|k| k.points.is_empty()) {
                            std::mem::swap(k, m);
                        }
                    }
                }
                count
            }
        }
    }

    /// The segment start of a candidate: the later of its bodies' path starts.
    fn segment_start(&mut self, world: &World, k: usize) -> f64 {
        let mut t0: f64 = 0.0;
        for c in self.candidates[k].colliders {
            if let Some((h, rb)) = world
                .colliders
                .get(c)
                .and_then(|co| co.parent())
                .and_then(|h| world.bodies.get(h).map(|rb| (h, rb)))
            {
                if rb.is_dynamic() {
                    t0 = t0.max(self.motion.path(h, rb).t0);
                }
            }
        }
        t0
    }

    /// The first instant (s) a candidate's gap closes (≤ the closed
    /// tolerance) on its segment, if it is closed at the end of the step.
    /// The gap is sampled at four points to bracket its first closing, then
    /// the bracket is narrowed by regula falsi (Illinois) to within the
    /// tolerance or 10⁻⁹ of the step.
    fn time_of_impact(&mut self, world: &World, settings: &ToppleSettings, k: usize) -> f64 {
        let dt = self.motion.dt;
        let t0 = self.segment_start(world, k);
        let tol = closed_tolerance(settings);
        let far = 1e3 * world.prediction.max(tol) + world.length_unit;
        let gap = |pass: &mut Self, t: f64| pass.gap(world, k, t, far).unwrap_or(far);
        if gap(self, dt) > tol {
            return f64::INFINITY;
        }
        let (mut a, mut ga) = (t0, gap(self, t0));
        if ga <= tol {
            return t0;
        }
        let mut b = dt;
        let mut gb = gap(self, dt);
        for j in 1..4 {
            let t = t0 + (dt - t0) * j as f64 / 4.0;
            let g = gap(self, t);
            if g <= tol {
                (b, gb) = (t, g);
                break;
            }
            (a, ga) = (t, g);
        }
        // Illinois on f = g − tol/2: any t with |f| ≤ tol/2 is closed.
        let target = 0.5 * tol;
        let (mut fa, mut fb) = (ga - target, gb - target);
        let mut side = 0;
        for _ in 0..TOI_ITERATIONS {
            if b - a <= 1e-9 * dt {
                break;
            }
            let t = (a * fb - b * fa) / (fb - fa);
            let t = if t > a && t < b { t } else { 0.5 * (a + b) };
            let f = gap(self, t) - target;
            if f.abs() <= target {
                return t;
            }
            if f > 0.0 {
                (a, fa) = (t, f);
                if side == 1 {
                    fb *= 0.5;
                }
                side = 1;
            } else {
                (b, fb) = (t, f);
                if side == -1 {
                    fa *= 0.5;
                }
                side = -1;
            }
        }
        b
    }

    /// The earliest time of impact among the open candidates.
    fn earliest(&self) -> Option<f64> {
        self.candidates
            .iter()
            .filter(|c| !c.done && c.toi.is_finite())
            .map(|c| c.toi)
            .min_by(f64::total_cmp)
    }

    /// Resolves the impacts at time `t`: the candidates closing then, with
    /// the group around them; then lets the changed bodies move on.
    fn resolve_at(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        settings: &ToppleSettings,
        t: f64,
        offset: f64,
    ) -> usize {
        let at_once = 1e-9 * self.motion.dt;
        self.bodies.clear();
        self.handles.clear();
        self.contacts.clear();
        self.queried.clear();
        for k in 0..self.candidates.len() {
            let c = self.candidates[k];
            if c.done || c.toi > t + at_once {
                continue;
            }
            self.candidates[k].done = true;
            self.queried.push(c.key);
            self.query_pair(
                world,
                hooks,
                settings,
                c.colliders,
                t,
                world.allowed,
                false,
                0,
            );
        }
        self.expand_group(world, hooks, settings, t);
        self.contact_points += self.contacts.len() as u64;
        // the impacts of a step share its work budget
        let budgeted = ToppleSettings {
            fallback: FallbackPolicy {
                max_work: self.work_left,
                ..settings.fallback
            },
            ..*settings
        };
        let groups = self
            .groups
            .resolve(&mut self.bodies, &self.contacts, &budgeted);
        let work = self.groups.work();
        self.work += work;
        if let Some(left) = &mut self.work_left {
            *left = left.saturating_sub(work);
        }
        self.record(offset + t, groups);
        for h in &self.handles {
            self.slot[body_index(*h)] = NO_SLOT;
        }
        self.move_on(world, hooks, settings, t, groups);
        groups
    }

    /// Adds a dynamic body to the group being built, at its state of time `t`.
    fn add_body(&mut self, world: &World, h: RigidBodyHandle, t: f64, depth: usize) -> usize {
        let i = body_index(h);
        if self.slot.len() <= i {
            self.slot.resize(i + 1, NO_SLOT);
        }
        if self.slot[i] != NO_SLOT {
            return self.slot[i] as usize;
        }
        let rb = &world.bodies[h];
        let path = *self.motion.path(h, rb);
        let (com, angle) = path.at(t, self.motion.dt);
        let (velocity, angular_velocity) = if path.changed {
            (path.velocity, path.angular_velocity)
        } else {
            (v2(rb.linvel()), f64::from(rb.angvel()))
        };
        let inv_i = f64::from(rb.mass_properties().effective_world_inv_inertia);
        let mass = f64::from(rb.mass());
        let inertia = if inv_i > 0.0 {
            1.0 / inv_i
        } else {
            // a body that cannot turn (support::LOCKED_INERTIA)
            let r = self.radius(world, h, rb).max(world.length_unit);
            LOCKED_INERTIA * mass * r * r
        };
        self.slot[i] = self.bodies.len() as u32;
        self.bodies.push(Body {
            mass,
            inertia,
            position: com,
            angle,
            velocity,
            angular_velocity,
            fixed: false,
        });
        self.handles.push(h);
        self.depth.resize(self.handles.len(), 0);
        self.depth[self.handles.len() - 1] = depth;
        self.slot[i] as usize
    }

    /// Breadth first from the seed bodies: every managed pair of a group
    /// body (Rapier's narrow-phase pairs and this step's candidates) is
    /// queried at time `t`; a dynamic body it closes with joins the group
    /// while within the impact window (`max_group_hops`); pairs with bodies
    /// beyond are left out.
    fn expand_group(&mut self, world: &World, hooks: &ToppleHooks, s: &ToppleSettings, t: f64) {
        let hops = s.max_group_hops.unwrap_or(usize::MAX);
        let mut next = 0;
        while next < self.handles.len() {
            let (h, depth) = (self.handles[next], self.depth[next]);
            next += 1;
            let rb = &world.bodies[h];
            for &c in rb.colliders() {
                self.found.clear();
                for pair in world.narrow_phase.contact_pairs_with(c) {
                    let other = if pair.collider1 == c {
                        pair.collider2
                    } else {
                        pair.collider1
                    };
                    self.found.push((other, pair.has_any_active_contact()));
                }
                for k in &self.candidates {
                    match k.colliders {
                        [a, b] if a == c => self.found.push((b, false)),
                        [a, b] if b == c => self.found.push((a, false)),
                        _ => {}
                    }
                }
                for f in 0..self.found.len() {
                    let (other, active) = self.found[f];
                    // A pair Rapier holds in contact is touching at any
                    // instant of the step: the straight paths between the
                    // step's two poses open it by up to r·Δθ²/8 for a turning
                    // body, so its gap at `t` counts up to Rapier's
                    // prediction distance.
                    let touch = if active {
                        world.prediction.max(world.allowed)
                    } else {
                        world.allowed
                    };
                    let key = pair_key(c, other);
                    if self.queried.contains(&key) {
                        continue;
                    }
                    let other_body = world
                        .colliders
                        .get(other)
                        .and_then(|co| dynamic_parent(world, co));
                    if other_body.is_some_and(|o| self.slot_of(o).is_none()) && depth >= hops {
                        continue;
                    }
                    self.queried.push(key);
                    self.query_pair(world, hooks, s, [c, other], t, touch, true, depth + 1);
                }
            }
        }
        self.found.clear();
    }

    fn slot_of(&self, h: RigidBodyHandle) -> Option<usize> {
        self.slot
            .get(body_index(h))
            .copied()
            .filter(|&s| s != NO_SLOT)
            .map(|s| s as usize)
    }

    /// Queries one managed convex pair at time `t`; its points with a gap of
    /// at most `touch` (m) become contacts (λ points on a flat patch), and a
    /// dynamic body of a closed pair that is not in the group yet joins it at
    /// `depth` contacts from the seeds. Returns whether it is closed.
    #[allow(clippy::too_many_arguments)]
    fn query_pair(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        s: &ToppleSettings,
        [a, b]: [ColliderHandle; 2],
        t: f64,
        touch: f64,
        persistent: bool,
        depth: usize,
    ) -> bool {
        let Some(material) = hooks.pair(a, b).map(|m| m.impact) else {
            return false;
        };
        let (Some(ca), Some(cb)) = (world.colliders.get(a), world.colliders.get(b)) else {
            return false;
        };
        let Ok(geometry) = support::pair(world.bodies, world.colliders, a, b) else {
            return false; // Rapier's (support): not part of the impact
        };
        let (Some(pa), Some(pb)) = (
            self.collider_pose(world, a, t),
            self.collider_pose(world, b, t),
        ) else {
            return false;
        };
        let tol = closed_tolerance(s).max(touch);
        self.pairs_queried += 1;
        let count = self.manifolds_of(geometry, &pa, ca.shape(), &pb, cb.shape(), tol as Real);
        let closed = self.manifolds[..count]
            .iter()
            .any(|m| m.points.iter().any(|p| f64::from(p.dist) <= tol));
        if !closed {
            return false;
        }
        // the bodies join the group (a body new to it one hop further out)
        let mut join = |co: &Collider| {
            dynamic_parent(world, co).map(|h| match self.slot_of(h) {
                Some(slot) => slot,
                None => self.add_body(world, h, t, depth),
            })
        };
        let bodies = [join(ca), join(cb)];
        let rule = crate::coupling::PatchRule {
            closed_tolerance: tol,
            flat_tolerance: s.patch.flat_tolerance.max(closed_tolerance(s)),
            ..s.patch
        };
        for m in &self.manifolds[..count] {
            // points of a sub-shape are in its own frame
            let p1 = m.subshape_pos1().map_or(pa, |sub| pa * *sub);
            let p2 = m.subshape_pos2().map_or(pb, |sub| pb * *sub);
            let normal = unit(v2(p1.transform_vector(m.local_n1).normalize()));
            self.points.clear();
            for p in &m.points {
                let mid = 0.5 * (p1.transform_point(p.local_p1) + p2.transform_point(p.local_p2));
                self.points.push(ManifoldPoint {
                    point: v2(mid),
                    dist: f64::from(p.dist),
                });
            }
            let contacts = &mut self.contacts;
            for_each_contact_point(&self.points, &rule, |point, dist| {
                contacts.push(PointContact {
                    bodies,
                    point,
                    normal,
                    // touching within `touch`: closed for the grouping stage
                    dist: dist.min(0.0),
                    material,
                    persistent,
                })
            });
        }
        true
    }

    /// Keeps the reports, bodies and contacts of the groups just resolved.
    fn record(&mut self, t: f64, groups: usize) {
        for g in 0..groups {
            let report = self.groups.reports()[g];
            self.reports.push(report);
            let b0 = self.event_bodies.len();
            for &i in self.groups.members(g) {
                self.event_bodies.push(self.handles[i]);
            }
            let c0 = self.event_contacts.len();
            for r in self.groups.records(g) {
                let handle = |i: Option<usize>| i.map(|i| self.handles[i]);
                self.event_contacts.push(ImpactContact {
                    bodies: [handle(r.bodies[0]), handle(r.bodies[1])],
                    point: r.point,
                    normal: r.normal,
                    normal_impulse: r.normal_impulse,
                    tangent_impulse: r.tangent_impulse,
                });
            }
            self.events.push(ImpactEvent {
                time_in_step: t,
                report,
                bodies: (b0, self.event_bodies.len()),
                contacts: (c0, self.event_contacts.len()),
            });
        }
    }

    /// The bodies whose velocity changed move on from `t` with the new
    /// velocity; their candidates get new times of impact, and their sweep
    /// over the rest of the step may add candidates.
    fn move_on(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        s: &ToppleSettings,
        t: f64,
        groups: usize,
    ) {
        let dt = self.motion.dt;
        let first_new = self.candidates.len();
        let mut moved = false;
        for g in 0..groups {
            for m in 0..self.groups.members(g).len() {
                let i = self.groups.members(g)[m];
                let (h, b) = (self.handles[i], self.bodies[i]);
                let rb = &world.bodies[h];
                let path = self.motion.path(h, rb);
                let old = if path.changed {
                    (path.velocity, path.angular_velocity)
                } else {
                    (v2(rb.linvel()), f64::from(rb.angvel()))
                };
                if old == (b.velocity, b.angular_velocity) {
                    continue;
                }
                path.restart(t, dt, b.velocity, b.angular_velocity);
                moved = true;
                self.sweep(world, hooks, h);
            }
        }
        if !moved {
            return;
        }
        for k in 0..self.candidates.len() {
            if self.candidates[k].done {
                continue;
            }
            let touched = k >= first_new || self.candidate_moved(world, k, t);
            if touched {
                self.candidates[k].toi = self.time_of_impact(world, s, k);
            }
        }
    }

    /// A candidate has a body whose path restarted at `t`.
    fn candidate_moved(&mut self, world: &World, k: usize, t: f64) -> bool {
        self.candidates[k].colliders.iter().any(|&c| {
            world
                .colliders
                .get(c)
                .and_then(|co| dynamic_parent(world, co))
                .is_some_and(|h| {
                    let rb = &world.bodies[h];
                    let p: Path = *self.motion.path(h, rb);
                    p.changed && p.t0 == t
                })
        })
    }
}

/// Pose of a body's frame from its centre of mass (m) and angle (rad).
fn body_pose(rb: &RigidBody, com: [f64; 2], angle: f64) -> Pose {
    let angle = angle as Real;
    let rotation = Pose::rotation(angle);
    let origin = vector(com) - rotation.transform_vector(rb.local_center_of_mass());
    Pose::new(origin, angle)
}

/// The closed tolerance of this build (m): the settings' tolerance, but not
/// below what the build resolves (64 ε of the scalar type, per metre).
/// The manifolds of a pair with a composite shape (one per pair of
/// sub-shapes) into `out`; how many.
fn composite_manifolds(
    pos12: &Pose,
    sa: &dyn Shape,
    sb: &dyn Shape,
    reach: Real,
    out: &mut Vec<ContactManifold<(), ()>>,
) -> usize {
    out.clear();
    let mut workspace = None;
    let ok = DefaultQueryDispatcher.contact_manifolds(pos12, sa, sb, reach, out, &mut workspace);
    if ok.is_ok() {
        out.len()
    } else {
        0
    }
}

/// A segment or a polyline (made of segments).
fn segment_like(s: &dyn Shape) -> bool {
    matches!(s.shape_type(), ShapeType::Segment | ShapeType::Polyline)
}

/// A contact manifold of shapes 1 and 2 as the manifold of 2 and 1.
fn flip_manifold(m: &mut ContactManifold<(), ()>) {
    std::mem::swap(&mut m.local_n1, &mut m.local_n2);
    std::mem::swap(&mut m.subshape1, &mut m.subshape2);
    let (pos1, pos2) = (m.subshape_pos1().copied(), m.subshape_pos2().copied());
    m.set_subshape_pos1(pos2);
    m.set_subshape_pos2(pos1);
    for p in m.points.iter_mut() {
        std::mem::swap(&mut p.local_p1, &mut p.local_p2);
        std::mem::swap(&mut p.fid1, &mut p.fid2);
    }
}

fn closed_tolerance(s: &ToppleSettings) -> f64 {
    s.patch
        .closed_tolerance
        .max(64.0 * f64::from(Real::EPSILON))
}
