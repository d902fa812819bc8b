//! The impact pass after Rapier's step: impacts at the instant their pair
//! closes, inside the step (see the design notes of [`crate::rapier`]).
//!
//! One struct, [`ImpactPass`], whose impl each file extends with one stage:
//!
//! | stage | file | what |
//! | --- | --- | --- |
//! | candidates | `candidates.rs` | pairs the hook took approaching points from, and pairs a fast body sweeps into (a swept box against Rapier's broad phase) |
//! | contact queries | `query.rs` | poses of a collider along its path, the gap and the contact manifolds of a pair at an instant |
//! | time of impact | `toi.rs` | for each candidate that is closed at the end of the step, the first instant τ its gap closes along the bodies' straight paths (bracketed, then regula falsi) |
//! | group | `group.rs` | at the earliest τ: the bodies connected to the closing pair through closed contacts (breadth first, within the impact window), their contacts from parry at the poses of τ, λ points on flat patches |
//! | batch | `batch.rs` | the impacts of the next instants whose groups cannot meet before the last of them: built one after another, solved side by side (on several threads with the `parallel` feature), applied in time order with the same bits as one at a time |
//! | resolve, continue | `resolve.rs` | [`ImpactGroups`]: the LZB resolver with the fallback policy under the step's work budget; each body whose velocity changed moves on from τ with its new velocity, its pairs get new times of impact; the events are recorded |
//! | run, predict, write back | this file | the stages in order over one step; the look-ahead that splits Rapier's step; new velocities and end poses into Rapier |

mod batch;
mod candidates;
mod group;
mod query;
mod resolve;
mod toi;

use super::backend::math::{Pose, Real, Vector};
use super::backend::parry::query::ContactManifold;
use super::backend::prelude::{
    BroadPhaseBvh, Collider, ColliderHandle, ColliderSet, NarrowPhase, RigidBody, RigidBodyHandle,
    RigidBodySet,
};

use super::hooks::ToppleHooks;
use super::motion::{Motion, Path};
use super::support::{self, Geometry, Role};
use crate::coupling::{ImpactGroups, ImpactReport, ManifoldPoint, PointContact, ToppleSettings};
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
    /// The pair's impact threshold (world units/s): the frame's while
    /// Rapier holds the pair, lower once it has not lately
    /// ([`ToppleHooks::threshold_of`]).
    threshold: f64,
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
    /// Resolve the impacts one instant at a time, never in batches (the
    /// same bits; tests compare the two).
    pub one_at_a_time: bool,
    /// Impact groups applied from batches of two or more instants.
    pub batched: u64,
    /// Batch items whose solve was done again under the budget the
    /// sequential order left them ([`ImpactGroups::same_under`]).
    pub solved_again: u64,
    /// The batch being built and solved (kept between steps).
    items: Vec<batch::Item>,
    /// A group is being built for a batch: paths are looked at, not made
    /// (`fresh` lists the ones to make when it is applied), and the bodies
    /// it looks at are noted in `reach`.
    speculative: bool,
    fresh: Vec<RigidBodyHandle>,
    reach: Vec<RigidBodyHandle>,
    /// The candidates the group being built marked done.
    seeds: Vec<usize>,
    /// By arena index: the batch (its stamp) whose group holds the body.
    claimed: Vec<u64>,
    /// By arena index: the batch (its stamp) and the last item of it whose
    /// build looked at the body.
    reached: Vec<(u64, usize)>,
    /// The current batch's stamp.
    stamp: u64,
    /// The batch item whose groups were applied last (`None`: the pass's
    /// own, resolved one instant at a time).
    last_item: Option<usize>,
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

impl ImpactPass {
    /// The grouping stage.
    pub fn groups(&self) -> &ImpactGroups {
        match self.last_item {
            Some(j) => &self.items[j].groups,
            None => &self.groups,
        }
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
        let mut events = 0;
        // the audit and the capture of impacts record on the calling
        // thread: while either is on, every impact is solved here
        let one_at_a_time =
            self.one_at_a_time || crate::impact::audit::is_on() || crate::impact::capture::is_on();
        while events < MAX_EVENTS {
            let Some(t) = self.earliest() else { break };
            if one_at_a_time {
                self.last_item = None;
                groups += self.resolve_at(world, hooks, settings, t, offset);
                events += 1;
                continue;
            }
            let (applied, solved) =
                self.batch(world, hooks, settings, t, offset, MAX_EVENTS - events);
            events += applied;
            groups += solved;
        }
        groups
    }

    /// The path of body `h` for the group being built: made on first use
    /// as everywhere else, or, while a batch is built, looked at without
    /// being made (noted in `fresh`, made when the group is applied, so
    /// that the paths are made in the order of the sequential pass).
    fn build_path(&mut self, h: RigidBodyHandle, rb: &RigidBody) -> Path {
        if !self.speculative {
            return *self.motion.path(h, rb);
        }
        let (path, made) = self.motion.peek(h, rb);
        if !made && !self.fresh.contains(&h) {
            self.fresh.push(h);
        }
        path
    }

    /// Notes the body of collider `c` as looked at by the group being
    /// built for a batch.
    fn note_reach(&mut self, world: &World, c: ColliderHandle) {
        if !self.speculative {
            return;
        }
        // a fixed or kinematic body is never moved by the pass
        if let Some(h) = world.colliders.get(c).and_then(|co| co.parent())
            && world.bodies.get(h).is_some_and(|rb| rb.is_dynamic())
        {
            self.reach.push(h);
        }
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
        self.motion.forget_changed_ends();
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
fn closed_tolerance(s: &ToppleSettings) -> f64 {
    s.patch
        .closed_tolerance
        .max(64.0 * f64::from(Real::EPSILON))
}
