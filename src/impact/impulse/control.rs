//! Stage 7: the entry and step control — the paper's fixed step ΔP = STEP · P₀ (paper
//! Sec. 3.1, docs/model.md §6) and the adaptive impulse step with its local
//! error estimates; the step limit and the finiteness check.
//!
//! The adaptive step's error of a full step, relative to the velocity scale
//! (m/s over m/s), is the larger of
//! - the ratio error: max_i W_ii |dP_i − dP_i^E| between the improved-Euler
//!   increments taken and the explicit-Euler ones distributed with the start
//!   energies (second order in h);
//! - the friction error: μ dP_n W_tt of a contact stuck at the step's start
//!   that slides in it (the break-loose point is not located);
//! - the gap error: the fraction of a step a closing gap spent closed
//!   without force (energy.rs).
//!
//! With a rest speed ([`crate::impact::ImpactSettings::rest_speed`]) the
//! impact ends as soon as no contact approaches faster than it and none
//! stores the energy to rebound faster (docs/model.md §9).
//!
//! A step whose error exceeds the tolerance is taken again with
//! h · clamp(0.9/√err, 0.1, 0.9); an accepted one grows by
//! clamp(0.9/√err, 0.2, 5), from what a landing let it take.

use super::super::{Body, Contact, ImpactError, ImpactOutcome, ImpactSettings, StopReason};
use super::data::ImpulseStepper;
use super::law::Start;
use super::step::Step;

/// The two ways of stepping the impulse.
#[derive(Clone, Copy, Debug)]
pub(crate) enum ImpulseScheme {
    /// [`crate::impact::StepControl::Fixed`].
    Fixed { impulse_step: f64 },
    /// [`crate::impact::StepControl::AdaptiveImpulse`].
    Adaptive { tolerance: f64 },
}

/// Landing fractions at or below this are not worth a step of their own.
pub(super) const MIN_LANDING: f64 = 1e-9;

impl ImpulseStepper {
    /// Resolves one validated impact into `out` with a fixed or an adaptive
    /// impulse step. Errors: the step limit or a non-finite state.
    pub(crate) fn solve_into(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        scheme: ImpulseScheme,
        settings: &ImpactSettings,
        out: &mut ImpactOutcome,
    ) -> Result<(), ImpactError> {
        self.load(bodies, contacts);
        self.elapsed = 0.0;
        self.e0_hold = settings.e0_hold;
        self.rest_speed = settings.rest_speed;
        out.kinetic_energy_before = bodies.iter().map(Body::kinetic_energy).sum();
        out.steps = 0;
        out.rejected_steps = 0;

        let reason = if self.scales.velocity == 0.0 {
            StopReason::NoApproach
        } else {
            match scheme {
                ImpulseScheme::Fixed { impulse_step } => {
                    self.adaptive = false;
                    let h = impulse_step * self.scales.impulse;
                    self.landing_impulse = MIN_LANDING * h;
                    self.run_fixed(h, settings.max_steps, out)?
                }
                ImpulseScheme::Adaptive { tolerance } => {
                    self.adaptive = true;
                    self.landing_impulse = MIN_LANDING * 1e-4 * self.scales.impulse;
                    self.run_adaptive(tolerance, settings.max_steps, out)?
                }
            }
        };
        self.finish(bodies, reason, out);
        Ok(())
    }

    /// The paper's scheme: steps of primary impulse `h` until the impact ends.
    pub(super) fn run_fixed(
        &mut self,
        h: f64,
        max_steps: usize,
        out: &mut ImpactOutcome,
    ) -> Result<StopReason, ImpactError> {
        loop {
            if self.at_rest() {
                return Ok(StopReason::AtRest);
            }
            match self.step(h) {
                Step::Done => return Ok(StopReason::Released),
                Step::Advanced { .. } => {
                    out.steps += 1;
                    if out.steps >= max_steps {
                        return Err(ImpactError::StepLimit { steps: out.steps });
                    }
                    self.check_finite(out.steps)?;
                }
            }
        }
    }

    /// Adaptive mode: the paper's scheme with the impulse step chosen per
    /// step (see the file docs); a step whose estimate exceeds `tolerance`
    /// is taken again shorter. Between events a lone loaded contact has
    /// constant ratios and no error, so its steps grow until they land on
    /// the events.
    pub(super) fn run_adaptive(
        &mut self,
        tolerance: f64,
        max_steps: usize,
        out: &mut ImpactOutcome,
    ) -> Result<StopReason, ImpactError> {
        let p0 = self.scales.impulse;
        // The Euler error is second order in h: its square root sets the
        // first step.
        let mut h = p0 * (0.1 * tolerance.sqrt()).clamp(1e-8, 1e-2);
        let h_min = p0 * 1e-15;
        let mut attempts = 0usize;
        loop {
            if self.at_rest() {
                return Ok(StopReason::AtRest);
            }
            attempts += 1;
            if attempts > max_steps {
                return Err(ImpactError::StepLimit { steps: out.steps });
            }
            self.saved_velocity.copy_from_slice(&self.velocity);
            self.saved_state.copy_from_slice(&self.state);
            let elapsed = self.elapsed;
            let length = match self.step(h) {
                Step::Done => return Ok(StopReason::Released),
                Step::Advanced { length } => length,
            };
            // the step's error estimate over the tolerance: ≤ 1 is accepted
            let error = self.step_error / tolerance;
            if error > 1.0 && h > h_min {
                self.velocity.copy_from_slice(&self.saved_velocity);
                self.state.copy_from_slice(&self.saved_state);
                self.elapsed = elapsed;
                out.rejected_steps += 1;
                h = (h * (0.9 / error.sqrt()).clamp(0.1, 0.9)).max(h_min);
                continue;
            }
            out.steps += 1;
            self.check_finite(out.steps)?;
            h = next_step(h, length, error, (h_min, p0));
        }
    }

    /// Every 4096th step: a non-finite velocity or energy is an error.
    fn check_finite(&self, steps: usize) -> Result<(), ImpactError> {
        if !steps.is_multiple_of(4096) {
            return Ok(());
        }
        let finite = self.velocity.iter().flatten().all(|x| x.is_finite())
            && self.state.iter().all(|s| s.energy.is_finite());
        if finite {
            Ok(())
        } else {
            Err(ImpactError::NonFinite { steps })
        }
    }

    /// The ratio error of a full step (see the file docs): the increments
    /// taken are the scratch's `increment` times `scale`; the explicit-Euler
    /// ones are distributed with the start energies (primary force
    /// `start_force`, N).
    pub(super) fn ratio_error(
        &mut self,
        h: f64,
        scale: f64,
        start_force: f64,
        threshold: f64,
    ) -> f64 {
        if start_force <= 0.0 {
            return 0.0;
        }
        let start = Start {
            threshold,
            time_exact: true,
        };
        let mut largest = 0.0f64;
        for (row, (s, x)) in self
            .rows
            .iter()
            .zip(self.state.iter().zip(&mut self.scratch))
        {
            // a contact still loaded here holds its start energy (landings
            // only release), whose force the predictor kept
            let ratio_force = if s.energy > 0.0 { x.start_force } else { 0.0 };
            let inc = row.increment(s, x.rate, ratio_force, (h, start_force), start);
            x.euler_increment = inc;
            largest = largest.max(inc);
        }
        let start_scale = if largest > h { h / largest } else { 1.0 };
        let mut worst = 0.0f64;
        for (row, x) in self.rows.iter().zip(&self.scratch) {
            let euler = start_scale * x.euler_increment;
            let diff = (x.increment * scale - euler).abs() * row.w_nn;
            worst = worst.max(diff);
        }
        worst / self.scales.velocity
    }

    /// The friction error (see the file docs) joins `step_error`.
    pub(super) fn friction_error(&mut self) {
        for (row, (s, x)) in self.rows.iter().zip(self.state.iter().zip(&self.scratch)) {
            let inc = x.increment + x.held_step;
            if x.stuck_at_start && !s.sticking && inc > 0.0 && row.has_friction() {
                let misplaced = row.stick_friction.max(row.friction) * inc * row.w_tt;
                self.step_error = self.step_error.max(misplaced / self.scales.velocity);
            }
        }
    }
}

/// The adaptive step after an accepted one of `h` that took `length` (N·s)
/// with `error` (over the tolerance). A step cut short by a landing grows
/// from what it took (at least a tenth of h): long steps that keep landing
/// early resolve nothing (an e = 0 contact pushed again after its
/// compression ended reloads in cycles that long steps cut into many tiny
/// ones). No step beyond the impact's impulse scale P₀.
fn next_step(h: f64, length: f64, error: f64, (h_min, p0): (f64, f64)) -> f64 {
    let grow = if error > 0.0 {
        (0.9 / error.sqrt()).clamp(0.2, 5.0)
    } else {
        5.0
    };
    let base = if length < h { length.max(0.1 * h) } else { h };
    (base * grow).clamp(h_min, p0)
}

impl ImpulseStepper {
    /// Whether a rest speed is set and every contact approaches slower than
    /// it and stores too little energy to rebound faster: √(2 e² E W_nn)
    /// below it, e² E being what the contact gives back (energy.rs).
    fn at_rest(&self) -> bool {
        let rest = self.rest_speed;
        rest > 0.0
            && self.rows.iter().zip(&self.state).all(|(row, s)| {
                !row.movable
                    || (-row.normal_rate(&self.velocity) <= rest
                        && (s.held
                            || 2.0 * row.restitution * row.restitution * s.energy * row.w_nn
                                <= rest * rest))
            })
    }
}
