//! Stage 3: one improved-Euler step in the primary's impulse (paper Sec. 3.1
//! does the same in time): a half step with the start energies predicts the
//! mid-step energies, whose ratios F_i/F_p distribute the full step
//! (docs/model.md §1–3), which then lands on its first switch. Second order
//! in h. The explicit step both halves share runs steps 1–7 of the module
//! docs in order, each in its own stage file.

use super::data::ImpulseStepper;

/// The two halves of an improved-Euler step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Stage {
    /// Half step distributed by the start energies, not landed.
    Predictor,
    /// Full step distributed by the mid-step energies, landed.
    Corrector,
}

/// Result of one step attempt.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Step {
    /// Nothing is loaded and nothing closed approaches: the impact is over.
    Done,
    /// Advanced; `length` is the step actually taken in the units of h.
    Advanced { length: f64 },
}

impl ImpulseStepper {
    /// One step of length `h` (N·s): the improved-Euler scheme in the impulse
    /// variable. A half Euler step predicts the stored energies at mid-step;
    /// the full step then distributes its impulse by the ratios F_i/F_p of those
    /// mid-step energies and lands on the first switch inside it.
    pub(super) fn step(&mut self, h: f64) -> Step {
        self.mid_velocity.copy_from_slice(&self.velocity);
        self.mid_state.copy_from_slice(&self.state);
        let elapsed = self.elapsed;
        if self.euler_step(0.5 * h, Stage::Predictor) == Step::Done {
            return Step::Done;
        }
        self.elapsed = elapsed;
        for (x, s) in self.scratch.iter_mut().zip(&self.state) {
            x.mid_energy = s.energy;
        }
        self.velocity.copy_from_slice(&self.mid_velocity);
        self.state.copy_from_slice(&self.mid_state);
        self.euler_step(h, Stage::Corrector)
    }

    /// One explicit step of length at most `h` (N·s); see the module doc.
    /// The predictor distributes by the start energies and takes the whole
    /// step; the corrector distributes by the mid-step energies (where
    /// positive) and lands on the first switch.
    fn euler_step(&mut self, h: f64, stage: Stage) -> Step {
        let threshold = self.scales.threshold;
        // 1. rates; 2. primary (law.rs).
        let Some(primary) = self.primary(h, stage) else {
            return Step::Done;
        };
        // 3.–5., until no switch is due at once.
        let length = loop {
            // 3. increments, scaled so that no contact takes more than h.
            let scale = self.distribute(h, primary, stage);
            if stage == Stage::Corrector && self.adaptive {
                self.step_error = self.ratio_error(h, scale, primary.start_force, threshold);
            }
            self.trial_impulses(scale);
            if stage == Stage::Predictor {
                break 1.0;
            }
            // 5. landing on the first switch inside the step: every impulse
            // of the step scales with its length σ, so v(σ) is linear. A
            // switch within a negligible impulse happens at once — a contact
            // with too little energy left releases it (dissipated, without
            // impulse), a closing gap closes — and the step is distributed
            // again.
            let step_time = self.scratch[primary.index].increment / primary.force;
            let (length, switched_now) = self.landing(h, step_time);
            if !switched_now {
                break length;
            }
            self.switch_marked();
        };
        self.commit(length);
        if stage == Stage::Corrector && self.adaptive {
            self.friction_error();
        }
        // 6. energies with the mid-step rate; 7. impact time and gaps (the
        // predictor keeps only its energies, so it skips them).
        let primary_energy_before = self.state[primary.index].energy;
        let primary_energy_raw = self.update_energies(primary.index, threshold);
        if stage == Stage::Corrector {
            let (dt, moment) =
                self.impact_time(primary.index, primary_energy_before, primary_energy_raw);
            self.elapsed += dt;
            self.update_gaps(dt, moment, threshold);
        }
        Step::Advanced { length: length * h }
    }

    /// Step 4: the whole step's impulses on the trial velocities: the normal
    /// increments, scaled by `scale`, then the held contacts and Coulomb
    /// friction (friction.rs).
    fn trial_impulses(&mut self, scale: f64) {
        for x in &mut self.scratch {
            x.increment *= scale;
        }
        self.trial.copy_from_slice(&self.velocity);
        for (row, x) in self.rows.iter().zip(&self.scratch) {
            if x.increment > 0.0 {
                row.apply(
                    row.normal_axis(),
                    x.increment,
                    &self.body_slots,
                    &mut self.trial,
                );
            }
        }
        self.held_and_friction();
    }

    /// Takes the fraction `length` of the trial step: velocities, normal,
    /// held and tangential increments.
    fn commit(&mut self, length: f64) {
        for (v, t) in self.velocity.iter_mut().zip(&self.trial) {
            for k in 0..3 {
                v[k] += length * (t[k] - v[k]);
            }
        }
        for (x, s) in self.scratch.iter_mut().zip(&mut self.state) {
            x.increment *= length;
            x.held_step *= length;
            x.tangent_step *= length;
            s.tangent_impulse += x.tangent_step;
            s.normal_impulse += x.held_step;
        }
    }
}
