//! The cadence of a step: how many of Rapier's own substeps solve each
//! piece of a sub-stepped frame, and which bodies keep the frame's count
//! (docs/stress.md, "Native Rapier's substep inside the pieces"). Speeds in
//! world units/s, times in s.

use super::backend::prelude::{
    ColliderSet, IslandManager, RigidBody, RigidBodyHandle, RigidBodySet,
};

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
    /// The reach of each body's colliders from its centre of mass (m), by
    /// arena index, with the body and the step it was measured in: read
    /// once per step, not once per piece (an app changes shapes only
    /// between steps).
    reach: Vec<(f64, Option<RigidBodyHandle>, u64)>,
    /// The stamp of the current step (one more at every `restore` that ends
    /// a step).
    step: u64,
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
        if !rb.is_dynamic() || own >= extra {
            return;
        }
        let w = f64::from(rb.angvel()).abs();
        if w == 0.0 || w * self.reach_of(h, rb, colliders) <= threshold {
            return;
        }
        if let Some(rb) = bodies.get_mut(h) {
            rb.set_additional_solver_iterations(extra);
            self.raised.push((h, own));
        }
    }

    /// [`reach`] of body `h`, measured once per step.
    fn reach_of(&mut self, h: RigidBodyHandle, rb: &RigidBody, colliders: &ColliderSet) -> f64 {
        let i = h.into_raw_parts().0 as usize;
        if self.reach.len() <= i {
            self.reach.resize(i + 1, (0.0, None, 0));
        }
        let (r, of, step) = &mut self.reach[i];
        if *of != Some(h) || *step != self.step {
            *r = reach(rb, colliders);
            *of = Some(h);
            *step = self.step;
        }
        *r
    }

    /// Notes the bodies an impact of the last pass changed.
    pub fn note_struck(&mut self, struck: impl Iterator<Item = RigidBodyHandle>) {
        self.struck.extend(struck);
    }

    /// Gives every raised body its own count back at the end of a step;
    /// the next step measures the bodies' reach again.
    pub fn end_step(&mut self, bodies: &mut RigidBodySet) {
        self.restore(bodies);
        self.step = self.step.wrapping_add(1).max(1);
    }

    /// Gives every raised body its own count back.
    fn restore(&mut self, bodies: &mut RigidBodySet) {
        for (h, own) in self.raised.drain(..) {
            if let Some(rb) = bodies.get_mut(h) {
                rb.set_additional_solver_iterations(own);
            }
        }
    }
}

/// The farthest reach of a body's colliders from its centre of mass (world
/// units): |ω| times it is how fast the body's points turn (world units/s).
fn reach(rb: &RigidBody, colliders: &ColliderSet) -> f64 {
    let com = rb.local_center_of_mass();
    rb.colliders()
        .iter()
        .filter_map(|&c| colliders.get(c))
        .map(|co| {
            let offset = co
                .position_wrt_parent()
                .map_or(0.0, |p| f64::from((p.translation - com).length()));
            offset + f64::from(co.shape().compute_local_bounding_sphere().radius)
        })
        .fold(0.0, f64::max)
}
