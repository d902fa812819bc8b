//! Stage 7: the stepping loop — step size control, free flight between
//! contacts, the end of the impact.
//!
//! A step is accepted when its error estimate is within the tolerance; the
//! next step is h · 0.9 err^(−1/5), between 0.2 h and 5 h (the usual
//! controller of a fifth-order pair). A point whose gap closes while it
//! approaches starts with a force growing as t^α, which no polynomial in t
//! follows: such a segment is stepped in x = √(t − t₀) (see `Clock`), its
//! first step a fraction of the square root of the point's time scale.
//!
//! When no point is loaded or held, every force is zero and the velocities
//! are constant: the gaps move linearly and the loop jumps to the first one
//! that closes (paper Sec. 2.3: the micro-gaps of the frozen positions), or
//! ends the impact when none approaches.
//!
//! With a rest speed ([`crate::impact::ImpactSettings::rest_speed`]) the
//! impact also ends as soon as no point approaches faster than it and none
//! stores the energy to rebound faster (docs/model.md §9).

use super::super::{ImpactError, ImpactOutcome, StopReason};
use super::data::{normal_rate, Clock, PointMode, Variable};
use super::tableau::Rk;
use super::Integrator;

/// The step size controller of Hairer, Nørsett and Wanner's DOPRI5 (a
/// proportional–integral controller, *Solving ODEs I* Sec. II.4 and IV.2):
/// the next step is h / (err^(1/5 − 3β/4) err_prev^(−β) / 0.9), between
/// 0.2 h and 5 h, with β = 0.04; a rejected step shrinks by
/// err^(−(1/5 − 3β/4)) · 0.9, at least to 0.2 h.
#[derive(Clone, Copy, Debug)]
struct Controller {
    previous: f64,
}

impl Default for Controller {
    fn default() -> Self {
        Controller { previous: 1e-4 }
    }
}

const BETA: f64 = 0.04;
const SAFETY: f64 = 0.9;
const GROW: f64 = 5.0;
const SHRINK: f64 = 0.2;

impl Controller {
    /// The factor of the next step after an accepted one (err ≤ 1).
    fn accepted(&mut self, err: f64) -> f64 {
        let err = err.max(1e-10);
        let factor = err.powf(0.2 - 0.75 * BETA) / self.previous.powf(BETA) / SAFETY;
        self.previous = err.max(1e-4);
        (1.0 / factor).clamp(SHRINK, GROW)
    }

    /// The factor of the next attempt after a rejected step (err > 1 or NaN).
    fn rejected(&self, err: f64) -> f64 {
        if err.is_nan() {
            return SHRINK;
        }
        (SAFETY / err.powf(0.2 - 0.75 * BETA)).clamp(SHRINK, 1.0)
    }
}

/// First step of a segment that starts with an approaching point, in units
/// of √T at the tolerance 10⁻⁵ (T the point's time scale, law.rs).
const ONSET_STEP: f64 = 0.3;

/// A switch landed on within this fraction of the step it was found in
/// makes no progress if it is one of a run of such switches
/// (see `standstill` in the loop).
const CRAWL: f64 = 1e-5;

/// Right-hand-side evaluations of one step (Dormand–Prince, first same as
/// last): the step limit counts this many settling evaluations as a step.
const STAGES: usize = 6;

/// An expanding point that lets go within this many of the controller's
/// next steps (at its present rate) ends the present segment: the rest of
/// its contact is stepped in x = σ₀ − √q (see `Variable::End`). Steps in x
/// cover less time per step than steps in t at the same error (t(x) bends
/// over the segment: dt/dx falls to 0 at its end), so a shorter segment
/// takes fewer steps: 1.1 takes 5 % fewer than 1.5 on the leaning train
/// and 2 % on the Domino X row and the pile with the same errors
/// (docs/impact.md, "Steps per impact, round nine"). Below one step a step
/// in time crosses the release, where the force has no fifth-order
/// expansion (0.7: errors ×10).
const END_WITHIN: f64 = 1.1;

/// A root segment goes on in time once x is this many steps past the onset
/// (the t^α start is resolved by then).
const ROOT_SPAN: f64 = 3.0;

impl Integrator {
    /// Integrates the loaded impact to its end.
    pub(super) fn run(
        &mut self,
        max_steps: usize,
        out: &mut ImpactOutcome,
    ) -> Result<StopReason, ImpactError> {
        if self.scales.velocity == 0.0 {
            return Ok(StopReason::NoApproach);
        }
        self.constraints_dirty = true;
        self.settle();
        let mut rk = std::mem::take(&mut self.rk);
        rk.resize(self.layout.len());
        let result = self.step_loop(&mut rk, max_steps, out);
        self.rk = rk;
        result
    }

    fn step_loop(
        &mut self,
        rk: &mut Rk,
        max_steps: usize,
        out: &mut ImpactOutcome,
    ) -> Result<StopReason, ImpactError> {
        let mut h = self.begin_segment(rk, None);
        let mut attempts = 0usize;
        let mut control = Controller::default();
        // free flights since the last step: each one closes a gap, so more
        // than one per point without a step in between is a loop that makes
        // no progress (a point that closes but does not load)
        let mut flights = 0usize;
        // switches landed on one after another without time moving on, or
        // moving by a vanishing part of each step: the modes cycle at one
        // instant (a set of stick/slip conditions with no consistent
        // choice, e.g. a stuck patch at its bound μ_s N that breaks loose
        // and, sliding with μ < μ_s, is turned back to sticking by the rows
        // around it); more than any settling could need is a loop that
        // makes no progress
        let mut standstill = 0usize;
        let standstill_cap = 8 + 2 * (self.rows.len() + self.patches.len());
        loop {
            if self.rest_speed > 0.0 && self.at_rest() {
                return Ok(StopReason::AtRest);
            }
            if !self.any_loaded() {
                if !self.free_flight() {
                    return Ok(StopReason::Released);
                }
                flights += 1;
                if flights > self.layout.contacts + 2
                    || attempts + self.settling / STAGES > max_steps
                {
                    return Err(ImpactError::StepLimit { steps: out.steps });
                }
                self.settle();
                h = self.begin_segment(rk, None);
                continue;
            }
            attempts += 1;
            // settling the modes at switches costs evaluations too; a set of
            // modes that keeps cycling would otherwise spend them unbounded
            if attempts + self.settling / STAGES > max_steps {
                return Err(ImpactError::StepLimit { steps: out.steps });
            }
            if let Variable::End { sigma, .. } = self.clock.variable {
                h = h.min(sigma - self.clock.x);
            }
            rk.y0.copy_from_slice(&self.y);
            flights = 0;
            let err = self.rk_step(rk, h);
            if err.is_nan() || err > 1.0 {
                out.rejected_steps += 1;
                if err.is_nan() && matches!(self.clock.variable, Variable::End { .. }) {
                    // the ending point stopped separating: back to time
                    h = self.begin_time_segment(rk, self.pace);
                    continue;
                }
                h *= control.rejected(err);
                if self.too_short(h) {
                    if self.clock.variable == Variable::Time {
                        return Err(ImpactError::NonFinite { steps: out.steps });
                    }
                    // the segment's variable does not suit the state any more
                    h = self.begin_time_segment(rk, self.scales.time * 1e-3);
                }
                continue;
            }
            out.steps += 1;
            let grow = control.accepted(err);
            let switch = if self.suspects.is_empty() {
                None
            } else {
                self.locate(rk)
            };
            // the controller's next step, in time
            let next = self.step_time(rk) * grow;
            if let Some(theta) = switch {
                let before = self.y[self.layout.time()];
                self.land(rk, theta);
                let moved = self.y[self.layout.time()] - before;
                if moved <= self.min_step || theta <= CRAWL {
                    standstill += 1;
                    if standstill > standstill_cap {
                        return Err(ImpactError::StepLimit { steps: out.steps });
                    }
                } else {
                    standstill = 0;
                }
                if !matches!(self.clock.variable, Variable::End { .. }) {
                    self.pace = next;
                }
                h = self.begin_segment(rk, Some(self.pace));
                continue;
            }
            self.y.copy_from_slice(&rk.y1);
            self.slope_current = false;
            self.clock.x += h;
            self.note_peaks();
            rk.advance();
            h *= grow;
            if let Variable::End { point, sigma } = self.clock.variable {
                if self.clock.x >= sigma * (1.0 - 1e-12) {
                    // the ending point lets go here, and with it any other
                    // expanding point that is as good as spent
                    self.let_go(point);
                    self.settle();
                    h = self.begin_segment(rk, Some(self.pace));
                }
            } else {
                self.pace = next;
                // in time the first stage of the next step is dy/dt here
                let known = (self.clock.variable == Variable::Time).then_some(&rk.k[0][..]);
                if let Some(end) = self.ending_point(next, known) {
                    h = self.begin_end_segment(rk, end);
                } else if self.clock.variable == Variable::Root && self.clock.x > ROOT_SPAN * h {
                    // the onset is behind: on in time
                    h = self.begin_time_segment(rk, next);
                }
            }
        }
    }

    /// Whether every point approaches slower than the rest speed and stores
    /// too little energy to rebound faster: √(2 e² E(q) W_nn) below it,
    /// e² E(q) being what the point gives back from compression q, whether
    /// it is still compressing or already expanding (law.rs).
    fn at_rest(&self) -> bool {
        let lay = self.layout;
        let rest = self.rest_speed;
        self.rows.iter().enumerate().all(|(i, row)| {
            if !row.movable {
                return true;
            }
            if -normal_rate(row, &self.y) > rest {
                return false;
            }
            let q = self.y[lay.q(i)];
            if q <= 0.0 || self.points[i].mode == PointMode::Held {
                return true;
            }
            let rebound = row.law.restitution_sq() * row.law.energy(q);
            2.0 * rebound * row.w_nn <= rest * rest
        })
    }

    /// Time (s) covered by the last step.
    fn step_time(&self, rk: &Rk) -> f64 {
        let t = self.layout.time();
        rk.y1[t] - rk.y0[t]
    }

    /// Whether a step of `h` in x is below the shortest step worth taking.
    fn too_short(&self, h: f64) -> bool {
        let t = match self.clock.variable {
            Variable::Time => h,
            Variable::Root => (self.clock.x + h).powi(2) - self.clock.x.powi(2),
            Variable::End { sigma, .. } => h / sigma.max(f64::MIN_POSITIVE) * self.scales.time,
        };
        t.is_nan() || t <= self.min_step
    }

    /// Starts a segment at the present state and returns its first step (in
    /// the segment's x): x = √(t − t₀) when a point starts to load while it
    /// approaches, its first step a fraction of √T (T its time scale);
    /// x = σ₀ − √q when an expanding point lets go within the next step; else
    /// x = t − t₀ with the step `next` (s) the controller proposed, or a
    /// hundredth of the impact's time scale.
    fn begin_segment(&mut self, rk: &mut Rk, next: Option<f64>) -> f64 {
        rk.fresh = false;
        let next = next.unwrap_or(0.01 * self.scales.time);
        self.pace = next;
        if let Some(t) = self.onset_scale() {
            self.clock = Clock {
                variable: Variable::Root,
                x: 0.0,
            };
            return ONSET_STEP * (t * (self.tolerance / 1e-5).powf(0.4)).sqrt();
        }
        match self.ending_point(next, None) {
            Some(end) => self.begin_end_segment(rk, end),
            None => self.begin_time_segment(rk, next),
        }
    }

    fn begin_time_segment(&mut self, rk: &mut Rk, next: f64) -> f64 {
        rk.fresh = false;
        self.clock = Clock {
            variable: Variable::Time,
            x: 0.0,
        };
        next
    }

    /// A segment to the end of the expanding point `point`, tried in one step.
    /// Its first step: the controller's pace (s) turned into x with
    /// dt/dx = 2σ e²/δ̇ at its start, all the way if that is further.
    fn begin_end_segment(&mut self, rk: &mut Rk, point: usize) -> f64 {
        rk.fresh = false;
        let row = &self.rows[point];
        let sigma = self.y[self.layout.q(point)].max(0.0).sqrt();
        let slope = 2.0 * sigma * row.law.restitution_sq() / normal_rate(row, &self.y);
        self.clock = Clock {
            variable: Variable::End { point, sigma },
            x: 0.0,
        };
        if slope > 0.0 {
            sigma.min(self.pace / slope)
        } else {
            sigma
        }
    }

    /// The expanding point that, at its present rate, lets go first and
    /// within [`END_WITHIN`] × `next` (s), if any; only while it clearly separates and
    /// is not being pushed back in (its rate would not reach zero before it
    /// lets go). `known`: dy/dt at the present state, if the caller has it.
    fn ending_point(&mut self, next: f64, known: Option<&[f64]>) -> Option<usize> {
        let lay = self.layout;
        let mut first = None;
        let mut soonest = END_WITHIN * next;
        for (i, row) in self.rows.iter().enumerate() {
            if self.points[i].mode != PointMode::Expand {
                continue;
            }
            let rate = normal_rate(row, &self.y);
            if rate <= 1e-3 * self.scales.velocity {
                continue;
            }
            let left = self.y[lay.q(i)] * row.law.restitution_sq() / rate;
            if left < soonest {
                soonest = left;
                first = Some(i);
            }
        }
        let i = first?;
        // the rate's change over the time left, from dv/dt
        let row = &self.rows[i];
        let accel = match known {
            Some(slope) => normal_rate(row, slope),
            None => {
                if !self.slope_current {
                    let mut slope = std::mem::take(&mut self.probe_slope);
                    let y = std::mem::take(&mut self.y);
                    self.eval(&y, &mut slope, false);
                    self.y = y;
                    self.probe_slope = slope;
                    self.slope_current = true;
                }
                normal_rate(&self.rows[i], &self.probe_slope)
            }
        };
        let rate = normal_rate(&self.rows[i], &self.y);
        (rate + 2.0 * accel.min(0.0) * soonest > 0.5 * rate).then_some(i)
    }

    /// An ending point's compression reached zero: it lets go, and so does
    /// every other expanding point within 10⁻⁹ of its compression scale
    /// (points of one flat face that let go together).
    fn let_go(&mut self, point: usize) {
        self.slope_current = false;
        let lay = self.layout;
        self.y[lay.q(point)] = 0.0;
        self.points[point].mode = PointMode::Compress;
        self.end_cycle(point);
        for i in 0..lay.contacts {
            let spent = self.points[i].mode == PointMode::Expand
                && self.y[lay.q(i)] <= 1e-9 * self.rows[i].q_scale;
            if spent {
                self.y[lay.q(i)] = 0.0;
                self.points[i].mode = PointMode::Compress;
                self.end_cycle(i);
            }
        }
    }

    /// Whether any point carries force or is about to.
    fn any_loaded(&self) -> bool {
        (0..self.layout.contacts).any(|i| match self.points[i].mode {
            PointMode::Held => self.points[i].held_force > 0.0,
            _ => self.carries_load(i),
        })
    }

    /// With every force zero: moves the gaps to the first closing one (s of
    /// free flight) and marks it closed; false if none approaches.
    fn free_flight(&mut self) -> bool {
        self.slope_current = false;
        let thr = self.scales.rate;
        let lay = self.layout;
        let mut first = None;
        let mut shortest = f64::INFINITY;
        for (i, row) in self.rows.iter().enumerate() {
            let rate = normal_rate(row, &self.y);
            if row.movable && rate < -thr {
                let t = (-self.y[lay.q(i)]).max(0.0) / -rate;
                if t < shortest {
                    shortest = t;
                    first = Some(i);
                }
            }
        }
        let Some(first) = first else {
            return false;
        };
        for (i, row) in self.rows.iter().enumerate() {
            if row.movable {
                self.y[lay.q(i)] -= normal_rate(row, &self.y) * shortest;
            }
        }
        self.y[lay.q(first)] = 0.0;
        self.y[lay.time()] += shortest;
        self.closes_after_cycle(first);
        true
    }

    /// The shortest time scale (s) of the points that start to load while
    /// they approach (mode compression, q ≈ 0, δ̇ < 0); `None` if none does.
    fn onset_scale(&self) -> Option<f64> {
        let lay = self.layout;
        let mut scale: Option<f64> = None;
        for (i, row) in self.rows.iter().enumerate() {
            let point = &self.points[i];
            let q = self.y[lay.q(i)];
            let starting = point.mode == PointMode::Compress && q.abs() <= row.q_load;
            let rate = normal_rate(row, &self.y);
            // a point that loads from rest (its rate starting from zero)
            // starts smoothly; only a real approach needs the root variable
            if starting && rate < -self.scales.onset {
                let t = row.law.time_scale(-rate, row.w_nn);
                scale = Some(scale.map_or(t, |s| s.min(t)));
            }
        }
        scale
    }
}
