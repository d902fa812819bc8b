//! Stage 2: the contact law and the distributing law — steps 1–3 of the
//! module docs.
//!
//! Equations: the force of a stored energy, F(E) = c E^(α/(α+1))
//! (docs/model.md §1, from F = k (−δ)^α, paper Eq. 25); the primary contact,
//! the one with the largest stored energy or, when none holds energy, the one
//! approaching fastest (docs/model.md §3); the increments
//! dP_i = h F_i(E_i)/F_p(E_p) of the loaded contacts (paper Eq. 27,
//! docs/model.md §1) and the start of a closed contact without energy that
//! approaches, dP_i = (h c_i / F_p)^(α+1) |δ̇_i|^α (docs/model.md §3, paper
//! Eq. 32 generalised); the e = 0 loss of energy when compression ends
//! (docs/model.md §2) and the held fallback of [`ImpactSettings::e0_hold`].
//!
//! [`ImpactSettings::e0_hold`]: super::super::ImpactSettings::e0_hold

use super::data::{ContactState, ImpulseStepper, Row};
use super::step::Stage;

/// The primary contact of a step and its force.
#[derive(Clone, Copy, Debug)]
pub(super) struct Primary {
    pub index: usize,
    /// F_p (N) used to distribute the step.
    pub force: f64,
    /// F_p (N) of the start energies (the explicit-Euler distribution).
    pub start_force: f64,
}

/// How a contact without energy starts: the approach threshold (m/s) and
/// whether the start is exact in time (the adaptive step) or takes the force
/// at the step's end (the fixed step).
#[derive(Clone, Copy, Debug)]
pub(super) struct Start {
    pub threshold: f64,
    pub time_exact: bool,
}

impl Row {
    /// F(E) = c E^(α/(α+1)) (N), 0 without stored energy (docs/model.md §1).
    #[inline]
    pub fn force(&self, stored_energy: f64) -> f64 {
        if stored_energy <= 0.0 {
            0.0
        } else {
            self.force_coeff * stored_energy.powf(self.power)
        }
    }

    /// Normal increment of this contact for a step of primary impulse `h`
    /// (N·s) whose primary pushes with `primary_force` (N): loaded contacts
    /// in the ratio F_i(E_i)/F_p (docs/model.md §1, F_i = `ratio_force`);
    /// approaching closed contacts without energy start as in the contact
    /// law, E_i ≈ |δ̇_i| dP_i. The fixed step uses docs/model.md §3,
    /// dP_i = (h c_i / F_p)^(α+1) |δ̇_i|^α, which takes the force at the
    /// step's end; the adaptive step, whose first steps can be long, the
    /// exact start at constant δ̇_i over the step's time h / F_p (F = k w^α
    /// with w = |δ̇_i| t integrates to dP_i = (h c_i / ((α+1) F_p))^(α+1)
    /// |δ̇_i|^α). Both agree as h → 0.
    #[inline]
    pub fn increment(
        &self,
        s: &ContactState,
        rate: f64,
        ratio_force: f64,
        (h, primary_force): (f64, f64),
        start: Start,
    ) -> f64 {
        if !self.movable {
            0.0
        } else if ratio_force > 0.0 {
            h * ratio_force / primary_force
        } else if s.gap == 0.0 && !s.held && rate < -start.threshold {
            let a1 = self.exponent + 1.0;
            let lead = if start.time_exact { 1.0 / a1 } else { 1.0 };
            (lead * h * self.force_coeff / primary_force).powf(a1) * (-rate).powf(self.exponent)
        } else {
            0.0
        }
    }
}

/// Who leads a step before the corrector's mid-step energies are known.
#[derive(Clone, Copy, Debug)]
enum Lead {
    /// The contact with the largest stored energy.
    Loaded(usize),
    /// No contact holds energy: the closed one approaching fastest, at `rate`.
    Starting { index: usize, rate: f64 },
}

/// The loaded contact with the largest energy and the closed one approaching
/// fastest, as a scan over the contacts finds them.
#[derive(Clone, Copy, Debug)]
struct Candidates {
    loaded: Option<usize>,
    largest_energy: f64,
    fastest: Option<usize>,
    fastest_rate: f64,
}

impl ImpulseStepper {
    /// Steps 1–2: the rates δ̇_i at the start of the step (an e = 0 contact
    /// whose compression has ended loses its energy, docs/model.md §2) and the
    /// primary contact: the one with the largest stored energy (in the
    /// corrector, the largest mid-step energy), or, when none holds energy,
    /// the one approaching fastest, whose force is then that of the energy
    /// |δ̇| h it stores over the step (docs/model.md §3). Flies freely to the first
    /// closing gap when only gaps approach; `None` when nothing approaches.
    pub(super) fn primary(&mut self, h: f64, stage: Stage) -> Option<Primary> {
        let found = self.scan_rates();
        let lead = match (found.loaded, found.fastest) {
            (Some(index), _) => Lead::Loaded(index),
            (None, Some(index)) => Lead::Starting {
                index,
                rate: found.fastest_rate,
            },
            (None, None) => {
                // Only open gaps approach: fly freely until the first one closes.
                let index = self.free_flight()?;
                Lead::Starting {
                    index,
                    rate: self.scratch[index].rate,
                }
            }
        };
        let start_force = match lead {
            Lead::Loaded(index) => self.rows[index].force(found.largest_energy),
            Lead::Starting { index, rate } => {
                // the primary starts too: its force at the step's end
                // (docs/model.md §3), or, in the adaptive step, its mean over
                // the step (see `Row::increment`)
                let row = &self.rows[index];
                let mean = if self.adaptive {
                    1.0 / (row.exponent + 1.0)
                } else {
                    1.0
                };
                mean * row.force(-rate * h)
            }
        };
        let mid = match stage {
            Stage::Corrector => self.largest_mid_energy(),
            Stage::Predictor => None,
        };
        let (index, force) = match (mid, lead) {
            (Some((index, energy)), _) => (index, self.rows[index].force(energy)),
            (None, Lead::Loaded(index) | Lead::Starting { index, .. }) => (index, start_force),
        };
        Some(Primary {
            index,
            force,
            start_force,
        })
    }

    /// The contact with the largest predicted mid-step energy, if any holds
    /// energy (the corrector's primary).
    fn largest_mid_energy(&self) -> Option<(usize, f64)> {
        let mut largest: Option<(usize, f64)> = None;
        for (i, (row, x)) in self.rows.iter().zip(&self.scratch).enumerate() {
            if x.mid_energy > largest.map_or(0.0, |l| l.1) && row.movable {
                largest = Some((i, x.mid_energy));
            }
        }
        largest
    }

    /// Step 1 over every contact: rates, the e = 0 loss of energy and the
    /// held fallback, and the candidates for the primary.
    fn scan_rates(&mut self) -> Candidates {
        let threshold = self.scales.threshold;
        let mut found = Candidates {
            loaded: None,
            largest_energy: 0.0,
            fastest: None,
            fastest_rate: -threshold,
        };
        for (i, (row, (s, x))) in self
            .rows
            .iter()
            .zip(self.state.iter_mut().zip(&mut self.scratch))
            .enumerate()
        {
            if !row.movable {
                continue;
            }
            let rate = row.normal_rate(&self.velocity);
            x.rate = rate;
            // e = 0: the energy is lost when compression ends (docs/model.md §2).
            // With `e0_hold`, a contact that does not separate then is held
            // closed (a plastic unilateral constraint, see ImpactSettings).
            if row.restitution == 0.0 && s.energy > 0.0 && rate >= -threshold {
                s.energy = 0.0;
                s.held = self.e0_hold && rate <= threshold;
            }
            if s.held && rate < -threshold {
                // approaching again with nothing holding it: a new impact
                s.held = false;
            }
            if s.energy > found.largest_energy {
                found.largest_energy = s.energy;
                found.loaded = Some(i);
            }
            if s.energy == 0.0 && s.gap == 0.0 && !s.held && rate < found.fastest_rate {
                found.fastest_rate = rate;
                found.fastest = Some(i);
            }
        }
        found
    }

    /// Step 3: every contact's normal increment for a primary step h, in
    /// the scratch; returns the factor (≤ 1) that keeps each below h.
    pub(super) fn distribute(&mut self, h: f64, primary: Primary, stage: Stage) -> f64 {
        let start = Start {
            threshold: self.scales.threshold,
            time_exact: self.adaptive,
        };
        let mut largest = 0.0f64;
        for (row, (s, x)) in self
            .rows
            .iter()
            .zip(self.state.iter().zip(&mut self.scratch))
        {
            let ratio_force = if stage == Stage::Corrector && x.mid_energy > 0.0 {
                row.force(x.mid_energy)
            } else {
                row.force(s.energy)
            };
            if stage == Stage::Predictor {
                x.start_force = ratio_force;
            }
            let inc = row.increment(s, x.rate, ratio_force, (h, primary.force), start);
            x.increment = inc;
            largest = largest.max(inc);
        }
        if largest > h {
            h / largest
        } else {
            1.0
        }
    }
}
