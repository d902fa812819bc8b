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

use super::backend::math::Real;
use super::backend::prelude::{IslandManager, RigidBody, RigidBodyHandle, RigidBodySet};

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
    /// The pose (centre of mass, angle) the pass read for each body at the
    /// end of a piece, by arena index, with the stamp of that piece (`None`:
    /// none noted, or an impact moved the body since): the next piece's
    /// start pose, read once instead of twice (an `atan2` per body and
    /// piece).
    ends: Vec<Option<(u64, [f64; 2], f64)>>,
    /// The stamp of the current piece (one more at every `record_start`).
    piece: u64,
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
    /// Records the poses of the awake bodies before Rapier's step. With
    /// `carry` (a later piece of the same step, nothing but topple's
    /// impacts having moved a body since the last pass) a body's pose is
    /// the one that pass read at the end of the last piece
    /// ([`Motion::note_end`]), the same bits read again.
    pub fn record_start(&mut self, islands: &IslandManager, bodies: &RigidBodySet, carry: bool) {
        for &(h, _, _) in &self.starts {
            self.start_of[index(h)] = NONE;
        }
        self.starts.clear();
        let last = self.piece;
        self.piece = self.piece.wrapping_add(1);
        for h in islands.active_bodies() {
            let Some(rb) = bodies.get(h) else { continue };
            if !rb.is_dynamic() {
                continue;
            }
            let (com, angle) = match self.ends.get(index(h)) {
                Some(&Some((stamp, com, angle))) if carry && stamp == last => (com, angle),
                _ => com_and_angle(rb),
            };
            *slot(&mut self.start_of, index(h)) = self.starts.len() as u32;
            self.starts.push((h, com, angle));
        }
    }

    /// Notes the pose (centre of mass, angle) the pass read for body `h`
    /// after Rapier's step of the current piece.
    pub fn note_end(&mut self, h: RigidBodyHandle, com: [f64; 2], angle: f64) {
        let i = index(h);
        if self.ends.len() <= i {
            self.ends.resize(i + 1, None);
        }
        self.ends[i] = Some((self.piece, com, angle));
    }

    /// Forgets the end poses noted for the bodies an impact of this pass
    /// changed: their poses are written again.
    pub fn forget_changed_ends(&mut self) {
        for (h, p) in self.handles.iter().zip(&self.paths) {
            if let (true, Some(end)) = (p.changed, self.ends.get_mut(index(*h))) {
                *end = None;
            }
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
            let path = self.make(i, rb);
            self.path_of[i] = self.paths.len() as u32;
            self.paths.push(path);
            self.handles.push(h);
        }
        &mut self.paths[self.path_of[i] as usize]
    }

    /// The path of a body as [`Motion::path`] gives it, without making it
    /// if it is not made yet: with whether it was (`false`: the path
    /// [`Motion::path`] would make now, the same bits, since a path is made
    /// from the body's start and end poses alone). The impact pass builds
    /// a batch's groups with it, and makes the paths in the order the
    /// impacts are applied ([`Motion::changed`] lists them in that order).
    pub fn peek(&self, h: RigidBodyHandle, rb: &RigidBody) -> (Path, bool) {
        let i = index(h);
        match self.path_of.get(i).copied().filter(|&p| p != NONE) {
            Some(p) => (self.paths[p as usize], true),
            None => (self.make(i, rb), false),
        }
    }

    /// The path of body `i` made from its start pose and its pose now.
    fn make(&self, i: usize, rb: &RigidBody) -> Path {
        let (com1, angle1) = com_and_angle(rb);
        match self.start_of.get(i).copied().filter(|&s| s != NONE) {
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
        }
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
    fn a_later_piece_carries_the_pose_the_pass_read_and_only_that_piece() {
        use super::super::backend::prelude::{
            ColliderBuilder, PhysicsWorld, RigidBodyBuilder, Vector,
        };
        let mut world = PhysicsWorld::default();
        let (h, _) = world.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(1.0, 2.0))
                .rotation(0.5),
            ColliderBuilder::ball(0.1),
        );
        world.step(); // Rapier lists the body as awake after a step
        let read = com_and_angle(&world.bodies[h]);
        let mut m = Motion::default();
        let start = |m: &Motion| (m.starts()[0].1, m.starts()[0].2);
        m.record_start(&world.islands, &world.bodies, false);
        assert_eq!(start(&m), read);
        // the pass notes another pose (as after Rapier's step): carried once
        m.note_end(h, [3.0, 4.0], 0.25);
        m.record_start(&world.islands, &world.bodies, true);
        assert_eq!(start(&m), ([3.0, 4.0], 0.25));
        // no pass in between, or a new step: read from Rapier again
        m.record_start(&world.islands, &world.bodies, true);
        assert_eq!(start(&m), read);
        m.note_end(h, [3.0, 4.0], 0.25);
        m.record_start(&world.islands, &world.bodies, false);
        assert_eq!(start(&m), read);
        // an impact of the pass moved the body: read again
        m.note_end(h, [3.0, 4.0], 0.25);
        m.begin_pass(0.01);
        m.path(h, &world.bodies[h])
            .restart(0.0, 0.01, [1.0, 0.0], 0.0);
        m.forget_changed_ends();
        m.record_start(&world.islands, &world.bodies, true);
        assert_eq!(start(&m), read);
    }

    #[test]
    fn angles_unwrap_across_pi() {
        let a = unwrap_near(3.1, -3.1);
        assert!((a - (3.1 - std::f64::consts::TAU)).abs() < 1e-12);
    }
}
