//! Where every moving body is at any instant of the current step.
//!
//! Rapier moves an awake body from its pose at the start of the step to its
//! pose at the end; inside the step the impact pass takes the straight path
//! between the two (centre of mass linear in time, angle linear in time). An
//! impact at time τ changes the velocities of its group; from τ on, each body
//! of the group moves on a new straight path with its post-impact velocity,
//! to a new pose at the end of the step. A body that did not move (asleep,
//! fixed, kinematic) keeps its pose. All values are f64 (m, rad, s), read
//! from Rapier in either precision.
//!
//! [`Cadence`] sets how finely Rapier solves the bodies inside the pieces
//! of a step.

use super::backend::math::Real;
use super::backend::prelude::{
    ColliderSet, IslandManager, RigidBody, RigidBodyHandle, RigidBodySet,
};

/// A body's motion over the current step: a straight path from (`t0`,
/// `com0`, `angle0`) to the end of the step (`com1`, `angle1`), with the
/// velocities that drove it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Path {
    /// Start of the current segment (s, from the start of the step).
    pub t0: f64,
    /// Centre of mass (m) and angle (rad) at `t0`.
    pub com0: [f64; 2],
    pub angle0: f64,
    /// Centre of mass (m) and angle (rad) at the end of the step.
    pub com1: [f64; 2],
    pub angle1: f64,
    /// An impact of this step changed the body's velocity ...
    pub changed: bool,
    /// ... to this (m/s, rad/s; meaningful when `changed`).
    pub velocity: [f64; 2],
    pub angular_velocity: f64,
}

impl Path {
    /// A body that stays where it is.
    pub fn still(com: [f64; 2], angle: f64) -> Path {
        Path {
            t0: 0.0,
            com0: com,
            angle0: angle,
            com1: com,
            angle1: angle,
            ..Path::default()
        }
    }

    /// Centre of mass (m) and angle (rad) at time `t` of a step of length
    /// `dt` (s); `t` before the segment's start reads its start.
    #[inline]
    pub fn at(&self, t: f64, dt: f64) -> ([f64; 2], f64) {
        let span = dt - self.t0;
        let s = if span > 0.0 {
            ((t - self.t0) / span).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let lerp = |a: f64, b: f64| a + s * (b - a);
        (
            [
                lerp(self.com0[0], self.com1[0]),
                lerp(self.com0[1], self.com1[1]),
            ],
            lerp(self.angle0, self.angle1),
        )
    }

    /// From time `t` (s) on, the body moves with velocity `v` (m/s) and
    /// angular velocity `w` (rad/s) to the end of a step of length `dt`.
    pub fn restart(&mut self, t: f64, dt: f64, v: [f64; 2], w: f64) {
        let (com, angle) = self.at(t, dt);
        let rest = dt - t;
        *self = Path {
            t0: t,
            com0: com,
            angle0: angle,
            com1: [com[0] + v[0] * rest, com[1] + v[1] * rest],
            angle1: angle + w * rest,
            changed: true,
            velocity: v,
            angular_velocity: w,
        };
    }

    /// Largest distance (m) a point within `radius` (m) of the centre of
    /// mass travels over the rest of the step: a bound for the swept test.
    pub fn reach(&self, radius: f64) -> f64 {
        let d = [self.com1[0] - self.com0[0], self.com1[1] - self.com0[1]];
        d[0].hypot(d[1]) + (self.angle1 - self.angle0).abs() * radius
    }
}

/// Centre of mass (m) and angle (rad) of a Rapier body.
pub(crate) fn com_and_angle(rb: &RigidBody) -> ([f64; 2], f64) {
    let c = rb.center_of_mass();
    (
        [f64::from(c.x), f64::from(c.y)],
        f64::from(rb.rotation().angle()),
    )
}

/// The paths of the bodies of one step, by body arena index.
#[derive(Debug, Default)]
pub(crate) struct Motion {
    /// Step length (s).
    pub dt: f64,
    /// Start poses (centre of mass, angle) of the bodies awake before the
    /// step, by arena index; `start_of[i]` indexes `starts`.
    starts: Vec<(RigidBodyHandle, [f64; 2], f64)>,
    start_of: Vec<u32>,
    /// Paths of the bodies the pass has looked at, by arena index.
    paths: Vec<Path>,
    path_of: Vec<u32>,
    handles: Vec<RigidBodyHandle>,
    /// Paths are predictions: from the pose now, at the velocity now.
    predicting: bool,
}

const NONE: u32 = u32::MAX;

#[inline]
fn index(h: RigidBodyHandle) -> usize {
    h.into_raw_parts().0 as usize
}

fn slot(map: &mut Vec<u32>, i: usize) -> &mut u32 {
    if map.len() <= i {
        map.resize(i + 1, NONE);
    }
    &mut map[i]
}

impl Motion {
    /// Records the poses of the awake bodies before Rapier's step.
    pub fn record_start(&mut self, islands: &IslandManager, bodies: &RigidBodySet) {
        for &(h, _, _) in &self.starts {
            self.start_of[index(h)] = NONE;
        }
        self.starts.clear();
        for h in islands.active_bodies() {
            let Some(rb) = bodies.get(h) else { continue };
            if !rb.is_dynamic() {
                continue;
            }
            let (com, angle) = com_and_angle(rb);
            *slot(&mut self.start_of, index(h)) = self.starts.len() as u32;
            self.starts.push((h, com, angle));
        }
    }

    /// Records body `h` too if it is dynamic, awake and not recorded yet: a
    /// body added since the last step, which Rapier's island manager lists
    /// only after that step.
    pub fn record_added(&mut self, bodies: &RigidBodySet, h: RigidBodyHandle) {
        if self.start_of.get(index(h)).is_some_and(|&s| s != NONE) {
            return;
        }
        let Some(rb) = bodies.get(h) else { return };
        if !rb.is_dynamic() || rb.is_sleeping() {
            return;
        }
        let (com, angle) = com_and_angle(rb);
        *slot(&mut self.start_of, index(h)) = self.starts.len() as u32;
        self.starts.push((h, com, angle));
    }

    /// Forgets the paths of the last pass; `dt` is the new step's length (s).
    pub fn begin_pass(&mut self, dt: Real) {
        self.reset(f64::from(dt), false);
    }

    /// Paths over the next `horizon` (s) as predictions: each awake body
    /// keeps its velocity from its pose now.
    pub fn begin_prediction(&mut self, horizon: f64) {
        self.reset(horizon, true);
    }

    fn reset(&mut self, dt: f64, predicting: bool) {
        self.dt = dt;
        self.predicting = predicting;
        for h in &self.handles {
            self.path_of[index(*h)] = NONE;
        }
        self.paths.clear();
        self.handles.clear();
    }

    /// The bodies awake before the step, with their start poses.
    pub fn starts(&self) -> &[(RigidBodyHandle, [f64; 2], f64)] {
        &self.starts
    }

    /// The path of a body over the step (made on first use): from its start
    /// pose to its pose now if it was awake before the step, else still.
    pub fn path(&mut self, h: RigidBodyHandle, rb: &RigidBody) -> &mut Path {
        let i = index(h);
        if *slot(&mut self.path_of, i) == NONE {
            let (com1, angle1) = com_and_angle(rb);
            let path = match self.start_of.get(i).copied().filter(|&s| s != NONE) {
                _ if self.predicting => {
                    let moving = rb.is_dynamic() && !rb.is_sleeping();
                    let (v, w) = (rb.linvel(), f64::from(rb.angvel()));
                    let h = if moving { self.dt } else { 0.0 };
                    Path {
                        t0: 0.0,
                        com0: com1,
                        angle0: angle1,
                        com1: [com1[0] + f64::from(v.x) * h, com1[1] + f64::from(v.y) * h],
                        angle1: angle1 + w * h,
                        ..Path::default()
                    }
                }
                Some(s) if rb.is_dynamic() => {
                    let (_, com0, angle0) = self.starts[s as usize];
                    Path {
                        t0: 0.0,
                        com0,
                        angle0: unwrap_near(angle0, angle1),
                        com1,
                        angle1,
                        ..Path::default()
                    }
                }
                // awake but not recorded (inserted or woken since): its
                // path is reconstructed from its velocity
                _ if rb.is_dynamic() && !rb.is_sleeping() => {
                    let (v, w) = (rb.linvel(), f64::from(rb.angvel()));
                    let dt = self.dt;
                    Path {
                        t0: 0.0,
                        com0: [com1[0] - f64::from(v.x) * dt, com1[1] - f64::from(v.y) * dt],
                        angle0: angle1 - w * dt,
                        com1,
                        angle1,
                        ..Path::default()
                    }
                }
                _ => Path::still(com1, angle1),
            };
            self.path_of[i] = self.paths.len() as u32;
            self.paths.push(path);
            self.handles.push(h);
        }
        &mut self.paths[self.path_of[i] as usize]
    }

    /// The bodies whose velocity an impact changed, with their paths.
    pub fn changed(&self) -> impl Iterator<Item = (RigidBodyHandle, &Path)> + '_ {
        self.handles
            .iter()
            .zip(&self.paths)
            .filter(|(_, p)| p.changed)
            .map(|(h, p)| (*h, p))
    }
}

/// Rapier's own substep inside the pieces of a step.
///
/// Rapier solves a step of length p in `num_solver_iterations` = N
/// substeps of p / N. A frame of Δt cut into pieces would be solved in
/// substeps of p / N, shorter than native Rapier's Δt / N, and a stack of
/// bodies with mass ratios of 30–10⁴ settles through a deeper transient of
/// Rapier's soft contacts at the shorter substep (docs/stress.md, "Rapier's
/// soft contact at a shorter step"). So a piece is solved in
/// [`Cadence::piece_iterations`] substeps, native Rapier's substep Δt / N,
/// while the bodies that turn faster than [`Cadence::TURNING_SHARE`] of the
/// impact threshold (a leaning,
/// pivoting domino and whatever touches it: Rapier substeps a connected
/// component at the count of its most demanding body) keep N substeps per
/// piece through Rapier's per-body `additional_solver_iterations`, the
/// resolution the domino rows were measured at (docs/game-rate.md). The
/// count a body had before the step is given back at the end of the step.
#[derive(Debug, Default)]
pub(crate) struct Cadence {
    /// Bodies raised in the current piece, with the count they had.
    raised: Vec<(RigidBodyHandle, usize)>,
    /// Bodies an impact changed since the last piece: woken, but listed in
    /// Rapier's active set only after its next step.
    struck: Vec<RigidBodyHandle>,
}

impl Cadence {
    /// The share of the impact threshold (max(`min_approach_speed` · L,
    /// 2 |g| Δt)) above which a body's turning speed keeps the frame's
    /// count of substeps per piece: at 1/2 the body's points turn faster
    /// than gravity moves them in one frame, |g| Δt, where the frame's term
    /// sets the threshold. Chosen by measurement (docs/stress.md, "Native
    /// Rapier's substep inside the pieces"): at 1 (and at 0.7) the pivoting
    /// dominoes of the ideal row at s/h 0.45 (and Domino P at s/h 0.3) turn
    /// slower than that and lose accuracy; at 1/2 no row of docs/game-rate.md
    /// moves further from the reference by more than 0.1 %.
    pub const TURNING_SHARE: f64 = 0.5;

    /// Rapier's substeps for a piece of `piece` (s) of a frame of `frame`
    /// (s) solved natively in `n` substeps: round(n · piece / frame), at
    /// least 1 and at most `n`, so that the substep stays near frame / n.
    pub fn piece_iterations(n: usize, piece: f64, frame: f64) -> usize {
        if n == 0 || !(piece > 0.0 && frame > 0.0) {
            return n;
        }
        ((n as f64 * piece / frame).round() as usize).clamp(1, n.max(1))
    }

    /// Before Rapier's step of a piece solved in `kept` of the frame's `n`
    /// substeps: the bodies of `islands`' active set, of `added` and struck
    /// by the last pass that turn faster than `threshold` (world units/s:
    /// |ω| times the body's bounding radius) get `n − kept` additional
    /// iterations (or their own count if higher); every body raised in the
    /// last piece gets its own count back first.
    #[allow(clippy::too_many_arguments)]
    pub fn begin_piece(
        &mut self,
        islands: &IslandManager,
        added: &[RigidBodyHandle],
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        n: usize,
        kept: usize,
        threshold: f64,
    ) {
        self.restore(bodies);
        if kept < n {
            let extra = n - kept;
            let struck = std::mem::take(&mut self.struck);
            let candidates = islands.active_bodies().chain(added.iter().copied());
            for h in candidates.chain(struck.iter().copied()) {
                self.raise(bodies, colliders, h, extra, threshold);
            }
            self.struck = struck;
        }
        self.struck.clear();
    }

    fn raise(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        h: RigidBodyHandle,
        extra: usize,
        threshold: f64,
    ) {
        let Some(rb) = bodies.get(h) else { return };
        // a body met twice (awake and struck) has `extra` already
        let own = rb.additional_solver_iterations();
        if !rb.is_dynamic() || own >= extra || turning_speed(rb, colliders) <= threshold {
            return;
        }
        if let Some(rb) = bodies.get_mut(h) {
            rb.set_additional_solver_iterations(extra);
            self.raised.push((h, own));
        }
    }

    /// Notes the bodies an impact of the last pass changed.
    pub fn note_struck(&mut self, struck: impl Iterator<Item = RigidBodyHandle>) {
        self.struck.extend(struck);
    }

    /// Gives every raised body its own count back (at the end of a step).
    pub fn restore(&mut self, bodies: &mut RigidBodySet) {
        for (h, own) in self.raised.drain(..) {
            if let Some(rb) = bodies.get_mut(h) {
                rb.set_additional_solver_iterations(own);
            }
        }
    }
}

/// How fast a body's points turn about its centre of mass (world units/s):
/// |ω| times the farthest reach of its colliders from the centre of mass.
fn turning_speed(rb: &RigidBody, colliders: &ColliderSet) -> f64 {
    let w = f64::from(rb.angvel()).abs();
    if w == 0.0 {
        return 0.0;
    }
    let com = rb.local_center_of_mass();
    let reach = rb
        .colliders()
        .iter()
        .filter_map(|&c| colliders.get(c))
        .map(|co| {
            let offset = co
                .position_wrt_parent()
                .map_or(0.0, |p| f64::from((p.translation - com).length()));
            offset + f64::from(co.shape().compute_local_bounding_sphere().radius)
        })
        .fold(0.0, f64::max);
    w * reach
}

/// `a` shifted by a multiple of 2π to within π of `b` (angles wrap).
fn unwrap_near(a: f64, b: f64) -> f64 {
    use std::f64::consts::TAU;
    a + ((b - a) / TAU).round() * TAU
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_restarted_path_keeps_its_pose_at_the_impact_and_moves_with_the_new_velocity() {
        let mut p = Path {
            t0: 0.0,
            com0: [0.0, 0.0],
            angle0: 0.0,
            com1: [1.0, 2.0],
            angle1: 0.5,
            ..Path::default()
        };
        let dt = 0.1;
        let (c, a) = p.at(0.025, dt);
        assert!((c[0] - 0.25).abs() < 1e-15 && (c[1] - 0.5).abs() < 1e-15);
        assert!((a - 0.125).abs() < 1e-15);
        p.restart(0.025, dt, [-2.0, 0.0], 1.0);
        let (c2, a2) = p.at(0.025, dt);
        assert_eq!((c2, a2), (c, a));
        let (c3, a3) = p.at(dt, dt);
        assert!((c3[0] - (0.25 - 2.0 * 0.075)).abs() < 1e-15);
        assert!((c3[1] - 0.5).abs() < 1e-15);
        assert!((a3 - (0.125 + 0.075)).abs() < 1e-15);
    }

    #[test]
    fn angles_unwrap_across_pi() {
        let a = unwrap_near(3.1, -3.1);
        assert!((a - (3.1 - std::f64::consts::TAU)).abs() < 1e-12);
    }
}
