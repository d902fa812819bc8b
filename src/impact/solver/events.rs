//! Stage 5: the switches of the law inside a step, located on the step's
//! interpolant.
//!
//! Each mode holds until one of its own conditions fails (rhs.rs notes the
//! trial points where one does):
//!
//! | mode | switch | condition |
//! | --- | --- | --- |
//! | compression | compression ends | δ̇ rises through 0 (then expansion, or for e = 0 the energy is lost: q = 0) |
//! | compression, expansion | the point lets go | q falls through 0 (the energy is spent; an open gap follows) |
//! | expansion | pushed in again | δ̇ falls through 0 (compression again) |
//! | open | the gap closes | q rises through 0 |
//! | slide | the slip stops | s v_t falls through 0 (then stick, if the bound allows) |
//! | stick | breaks loose | \|f\| reaches μ_s N (then slide) |
//! | held | lets go | λ falls through 0 |
//!
//! Rates within ± 10⁻⁹ of the velocity scale count as zero, so a point that
//! has just switched does not switch back on rounding. The first four and the
//! slip are linear in the state: their interpolant is a polynomial in the
//! step fraction θ, searched on eight samples and refined by the Illinois
//! variant of regula falsi. The last two need the constraint forces, so the
//! state is interpolated and evaluated at each trial θ. The step is then cut
//! back to the earliest switch, every switch due there is applied, and the
//! modes are settled at that instant (modes.rs).

use super::data::{Axis, PatchMode, PointMode, Suspect, Switch};
use super::tableau::Rk;
use super::Integrator;

/// Switches closer than this fraction of a step to the earliest one are
/// applied with it (points of one flat face letting go together).
const SAME_INSTANT: f64 = 1e-9;

/// A gap that closes later in a step closes with its earliest switch if it
/// is within this many rounding widths of the compression
/// (`Row::q_zero`, 10⁻¹² of its scale) there: it is then set closed
/// (q = 0), a change of at most 2·10⁻¹² of the compression scale.
const CLOSE_WITH: f64 = 2.0;

/// Relative width of the bracket at which the root search stops: linear
/// conditions (a polynomial, cheap to evaluate) and the constraint forces
/// (each value an interpolated state and an evaluation; the step's error is
/// far above this anyway).
const ROOT_WIDTH: f64 = 1e-13;
const NONLINEAR_WIDTH: f64 = 1e-7;

impl Integrator {
    /// After an accepted step with suspect points or patches: the earliest
    /// switch inside it as a fraction θ ∈ (0, 1] of the step, with the
    /// switches due at that instant in `self.due`; `None` if the suspicion
    /// was a trial point's and the interpolant crosses nothing.
    pub(super) fn locate(&mut self, rk: &mut Rk) -> Option<f64> {
        rk.prepare_dense();
        self.due.clear();
        let mut earliest = f64::INFINITY;
        let mut nonlinear = false;
        let start = rk.y0[self.layout.time()];
        for k in 0..self.suspects.len() {
            let item = self.suspects[k];
            // an item that switched at this very instant does not switch
            // back within rounding of it
            let switched = match item {
                Suspect::Point(i) => self.points[i].switched_at,
                Suspect::Patch(p) => self.patch_states[p].switched_at,
            };
            let from = if switched == start { SAME_INSTANT } else { 0.0 };
            for watch in self.linear_switches(item, rk).into_iter().flatten() {
                let phi = |t: f64| watch.phi(t);
                let switch = watch.switch;
                let upto = (earliest * (1.0 + SAME_INSTANT)).min(1.0);
                if let Some(t) = first_crossing(phi, from, upto) {
                    earliest = earliest.min(t);
                    self.due.push((t, switch));
                }
            }
            nonlinear |= self.has_nonlinear(item);
        }
        if nonlinear {
            // the watched rows, with the sign of each stuck patch's friction
            // where it was seen beyond its bound (the step's end), so that
            // each condition is smooth in θ
            self.watched.clear();
            for k in 0..self.suspects.len() {
                match self.suspects[k] {
                    Suspect::Point(i) if self.points[i].mode == PointMode::Held => {
                        self.watched.push((self.suspects[k], 1.0));
                    }
                    Suspect::Patch(p) if self.patch_modes[p] == PatchMode::Stick => {
                        let sign = self.patch_states[p].friction.signum();
                        self.watched.push((self.suspects[k], sign));
                    }
                    _ => {}
                }
            }
            let upto = earliest.min(1.0);
            let mut state = std::mem::take(&mut self.probe_state);
            let mut slope = std::mem::take(&mut self.probe_slope);
            let mut phi = |s: &mut Self, t: f64| {
                rk.dense_state(t, &mut state);
                s.eval(&state, &mut slope, false);
                s.constraint_violation()
            };
            let t = first_crossing_mut(self, &mut phi, upto);
            self.probe_state = state;
            self.probe_slope = slope;
            if let Some(t) = t {
                earliest = earliest.min(t);
            }
        }
        if !earliest.is_finite() {
            return None;
        }
        let cut = earliest * (1.0 + SAME_INSTANT) + f64::EPSILON;
        self.due.retain(|&(t, _)| t <= cut);
        self.close_with(rk, earliest, cut);
        Some(earliest)
    }

    /// Adds to `self.due` the gaps that close later in this step but are
    /// already closed to within [`CLOSE_WITH`] rounding widths of the
    /// compression (`Row::q_zero`) at the earliest switch: they close with
    /// it instead of a rounding of time later, each in a step of its own.
    /// (The points of a face that an impact's start or a wave's front
    /// reaches together: on the captured Domino T impacts, cascades of up
    /// to seven closings within 10⁻¹⁰ of the impact's time scale.)
    fn close_with(&mut self, rk: &Rk, earliest: f64, cut: f64) {
        for k in 0..self.suspects.len() {
            let Suspect::Point(i) = self.suspects[k] else {
                continue;
            };
            let [_, Some(watch)] = self.linear_switches(Suspect::Point(i), rk) else {
                continue;
            };
            if !matches!(watch.switch, Switch::Closes(_))
                || self.due.iter().any(|&(_, s)| s == watch.switch)
            {
                continue;
            }
            let mut near = watch;
            near.first.2 -= CLOSE_WITH * self.rows[i].q_zero;
            if near.phi(earliest) > 0.0
                && first_crossing(|t| watch.phi(t), cut.min(1.0), 1.0).is_some()
            {
                self.due.push((earliest, watch.switch));
            }
        }
    }

    /// The linear switches a suspect can make (see [`Watch`]).
    fn linear_switches(&self, item: Suspect, rk: &Rk) -> [Option<Watch>; 2] {
        let thr = self.scales.rate;
        let mut out: [Option<Watch>; 2] = [None, None];
        match item {
            Suspect::Point(i) => {
                let row = &self.rows[i];
                let point = &self.points[i];
                let q = rk.dense_functional(&[(self.layout.q(i), 1.0)]);
                let rate = rk.dense_functional(&terms(row.a, row.b, &row.normal));
                match point.mode {
                    PointMode::Compress => {
                        // loaded, and δ̇ rises through 0
                        out[0] = Some(Watch::both(
                            Switch::CompressionEnds(i),
                            (rate, 1.0, thr),
                            (q, 1.0, row.q_load),
                        ));
                        if point.open {
                            // the gap closes: approaching fast, or where a
                            // patch without slip starts to carry load
                            let fast = if self.onset_matters(i) {
                                f64::NEG_INFINITY
                            } else {
                                self.scales.onset
                            };
                            out[1] = Some(Watch::both(
                                Switch::Closes(i),
                                (q, 1.0, point.close_at),
                                (rate, -1.0, fast),
                            ));
                        }
                    }
                    PointMode::Expand => {
                        out[0] = Some(Watch::one(Switch::Recompresses(i), (rate, -1.0, thr)));
                        out[1] = Some(Watch::one(Switch::LetsGo(i), (q, -1.0, row.q_zero)));
                    }
                    PointMode::Held if point.hold_limit.is_finite() => {
                        let pn = rk.dense_functional(&[(self.layout.pn(i), 1.0)]);
                        out[0] = Some(Watch::one(
                            Switch::HoldSpent(i),
                            (pn, 1.0, point.hold_limit),
                        ));
                    }
                    PointMode::Held => {}
                }
            }
            Suspect::Patch(p) => {
                if let PatchMode::Slide(s) = self.patch_modes[p] {
                    let patch = &self.patches[p];
                    let g = rk.dense_functional(&terms(patch.a, patch.b, &patch.tangent));
                    // a patch that broke loose at zero slip may start a
                    // rounding's width on the wrong side: its slip stops
                    // only once it falls a further `thr` below that
                    let behind = (-s * horner(&g, 0.0)).max(0.0);
                    out[0] = Some(Watch::one(Switch::SlipStops(p), (g, -s, thr + behind)));
                }
            }
        }
        out
    }

    fn has_nonlinear(&self, item: Suspect) -> bool {
        match item {
            Suspect::Point(i) => self.points[i].mode == PointMode::Held,
            Suspect::Patch(p) => self.patch_modes[p] == PatchMode::Stick,
        }
    }

    /// The largest violation among the watched held forces (−λ) and stuck
    /// patches (s f − μ_s N, s the sign of f where it broke loose) after an
    /// evaluation (N): positive once one lets go.
    fn constraint_violation(&self) -> f64 {
        let mut worst = f64::NEG_INFINITY;
        for &(item, sign) in &self.watched {
            let v = match item {
                Suspect::Point(i) => -self.points[i].held_force,
                Suspect::Patch(p) => {
                    let load = &self.patch_states[p];
                    sign * load.friction - self.patches[p].stick_bound * load.normal
                }
            };
            worst = worst.max(v);
        }
        worst
    }

    /// Cuts the last step back to fraction `theta`: the state there from the
    /// interpolant, every due switch applied, the modes settled.
    pub(super) fn land(&mut self, rk: &mut Rk, theta: f64) {
        let mut y = std::mem::take(&mut self.y);
        rk.dense_state(theta, &mut y);
        self.y = y;
        self.slope_current = false;
        self.clock.x += theta * rk.h;
        self.note_peaks();
        for k in 0..self.due.len() {
            let switch = self.due[k].1;
            self.apply(switch);
        }
        self.settle();
        rk.fresh = false;
    }

    /// Applies one switch (docs/model.md §2, §4).
    fn apply(&mut self, switch: Switch) {
        let lay = self.layout;
        let now = self.y[lay.time()];
        match switch {
            Switch::SlipStops(p) => self.patch_states[p].switched_at = now,
            Switch::CompressionEnds(i)
            | Switch::Recompresses(i)
            | Switch::LetsGo(i)
            | Switch::Closes(i)
            | Switch::HoldSpent(i) => self.points[i].switched_at = now,
        }
        match switch {
            Switch::CompressionEnds(i) => {
                let point = &mut self.points[i];
                let row = &self.rows[i];
                if row.law.restitution > 0.0 {
                    point.mode = PointMode::Expand;
                } else {
                    // e = 0: the stored energy is lost; after a cycle that
                    // moved the point's own rate by little, the next cycles
                    // are taken by their limit (held closed) if it is pushed
                    let impulse = self.y[lay.pn(i)];
                    let swing = row.w_nn * (impulse - point.cycle_start);
                    point.cycle_start = impulse;
                    self.y[lay.q(i)] = 0.0;
                    point.released = swing <= self.cycle_bound;
                }
            }
            Switch::Recompresses(i) => self.points[i].mode = PointMode::Compress,
            Switch::LetsGo(i) => {
                self.end_cycle(i);
                self.points[i].mode = PointMode::Compress;
                self.y[lay.q(i)] = 0.0;
            }
            // the segment restarts at the onset (see `Variable::Root`); a
            // patch without slip sticks from here (modes.rs)
            Switch::Closes(i) => {
                // a gap closed with an earlier switch (`close_with`) may be
                // a rounding short of contact
                self.y[lay.q(i)] = self.y[lay.q(i)].max(0.0);
                self.points[i].closed_at = now;
                self.closes_after_cycle(i);
            }
            Switch::HoldSpent(i) => {
                // on from rest, touching, under the law (no stored energy)
                let point = &mut self.points[i];
                point.mode = PointMode::Compress;
                point.hold_limit = f64::INFINITY;
                point.fast_rebound = false;
                point.cycle_start = self.y[lay.pn(i)];
                self.y[lay.q(i)] = 0.0;
                self.constraints_dirty = true;
            }
            Switch::SlipStops(p) => self.set_patch(p, PatchMode::Stick),
        }
    }
}

/// A watched condition of the state, linear in it: one or two quantities,
/// each given by its interpolant's coefficients, a sign and a target. The
/// switch happens where every sign · quantity − target is positive.
#[derive(Clone, Copy, Debug)]
struct Watch {
    switch: Switch,
    first: ([f64; 5], f64, f64),
    second: Option<([f64; 5], f64, f64)>,
}

impl Watch {
    fn one(switch: Switch, first: ([f64; 5], f64, f64)) -> Self {
        Watch {
            switch,
            first,
            second: None,
        }
    }

    fn both(switch: Switch, first: ([f64; 5], f64, f64), second: ([f64; 5], f64, f64)) -> Self {
        Watch {
            switch,
            first,
            second: Some(second),
        }
    }

    /// min over the conditions of sign · quantity(θ) − target.
    fn phi(&self, t: f64) -> f64 {
        let one = |(g, sign, target): ([f64; 5], f64, f64)| sign * horner(&g, t) - target;
        match self.second {
            Some(second) => one(self.first).min(one(second)),
            None => one(self.first),
        }
    }
}

/// (state index, weight) of the rate along `axis` of body `b` against `a`.
fn terms(a: usize, b: usize, axis: &Axis) -> [(usize, f64); 6] {
    [
        (3 * b, axis.dir[0]),
        (3 * b + 1, axis.dir[1]),
        (3 * b + 2, axis.arm_b),
        (3 * a, -axis.dir[0]),
        (3 * a + 1, -axis.dir[1]),
        (3 * a + 2, -axis.arm_a),
    ]
}

/// The interpolant g₁ + θ (g₂ + (1 − θ)(g₃ + θ (g₄ + (1 − θ) g₅))).
#[inline]
fn horner(g: &[f64; 5], t: f64) -> f64 {
    let s = 1.0 - t;
    g[0] + t * (g[1] + s * (g[2] + t * (g[3] + s * g[4])))
}

/// The first θ ∈ (`from`, `upto`] where φ turns positive (φ(from) taken as
/// ≤ 0), on eight samples refined by Illinois; the returned θ is on the
/// positive side.
fn first_crossing(phi: impl Fn(f64) -> f64, from: f64, upto: f64) -> Option<f64> {
    if upto <= from {
        return None;
    }
    let (mut lo, mut f_lo) = (from, phi(from).min(0.0));
    for j in 1..=8 {
        let t = from + (upto - from) * j as f64 / 8.0;
        let f = phi(t);
        if f > 0.0 {
            return Some(illinois(&phi, (lo, f_lo), (t, f)));
        }
        (lo, f_lo) = (t, f);
    }
    None
}

/// [`first_crossing`] for a φ that needs the integrator (four samples).
///
/// A condition that sits at its boundary at the start (φ(0) within 10⁻⁹ of
/// the first positive sample, e.g. a friction force at its bound when the
/// slip stopped) and turns positive at once is landed on right after the
/// start (θ = 10⁻⁶ of the bracket) instead of bisecting towards θ = 0; the
/// modes are then settled there (modes.rs), which switches it.
fn first_crossing_mut(
    s: &mut Integrator,
    mut phi: impl FnMut(&mut Integrator, f64) -> f64,
    upto: f64,
) -> Option<f64> {
    let (mut lo, mut f_lo) = (0.0, f64::NEG_INFINITY);
    for j in 1..=4 {
        let t = upto * j as f64 / 4.0;
        let f = phi(s, t);
        if f > 0.0 {
            if !f_lo.is_finite() {
                f_lo = phi(s, 0.0).min(0.0);
            }
            if f_lo >= -1e-9 * f {
                let near = lo + 1e-6 * (t - lo);
                if phi(s, near) > 0.0 {
                    return Some(near);
                }
            }
            let mut g = |t: f64| phi(s, t);
            return Some(illinois_mut(
                &mut g,
                (lo, f_lo),
                (t, f),
                NONLINEAR_WIDTH * upto,
            ));
        }
        (lo, f_lo) = (t, f);
    }
    None
}

fn illinois(phi: &impl Fn(f64) -> f64, lo: (f64, f64), hi: (f64, f64)) -> f64 {
    let mut g = |t: f64| phi(t);
    let width = ROOT_WIDTH * hi.0;
    illinois_mut(&mut g, lo, hi, width)
}

/// Regula falsi with the Illinois halving, on a bracket with φ(lo) ≤ 0 < φ(hi),
/// until it is at most `width` wide (in θ).
fn illinois_mut(
    phi: &mut impl FnMut(f64) -> f64,
    lo: (f64, f64),
    hi: (f64, f64),
    width: f64,
) -> f64 {
    let ((mut a, mut fa), (mut b, mut fb)) = (lo, hi);
    let mut side = 0;
    for _ in 0..64 {
        if b - a <= width {
            break;
        }
        let t = if fb - fa > 0.0 && fa.is_finite() {
            (a - fa * (b - a) / (fb - fa)).clamp(a, b)
        } else {
            0.5 * (a + b)
        };
        let t = if t <= a || t >= b { 0.5 * (a + b) } else { t };
        let f = phi(t);
        if f > 0.0 {
            (b, fb) = (t, f);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        } else {
            (a, fa) = (t, f);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_first_of_two_crossings() {
        // φ = −(θ − 0.3)(θ − 0.7) is positive between its roots
        let phi = |t: f64| -(t - 0.3) * (t - 0.7);
        let t = first_crossing(phi, 0.0, 1.0).unwrap();
        assert!((t - 0.3).abs() < 1e-12, "{t}");
        assert!(phi(t) > 0.0 || phi(t).abs() < 1e-15);
    }

    #[test]
    fn no_crossing_is_none() {
        assert_eq!(first_crossing(|t| -1.0 - t, 0.0, 1.0), None);
    }
}
