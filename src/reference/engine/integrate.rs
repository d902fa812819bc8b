//! One step of the smooth phase (paper Eqs. 17–20 with the contact mode held
//! fixed): the derivative, the paper's improved Euler or Dormand–Prince with
//! error control, and the step shortened by bisection to the first event.

use super::super::dynamics::Active;
use super::super::dynamics::{Dynamics, Mode, RowConst, View};
use super::super::geometry::geom;
use super::super::settings::Integrator;
use super::super::stepper::{DOPRI5, HEUN};
use super::{Engine, EngineError, EventKey};

fn rhs(
    dynamics: &mut Dynamics,
    rc: &RowConst,
    lo: usize,
    hi: usize,
    pos: &[[f64; 3]],
    active: &[Active],
    y: &[f64],
    dy: &mut [f64],
) -> bool {
    let view = View { lo, hi, y, pos };
    if !dynamics.forces(rc, &view, active) {
        return false;
    }
    for b in 0..hi - lo {
        for x in 0..3 {
            dy[6 * b + x] = y[6 * b + 3 + x];
            dy[6 * b + 3 + x] = dynamics.acc[b][x];
        }
    }
    let last = dy.len() - 1;
    dy[last] = -dynamics.power;
    dy.iter().all(|v| v.is_finite())
}

impl Engine {
    /// The derivative at the state, and the references of the events for
    /// the next step. `after_mode`: the contact mode was chosen at this
    /// state (an event, a window change); otherwise the mode is the one
    /// held since the last event.
    pub(super) fn eval_k0(&mut self, after_mode: bool) -> Result<(), EngineError> {
        self.k0.resize(self.y.len(), 0.0);
        self.evaluations += 1;
        if !rhs(
            &mut self.dynamics,
            &self.rc,
            self.lo,
            self.hi,
            &self.pos,
            &self.active,
            &self.y,
            &mut self.k0,
        ) {
            return Err(EngineError::Singular(self.t));
        }
        self.set_references(after_mode);
        Ok(())
    }

    /// The derivative for the next step from the forces of the event test
    /// at the step's end (`forces_at_y1`, held in the dynamics), taken at
    /// the state the projection made of it: the positions move with the
    /// projected velocities, the accelerations and the contact power are
    /// those of the step's end. The projection moved the state by the
    /// drift of one step off the constraints, O(Δt³), so the derivative
    /// differs from one solved at the projected state by as much, and the
    /// step that follows by O(Δt⁴): below the order of the paper's
    /// improved Euler (local error O(Δt³)), and one force solve fewer per
    /// step. The event references follow from the same forces.
    fn k0_from_step_end(&mut self) -> Result<(), EngineError> {
        self.k0.resize(self.y.len(), 0.0);
        let d = &self.dynamics;
        for b in 0..self.hi - self.lo {
            for x in 0..3 {
                self.k0[6 * b + x] = self.y[6 * b + 3 + x];
                self.k0[6 * b + 3 + x] = d.acc[b][x];
            }
        }
        let last = self.k0.len() - 1;
        self.k0[last] = -d.power;
        if !self.k0.iter().all(|v| v.is_finite()) {
            return Err(EngineError::Singular(self.t));
        }
        self.set_references(false);
        Ok(())
    }

    /// The forces at the step start (`start_forces`) and the event
    /// references of the next step, from the forces in the dynamics.
    fn set_references(&mut self, after_mode: bool) {
        let d = &self.dynamics;
        self.start_forces.clear();
        self.start_forces
            .extend((0..self.active.len()).map(|c| [d.fn_[c], d.ft[c], d.vt[c]]));
        // Event references at the start of the step. A condition already
        // violated where the mode was chosen (a mode the search could not
        // make consistent, `modes::select`) is no event: it would fire at
        // every step and stall the run; the next event runs the search
        // again. A condition that was met there and has drifted past its
        // tolerance since, a little in each step (each step's reference is
        // its start), is an event at once: otherwise a block whose slip
        // reversed slowly kept its friction along the old direction, which
        // then drove it on (seed 3, combo 2555 of the full stress sweep).
        let same = !after_mode && self.ref_fn.len() == self.active.len();
        if !same {
            self.ref_fn.clear();
            self.ref_stick.clear();
            self.ref_slide.clear();
        }
        let (force, slip) = (self.tol.force, 0.5 * self.v_tol);
        // a violation: no event if it was there where the mode was chosen
        let late = |before: Option<f64>, none: f64| match before {
            Some(r) if r.is_finite() => 0.0,
            _ => none,
        };
        for (c, a) in self.active.iter().enumerate() {
            let before = |r: &[f64]| same.then(|| r[c]);
            let fnn = self.dynamics.fn_[c];
            let ref_fn = if fnn < -force {
                late(before(&self.ref_fn), f64::NEG_INFINITY)
            } else {
                fnn.min(0.0)
            };
            let excess = self.rc.stick_excess(a.slot, self.dynamics.ft[c], fnn);
            let ref_stick = if excess > force {
                late(before(&self.ref_stick), f64::INFINITY)
            } else {
                excess.max(0.0)
            };
            let dir = match a.mode {
                Mode::Slide(d) => d,
                _ => 0.0,
            };
            let along = dir * self.dynamics.vt[c];
            let ref_slide = if along < -slip {
                late(before(&self.ref_slide), f64::NEG_INFINITY)
            } else {
                along.min(0.0)
            };
            if same {
                self.ref_fn[c] = ref_fn;
                self.ref_stick[c] = ref_stick;
                self.ref_slide[c] = ref_slide;
            } else {
                self.ref_fn.push(ref_fn);
                self.ref_stick.push(ref_stick);
                self.ref_slide.push(ref_slide);
            }
        }
    }

    /// The step's error estimate against the tolerance (Dormand–Prince;
    /// 0 for the paper's fixed step): above 1 the step is rejected.
    pub(super) fn error_norm(&self) -> f64 {
        let Integrator::Adaptive { tolerance } = self.s.integrator else {
            return 0.0;
        };
        let p = &self.rc.p;
        let scales = [
            p.block.height,
            p.block.height,
            1.0,
            p.speed_scale(),
            p.speed_scale(),
            p.speed_scale() / p.block.height,
        ];
        let mut worst = 0.0f64;
        let n = self.y.len() - 1;
        for x in 0..n {
            let e = self.stages.err[x].abs() / (tolerance * scales[x % 6]);
            worst = worst.max(e);
        }
        let ework = p.block.mass * p.gravity * p.block.height;
        worst.max(self.stages.err[n].abs() / (tolerance * ework))
    }

    /// One trial step of size h from `y` into `y1`; false if singular.
    pub(super) fn trial(&mut self, h: f64) -> bool {
        let tab = match self.s.integrator {
            Integrator::Paper { .. } => &HEUN,
            Integrator::Adaptive { .. } => &DOPRI5,
        };
        let dynamics = &mut self.dynamics;
        let rc = &self.rc;
        let (lo, hi) = (self.lo, self.hi);
        let pos = &self.pos;
        let active = &self.active;
        let mut evals = 0;
        let ok = self
            .stages
            .step(tab, h, &self.y, &self.k0, &mut self.y1, |y, dy| {
                evals += 1;
                rhs(dynamics, rc, lo, hi, pos, active, y, dy)
            });
        self.evaluations += evals;
        ok
    }

    /// Forces at y1 into the dynamics (for the event test).
    pub(super) fn forces_at_y1(&mut self) -> bool {
        let view = View {
            lo: self.lo,
            hi: self.hi,
            y: &self.y1,
            pos: &self.pos,
        };
        self.evaluations += 1;
        self.dynamics.forces(&self.rc, &view, &self.active)
    }

    /// The step length in (0, `h`] that ends within the event time
    /// tolerance after the first event of a step of length `h` whose end
    /// has one: the earliest length at which `events_at` finds one, to
    /// within `Settings::event_time_tolerance`, its state left in `ybest`.
    ///
    /// The search keeps the bracket [a, b] (no event at a, an event at b)
    /// and follows one condition that is violated at b (`EventProbe`), its
    /// margin at a = 0 taken from the step start (`start_margin`):
    /// with that condition's margin measured at both ends, the next trial
    /// length is the regula falsi point of the margin, with the Illinois
    /// modification (the margin kept at an end that stays twice in a row is
    /// halved) so that both ends close in; without both margins (a
    /// condition that has no continuous margin, a singular trial, a new
    /// condition taking over), the midpoint. A trial point is kept at least
    /// half the tolerance inside the bracket, and a bracket that has not
    /// halved in three trials is bisected, so the search never takes more
    /// trials than about three times the bisection it replaces (about 20
    /// trials for Δt = 10⁻⁴ s and 10⁻¹⁰ s) and usually far fewer, the
    /// margins being smooth in the step length. The event, and so the
    /// state at which it is handled, is the same as by bisection: the
    /// first step length at which the test fires, to the same tolerance.
    fn locate_event(&mut self, h: f64) -> f64 {
        let tol = self.s.event_time_tolerance;
        let finite = |m: Option<f64>| m.filter(|m| m.is_finite());
        let (mut a, mut b) = (0.0, h);
        // the followed condition's margin at a (≤ 0) and at b (> 0)
        let first = self.probe.first.filter(|(_, m)| m.is_finite());
        self.probe.watch = first.map(|(key, _)| key);
        let (mut fa, mut fb): (Option<f64>, Option<f64>) = (
            first.and_then(|(key, _)| self.start_margin(key)),
            first.map(|(_, m)| m),
        );
        // a contact closing: its crossing located on the positions alone
        // (`close_bracket`), the two ends of that bracket tried first
        let mut suggested = match (first, fa) {
            (Some((EventKey::Close(i, slot), mb)), Some(ma)) => self
                .close_bracket(i, slot, h, ma, mb)
                .map_or([None; 2], |(lo, hi)| [Some(lo), Some(hi)]),
            _ => [None; 2],
        };
        // which end the last trials moved (-1: a, +1: b), for Illinois
        let mut last_side = 0i8;
        let mut widths = [h; 3];
        let mut trials = 0usize;
        while b - a > tol {
            trials += 1;
            let halving_stalled = trials > 3 && b - a > 0.5 * widths[trials % 3];
            widths[trials % 3] = b - a;
            let mid = 0.5 * (a + b);
            let suggestion = suggested
                .iter_mut()
                .find_map(|s| s.take().filter(|&s| s > a && s < b));
            let t = match (fa, fb) {
                _ if suggestion.is_some() => suggestion.unwrap_or(mid),
                (Some(ma), Some(mb)) if !halving_stalled && mb > ma => {
                    let t = a + (b - a) * (-ma / (mb - ma));
                    t.clamp(a + 0.5 * tol, b - 0.5 * tol)
                }
                _ => mid,
            };
            let ok = self.trial(t) && self.forces_at_y1();
            let y1 = std::mem::take(&mut self.y1);
            let ev = !ok || self.events_at(&y1);
            self.y1 = y1;
            let watched = if ok { finite(self.probe.watched) } else { None };
            if ev {
                b = t;
                self.ybest.clone_from(&self.y1);
                match watched.filter(|m| *m > 0.0) {
                    Some(m) => {
                        fb = Some(m);
                        if last_side == 1 {
                            fa = fa.map(|v| 0.5 * v);
                        }
                    }
                    None => {
                        // another condition fires first: follow it
                        let next = if ok { self.probe.first } else { None };
                        let next = next.filter(|(_, m)| m.is_finite());
                        self.probe.watch = next.map(|(key, _)| key);
                        fb = next.map(|(_, m)| m);
                        fa = None;
                    }
                }
                last_side = 1;
            } else {
                a = t;
                fa = watched.filter(|m| *m <= 0.0);
                if last_side == -1 {
                    fb = fb.map(|v| 0.5 * v);
                }
                last_side = -1;
            }
        }
        self.probe.watch = None;
        b
    }

    /// The bracket [lo, hi] (step lengths, s; hi − lo within the event
    /// time tolerance) in which candidate (i, slot)'s gap, at the end of a
    /// Heun step of that length from the step start, crosses −ε (its
    /// closing margin crosses 0), found on the positions alone: a Heun step
    /// of length t ends at q + t/2 (q̇ + (q̇ + t q̈)) with q̇, q̈ of the
    /// step start (`k0`), a polynomial in t that needs no force solve. The
    /// positions are computed by the operations of the written-out Heun
    /// step (`stepper.rs`), so the gap at a length is the one the full trial
    /// there measures, to the bit. `ma` ≤ 0 and `mb` > 0 are the margins
    /// at lengths 0 and `h`. The search is the one of
    /// [`Engine::locate_event`] (regula falsi, Illinois, halving where it
    /// stalls) on this one margin. `None` for the Dormand–Prince
    /// integrator (its positions need the stages' solves), or where the
    /// contact leaves its face or the search does not close in.
    fn close_bracket(&self, i: usize, slot: usize, h: f64, ma: f64, mb: f64) -> Option<(f64, f64)> {
        if !matches!(self.s.integrator, Integrator::Paper { .. }) {
            return None;
        }
        let tol = self.s.event_time_tolerance;
        let (mut a, mut b, mut fa, mut fb) = (0.0, h, ma, mb);
        let mut last_side = 0i8;
        let mut widths = [h; 3];
        let mut evals = 0usize;
        while b - a > tol {
            evals += 1;
            if evals > 200 {
                return None;
            }
            let halving_stalled = evals > 3 && b - a > 0.5 * widths[evals % 3];
            widths[evals % 3] = b - a;
            let t = if !halving_stalled && fb > fa {
                let t = a + (b - a) * (-fa / (fb - fa));
                t.clamp(a + 0.5 * tol, b - 0.5 * tol)
            } else {
                0.5 * (a + b)
            };
            let m = self.close_margin_after(i, slot, t)?;
            if m > 0.0 {
                b = t;
                fb = m;
                if last_side == 1 {
                    fa *= 0.5;
                }
                last_side = 1;
            } else {
                a = t;
                fa = m;
                if last_side == -1 {
                    fb *= 0.5;
                }
                last_side = -1;
            }
        }
        Some((a, b))
    }

    /// The closing margin of candidate (i, slot) (`events_at`: (−ε − δ)/ε)
    /// at the end of a Heun step of length `t` from the step start, from
    /// the positions alone (see [`Engine::close_bracket`]); `None` if the
    /// slot does not exist or its corner is off its face there.
    fn close_margin_after(&self, i: usize, slot: usize, t: f64) -> Option<f64> {
        let (lo, hi) = (self.lo, self.hi);
        let (y, k0) = (&self.y, &self.k0);
        let q = |j: usize| -> [f64; 3] {
            if j < lo || j >= hi {
                return self.pos[j];
            }
            let k = 6 * (j - lo);
            std::array::from_fn(|x| {
                // the stage's velocity, then the step's end, as `Stages::heun`
                let stage_v = y[k + 3 + x] + t * (0.0 + 1.0 * k0[k + 3 + x]);
                y[k + x] + t * (0.0 + 0.5 * k0[k + x] + 0.5 * stage_v)
            })
        };
        let p = &self.rc.p;
        let g = geom(&p.block, p.lambda_points, self.row.n, i, slot, q)?;
        g.valid.then(|| (-self.eps_gap - g.gap) / self.eps_gap)
    }

    /// The margin of an event condition (`EventProbe`) at the step start,
    /// if it has one there and it is not violated: from the forces of
    /// `eval_k0` for an active contact, from the geometry at `y` for a
    /// candidate closing.
    fn start_margin(&self, key: EventKey) -> Option<f64> {
        let (force, slip) = (self.tol.force, 0.5 * self.v_tol);
        let margin = match key {
            EventKey::Lift(c) => {
                let [fnn, _, _] = *self.start_forces.get(c)?;
                (self.ref_fn[c] - force - fnn) / force
            }
            EventKey::Stick(c) => {
                let [fnn, ft, _] = *self.start_forces.get(c)?;
                let excess = self.rc.stick_excess(self.active[c].slot, ft, fnn);
                (excess - (self.ref_stick[c] + force)) / force
            }
            EventKey::Slide(c) => {
                let [_, _, vt] = *self.start_forces.get(c)?;
                let Mode::Slide(dir) = self.active[c].mode else {
                    return None;
                };
                (self.ref_slide[c] - slip - dir * vt) / slip
            }
            EventKey::Close(i, slot) => {
                let g = self.rc.geom(&self.view(), i, slot)?;
                if !g.valid {
                    return None;
                }
                (-self.eps_gap - g.gap) / self.eps_gap
            }
        };
        (margin.is_finite() && margin <= 0.0).then_some(margin)
    }

    /// Advances by one accepted step (possibly shortened to an event).
    pub(super) fn advance(&mut self, t_end: f64) -> Result<(), EngineError> {
        let mut h = match self.s.integrator {
            Integrator::Paper { dt } => dt,
            Integrator::Adaptive { .. } => self.h_adapt,
        };
        h = h.min(t_end - self.t).max(1e-14);
        // error control
        let mut tries = 0;
        let mut h_next = h;
        loop {
            tries += 1;
            if tries > 60 {
                return Err(EngineError::Singular(self.t));
            }
            if !self.trial(h) {
                h *= 0.5;
                continue;
            }
            let err = self.error_norm();
            if err > 1.0 {
                h *= (0.9 * err.powf(-0.2)).clamp(0.1, 0.5);
                continue;
            }
            if let Integrator::Adaptive { .. } = self.s.integrator {
                let grow = if err > 0.0 {
                    (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
                } else {
                    5.0
                };
                h_next = (h * grow).min(0.002 * self.rc.p.time_scale());
            }
            break;
        }
        // events
        let mut event = false;
        if !self.forces_at_y1() {
            return Err(EngineError::Singular(self.t));
        }
        let y1 = std::mem::take(&mut self.y1);
        let ev = self.events_at(&y1);
        self.y1 = y1;
        if ev {
            event = true;
            self.ybest.clone_from(&self.y1);
            h = self.locate_event(h);
            std::mem::swap(&mut self.y1, &mut self.ybest);
            h_next = h_next.max(1e-3 * self.rc.p.time_scale().min(h_next));
        }
        std::mem::swap(&mut self.y, &mut self.y1);
        self.t += h;
        self.steps += 1;
        let last = self.y.len() - 1;
        self.energy.friction += self.y[last];
        self.y[last] = 0.0;
        self.h_adapt = h_next;
        if event || self.mode_unsettled {
            self.handle_events()?;
        } else {
            // the forces of the event test are those at this state and
            // active set: the projection takes their geometry
            if self.project(true) {
                self.eval_k0(false)?;
            } else {
                self.k0_from_step_end()?;
            }
        }
        self.freeze()?;
        self.record();
        Ok(())
    }
}
