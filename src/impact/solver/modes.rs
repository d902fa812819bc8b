//! Stage 6: the modes at an instant — which touching points are pushed
//! together, which patches stick or slide, which held points let go — at
//! the start of the impact and after every switch.
//!
//! * A touching point (q = 0) that does not separate (δ̇ ≤ 0, to rounding)
//!   is closed: it loads as soon as it is pushed in. An e = 0 point that has
//!   just lost its energy after a fast load cycle
//!   ([`crate::impact::ImpactSettings::fast_cycle`], or every cycle with
//!   [`crate::impact::ImpactSettings::e0_hold`]) is held instead when the
//!   other forces push it in (δ̈ < 0).
//! * A held point lets go when its force λ would be negative, or is zero
//!   (nothing pushes it any more).
//! * A patch with no loaded point has no friction (idle); a touching point
//!   pushed in at once (an e = 0 point whose compression has just ended
//!   and that is pushed again) counts as loaded. A loaded patch
//!   without slip sticks while the force that keeps it stuck is within
//!   μ_s N; otherwise it slides against the push. A sliding patch whose slip
//!   is zero keeps sliding only if the push accelerates it that way.
//! * A patch without slip (μ = ∞, docs/model.md §4) sticks whenever it is
//!   loaded; if it was slipping, the tangential impulse that stops its slip
//!   (with every other row held) is applied at once: the limit μ → ∞ of
//!   the sliding law. A patch that sticks after its slip stopped takes the
//!   same (rounding-sized) impulse, so that it sticks at zero slip exactly.
//!
//! Each change is followed by a new evaluation, until nothing changes (at
//! most a few passes; a cap ends a cycle, which the next event resolves).

use super::constraints::Target;
use super::data::{normal_rate, rate, PatchMode, PointMode};
use super::Integrator;

impl Integrator {
    /// Settles every mode at the present state.
    ///
    /// Each pass re-evaluates the forces with the modes of the last and
    /// changes every mode whose condition fails. The passes end when nothing
    /// changes, or when a pass comes back to modes and velocities already
    /// seen in this settling: from there the passes would repeat the same
    /// cycle to the cap (a stuck patch at its bound breaks loose and the
    /// rows around it turn it back to sticking), so the cycle is left as it
    /// is and the next event resolves it, as the cap would leave it.
    pub(super) fn settle(&mut self) {
        let cap = 4 + 2 * (self.rows.len() + self.patches.len());
        let mut slope = std::mem::take(&mut self.probe_slope);
        self.seen_modes.clear();
        let mut settled = false;
        for _ in 0..cap {
            self.settling += 1;
            self.refresh_constraints();
            let y = std::mem::take(&mut self.y);
            self.eval(&y, &mut slope, false);
            self.y = y;
            // cleared by a projection of the velocities (`stop_slips`)
            self.slope_current = true;
            let mut changed = self.settle_points(&slope);
            changed |= self.settle_patches(&slope);
            if !changed {
                settled = true;
                break;
            }
            let signature = self.mode_signature();
            if self.seen_modes.contains(&signature) {
                break;
            }
            self.seen_modes.push(signature);
        }
        self.refresh_constraints();
        self.probe_slope = slope;
        // the last pass's evaluation holds for the modes it left
        self.slope_current &= settled;
    }

    /// A 64-bit digest (FNV-1a) of every point's and patch's mode and of
    /// the body velocities: equal digests within one settling mean the
    /// passes have come back to a state they left (a collision only ends
    /// the passes early, as the cap would).
    fn mode_signature(&self) -> u64 {
        const PRIME: u64 = 0x0000_0100_0000_01b3;
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut add = |x: u64| h = (h ^ x).wrapping_mul(PRIME);
        for point in &self.points {
            add(point.mode as u64);
        }
        for mode in &self.patch_modes {
            add(match *mode {
                PatchMode::Idle => 0,
                PatchMode::Stick => 1,
                PatchMode::Slide(s) => 2 + u64::from(s > 0.0),
            });
        }
        for v in &self.y[..3 * self.layout.bodies] {
            add(v.to_bits());
        }
        h
    }

    fn settle_points(&mut self, slope: &[f64]) -> bool {
        let thr = self.scales.rate;
        // the largest approach a closing after a fast cycle may have to be
        // held (docs/model.md §8); e = 0 points are at rest to rounding
        let slow = (2.0 * thr).max(self.fast_bounce * self.scales.velocity);
        let lay = self.layout;
        let now = self.y[lay.time()];
        let mut changed = false;
        let mut plastic = false;
        for i in 0..lay.contacts {
            let row = &self.rows[i];
            if !row.movable {
                continue;
            }
            let point = &mut self.points[i];
            match point.mode {
                PointMode::Compress if point.released => {
                    // an e = 0 point whose fast load cycle just ended, or an
                    // e > 0 point closing after one: held if it is pushed in
                    // again (an approach of the latter is stopped by the
                    // hold, as a plastic impact would stop it)
                    let rate = normal_rate(row, &self.y);
                    if rate <= 2.0 * thr && -rate <= slow && normal_rate(row, slope) < 0.0 {
                        point.mode = PointMode::Held;
                        point.hold_limit = if row.law.restitution > 0.0 {
                            // P_n after the plastic stop, plus one fast swing
                            self.y[lay.pn(i)]
                                + (-rate).max(0.0) / row.w_nn
                                + self.fast_bounce * self.scales.velocity / row.w_nn
                        } else {
                            f64::INFINITY
                        };
                        point.switched_at = now;
                        self.constraints_dirty = true;
                        changed = true;
                        plastic |= rate < -2.0 * thr;
                    }
                    point.released = false;
                }
                PointMode::Held if point.held_force <= 0.0 => {
                    // a hold that lets go at the instant it was made took
                    // nothing: the point's next closing follows the law
                    let lasted = point.switched_at < now;
                    point.fast_rebound = false;
                    point.hold_limit = f64::INFINITY;
                    point.mode = PointMode::Compress;
                    point.switched_at = now;
                    self.y[lay.q(i)] = 0.0;
                    self.constraints_dirty = true;
                    changed = true;
                    if lasted && row.law.restitution > 0.0 {
                        self.end_cycle(i);
                    }
                }
                _ => {}
            }
        }
        if plastic {
            self.stop_slips();
        }
        changed
    }

    /// Ends point `i`'s load cycle (an e > 0 point lets go, or its hold
    /// ends): a cycle that moved its own rate by at most `fast_cycle` of the
    /// velocity scale, W_ii ΔP ≤ fast_cycle · V, makes its next closing a
    /// candidate for the hold (docs/model.md §8).
    pub(super) fn end_cycle(&mut self, i: usize) {
        let pn = self.y[self.layout.pn(i)];
        let swing = self.rows[i].w_nn * (pn - self.points[i].cycle_start);
        let point = &mut self.points[i];
        point.cycle_start = pn;
        point.fast_rebound = swing <= self.fast_bounce * self.scales.velocity;
    }

    /// Point `i`'s gap has closed: after a fast cycle of an e > 0 point the
    /// next settling holds it if it is pushed in.
    pub(super) fn closes_after_cycle(&mut self, i: usize) {
        let point = &mut self.points[i];
        if point.fast_rebound && self.rows[i].law.restitution > 0.0 {
            point.released = true;
        }
    }

    /// Whether a point carries load or is about to: compressed, held, or
    /// touching and approaching.
    pub(super) fn carries_load(&self, i: usize) -> bool {
        let row = &self.rows[i];
        let q = self.y[self.layout.q(i)];
        match self.points[i].mode {
            PointMode::Held | PointMode::Expand => true,
            PointMode::Compress => {
                q > row.q_zero
                    || (q >= -row.q_zero && normal_rate(row, &self.y) < -self.scales.rate)
            }
        }
    }

    /// Whether point `i` touches (q = 0) without separating (its rate
    /// within the switch's rounding, 2 × `Scales::rate`, of zero) and is
    /// pushed in by the other forces (δ̈ < 0 in `slope`, dy/dt at the
    /// present state): it loads again at once (an e = 0 point whose
    /// compression has just ended and that is pushed again, cycle after
    /// cycle), so its patch need not go idle and come back at a switch of
    /// its own one rounding later.
    fn pushed_in(&self, i: usize, slope: &[f64]) -> bool {
        let row = &self.rows[i];
        let q = self.y[self.layout.q(i)];
        self.points[i].mode == PointMode::Compress
            && q.abs() <= row.q_zero
            && normal_rate(row, &self.y) <= 2.0 * self.scales.rate
            && normal_rate(row, slope) < -self.scales.accel
    }

    fn settle_patches(&mut self, slope: &[f64]) -> bool {
        let thr = self.scales.rate;
        let mut changed = false;
        let mut jump = false;
        for p in 0..self.patches.len() {
            let patch = &self.patches[p];
            let members = &self.members[patch.first..patch.first + patch.count];
            let slip = rate(&self.y, patch.a, patch.b, &patch.tangent);
            let now = self.patch_modes[p];
            // a patch whose points are unloaded but pushed in at once (an
            // e = 0 point whose compression has just ended) is loaded from
            // this instant: a sliding patch keeps sliding (its friction
            // −μ s N grows from zero with the load, the direction of its
            // slip is unchanged), any other takes its mode here, where it
            // would otherwise go idle and take it at the point's onset one
            // rounding of q later (a switch, and a step, for nothing)
            let loaded = members.iter().any(|&i| self.carries_load(i))
                || members.iter().any(|&i| self.pushed_in(i, slope));
            let next = if patch.frictionless() || !loaded {
                // no load, no friction: a stuck row without load would
                // carry whatever force the other stuck rows leave it
                PatchMode::Idle
            } else if patch.no_slip() {
                PatchMode::Stick
            } else {
                match now {
                    PatchMode::Stick => {
                        let load = &self.patch_states[p];
                        if load.friction.abs() > patch.stick_bound * load.normal {
                            PatchMode::Slide(-load.friction.signum())
                        } else {
                            PatchMode::Stick
                        }
                    }
                    PatchMode::Slide(s) if s * slip > thr => now,
                    PatchMode::Slide(s) if slip.abs() <= thr => {
                        // at zero slip: sticks if the push turns the slip
                        // back; keeps sliding if it pushes the slip on or
                        // leaves it at zero (its slip is held by other rows)
                        if s * rate(slope, patch.a, patch.b, &patch.tangent) < -self.scales.accel {
                            PatchMode::Stick
                        } else {
                            now
                        }
                    }
                    _ if slip.abs() <= thr => PatchMode::Stick,
                    _ => PatchMode::Slide(slip.signum()),
                }
            };
            // a stuck patch's slip (rounding left by the switch that stuck
            // it, or any slip of a patch without slip) stops at once
            jump |= next == PatchMode::Stick && slip.abs() > 1e-3 * thr;
            if next != now {
                self.set_patch(p, next);
                changed = true;
            }
        }
        if jump {
            self.stop_slips();
        }
        changed
    }

    /// Changes a patch's mode; the constraint rows follow.
    pub(super) fn set_patch(&mut self, p: usize, mode: PatchMode) {
        self.patch_modes[p] = mode;
        self.patch_states[p].switched_at = self.y[self.layout.time()];
        let patch = &self.patches[p];
        let slide = match mode {
            PatchMode::Slide(s) => -patch.friction * s,
            PatchMode::Idle | PatchMode::Stick => 0.0,
        };
        for &i in &self.members[patch.first..patch.first + patch.count] {
            let row = &mut self.rows[i];
            row.slide = slide;
            row.drive = row.normal.minus(-slide, patch.tangent);
        }
        self.constraints_dirty = true;
    }

    /// Rebuilds and factors the constraint rows if a mode changed.
    fn refresh_constraints(&mut self) {
        if !self.constraints_dirty {
            return;
        }
        self.constraints_dirty = false;
        self.constraints.clear();
        for (p, patch) in self.patches.iter().enumerate() {
            if self.patch_modes[p] == PatchMode::Stick {
                self.constraints.add(
                    Target::Stick(p),
                    patch.a,
                    patch.b,
                    patch.tangent,
                    patch.tangent,
                );
            }
        }
        for (i, row) in self.rows.iter().enumerate() {
            if self.points[i].mode != PointMode::Held {
                continue;
            }
            let patch = &self.patches[row.patch];
            let push = match self.patch_modes[row.patch] {
                PatchMode::Slide(s) => row.normal.minus(patch.friction * s, patch.tangent),
                _ => row.normal,
            };
            self.constraints
                .add(Target::Held(i), row.a, row.b, row.normal, push);
        }
        self.constraints.factor(&self.bodies);
    }

    /// The impulse that stops the slip of every stuck row at once (and
    /// keeps every held row's rate at zero), applied to the velocities and
    /// booked on the rows' points.
    fn stop_slips(&mut self) {
        self.slope_current = false;
        self.refresh_constraints();
        let lay = self.layout;
        let mut y = std::mem::take(&mut self.y);
        self.constraints
            .project(&self.bodies, &mut y[..3 * lay.bodies]);
        self.y = y;
        for k in 0..self.constraints.len() {
            match self.constraints.force(k) {
                (Target::Held(i), p) => {
                    // a held row of a sliding patch pushes along
                    // n − μ s t: its friction impulse is booked with it
                    self.y[lay.pn(i)] += p;
                    self.y[lay.pt(i)] += self.rows[i].slide * p;
                }
                (Target::Stick(patch), p) => {
                    let patch = &self.patches[patch];
                    let members = &self.members[patch.first..patch.first + patch.count];
                    // booked on the points that carry load (all of them if
                    // none does yet)
                    let loaded = members.iter().filter(|&&i| self.carries_load(i)).count();
                    for &i in members {
                        let share = if loaded == 0 {
                            p / members.len() as f64
                        } else if self.carries_load(i) {
                            p / loaded as f64
                        } else {
                            0.0
                        };
                        self.y[lay.pt(i)] += share;
                    }
                }
            }
        }
    }

    /// Records the largest compression each loaded point has reached.
    pub(super) fn note_peaks(&mut self) {
        let lay = self.layout;
        for (i, point) in self.points.iter_mut().enumerate() {
            if matches!(point.mode, PointMode::Compress | PointMode::Expand) {
                point.peak = point.peak.max(self.y[lay.q(i)]);
            }
        }
    }
}
