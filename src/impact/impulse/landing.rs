//! Stage 5: the events of the law inside a step — step 5 of the module docs
//! — and free flight to the first closing gap.
//!
//! Every impulse of a step scales with its length σ ∈ (0, 1], so the rates
//! are linear in σ: δ̇(σ) = δ̇₀ + σ Δ. The step is cut back to the first of
//!
//! | event | condition | σ |
//! | --- | --- | --- |
//! | compression ends | δ̇ rises through 0 | −δ̇₀ / Δ |
//! | the energy runs out in expansion | σ dP (δ̇₀ + σ Δ/2) / e² = E (docs/model.md §2) | smallest root in (0, 1] |
//! | a resting closed contact approaches | δ̇ falls below −threshold | (δ̇₀ + 2 threshold) / −Δ |
//! | an open gap closes | g + dt (δ̇₀ σ + Δ σ²/2) = 0, dt the step's time | smallest root in (0, 1] |
//! | a sliding contact's slip stops | v_t changes sign | v_t₀ / (v_t₀ − v_t₁) |
//!
//! An event within [`MIN_LANDING`] of the step's start (as an impulse,
//! `landing_impulse`) is not worth a step: a contact with that little energy
//! left releases it at once (dissipated, without impulse), a gap that close
//! closes at once, and the step is distributed again.
//!
//! [`MIN_LANDING`]: super::MIN_LANDING

use super::data::{ContactState, ImpulseStepper, Row, Scratch};

/// What one contact's events need besides its own data.
#[derive(Clone, Copy, Debug)]
struct Window {
    /// Rates above −threshold count as not approaching (m/s).
    threshold: f64,
    /// The step's impact time estimated at the primary's ratio energy (s).
    step_time: f64,
    /// Landing fractions at or below this happen at once.
    min_landing: f64,
}

impl ImpulseStepper {
    /// Step 5: the fraction σ ∈ (0, 1] of the step at which the first event
    /// happens (the scratch's `rate_change` receives the whole step's rate
    /// change), and whether some contact switches at once (marked `released`
    /// or `closing` in its scratch).
    pub(super) fn landing(&mut self, h: f64, step_time: f64) -> (f64, bool) {
        let window = Window {
            threshold: self.scales.threshold,
            step_time,
            min_landing: self.landing_impulse / h,
        };
        let mut length = 1.0f64;
        let mut switched_now = false;
        for (row, (s, x)) in self
            .rows
            .iter()
            .zip(self.state.iter().zip(&mut self.scratch))
        {
            if !row.movable {
                continue;
            }
            length = length.min(land_point(row, s, x, (&self.velocity, &self.trial), window));
            switched_now |= x.released || x.closing;
        }
        (length, switched_now)
    }

    /// Contacts marked `released` lose their energy; gaps marked `closing`
    /// close.
    pub(super) fn switch_marked(&mut self) {
        for (s, x) in self.state.iter_mut().zip(&mut self.scratch) {
            if x.released {
                x.released = false;
                s.energy = 0.0;
            }
            if x.closing {
                x.closing = false;
                s.gap = 0.0;
            }
        }
    }

    /// When nothing is loaded and no closed contact approaches, but open gaps
    /// do: advances every gap by δ̇·t for the free-flight time t until the first
    /// one closes (velocities do not change) and returns that contact. The gaps
    /// are microscopic (positions are frozen), so this is the same impact.
    pub(super) fn free_flight(&mut self) -> Option<usize> {
        let threshold = self.scales.threshold;
        let mut first = None;
        let mut shortest = f64::INFINITY;
        for (i, (row, (s, x))) in self
            .rows
            .iter()
            .zip(self.state.iter().zip(&self.scratch))
            .enumerate()
        {
            if row.movable && s.gap > 0.0 && x.rate < -threshold {
                let t = s.gap / -x.rate;
                if t < shortest {
                    shortest = t;
                    first = Some(i);
                }
            }
        }
        let first = first?;
        for (row, (s, x)) in self
            .rows
            .iter()
            .zip(self.state.iter_mut().zip(&self.scratch))
        {
            if row.movable && s.energy == 0.0 {
                s.gap = (s.gap + x.rate * shortest).max(0.0);
            }
        }
        self.state[first].gap = 0.0;
        self.elapsed += shortest;
        Some(first)
    }
}

/// One contact's first event in the step (the table in the file docs), 1
/// when none; an event due at once is marked in `x` and not returned.
#[inline]
fn land_point(
    row: &Row,
    s: &ContactState,
    x: &mut Scratch,
    (velocity, trial): (&[[f64; 3]], &[[f64; 3]]),
    w: Window,
) -> f64 {
    let rate = x.rate;
    let change = row.normal_rate(trial) - rate;
    x.rate_change = change;
    let inc = x.increment + x.held_step;
    let at = if inc > 0.0 && rate < -w.threshold && rate + change > 0.0 {
        // compression ends
        -rate / change
    } else if x.increment > 0.0 && rate >= -w.threshold && s.energy > 0.0 {
        // expansion: release(σ) = σ inc (rate + σ change / 2) / e² reaches E
        let inc = x.increment;
        let e2 = row.restitution * row.restitution;
        let at = first_root(0.5 * inc * change, inc * rate, -e2 * s.energy);
        // Too little energy left to be worth a step: it is released
        // (dissipated) at once, without impulse.
        x.released = at.is_some_and(|at| at <= w.min_landing);
        at.unwrap_or(1.0)
    } else if inc == 0.0
        && s.energy == 0.0
        && s.gap == 0.0
        && !s.held
        && rate + change < -w.threshold
    {
        // a resting closed contact starts to approach: land just past the
        // threshold so that it joins in the next step
        ((rate + 2.0 * w.threshold) / -change).max(0.0)
    } else if inc == 0.0 && s.energy == 0.0 && s.gap > 0.0 {
        // an open gap closes: gap(σ) = g + dt (δ̇ σ + Δ σ²/2), with the
        // step's time estimated at the primary's ratio energy
        let at = first_root(-0.5 * change * w.step_time, -rate * w.step_time, -s.gap);
        x.closing = at.is_some_and(|at| at <= w.min_landing);
        at.unwrap_or(1.0)
    } else {
        1.0
    };
    let mut length = 1.0f64;
    if at > w.min_landing {
        length = length.min(at);
    }
    // a sliding contact's slip stops
    if inc > 0.0 && !x.stuck_at_start && !row.no_slip() && row.has_friction() {
        let slip0 = row.tangent_rate(velocity);
        let slip1 = row.tangent_rate(trial);
        if slip0 * slip1 < 0.0 {
            let at = slip0 / (slip0 - slip1);
            if at > w.min_landing {
                length = length.min(at);
            }
        }
    }
    length
}

/// The smallest root in (0, 1] of a σ² + b σ + c with c < 0, if the
/// quadratic has crossed zero by σ = 1 (a + b + c > 0).
#[inline]
fn first_root(a: f64, b: f64, c: f64) -> Option<f64> {
    (a + b + c > 0.0).then(|| smallest_positive_root(a, b, c))
}

/// Smallest root in (0, 1] of a σ² + b σ + c with c < 0 < a + b + c.
fn smallest_positive_root(a: f64, b: f64, c: f64) -> f64 {
    if a.abs() < 1e-14 * b.abs().max(1e-300) {
        return (-c / b).clamp(0.0, 1.0);
    }
    let disc = (b * b - 4.0 * a * c).max(0.0).sqrt();
    // Numerically stable pair of roots.
    let q = -0.5 * (b + b.signum() * disc);
    let (r1, r2) = (q / a, c / q);
    [r1, r2]
        .into_iter()
        .filter(|r| *r > 0.0 && *r <= 1.0)
        .fold(1.0, f64::min)
}
