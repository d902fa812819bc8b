//! Stage 6: the stored energies after a step, the step's impact time and the
//! gaps — steps 6–7 of the module docs.
//!
//! Equations: dE = −δ̇ dP in compression and dE = −δ̇ dP / e² in expansion
//! with the mid-step rate δ̇ = (δ̇₀ + δ̇₁)/2 (docs/model.md §2, paper Eqs.
//! 22–23); e = 0 releases at once; E ≥ 0, and an expanding contact never
//! takes more impulse than its energy pays for. The impact time
//! dt = ∫ dP_p / F_p(E_p) (the contact law, docs/model.md §1 and §7) and the
//! gaps g += ∫ δ̇ dt of the contacts without energy.

use super::data::{
    warped_nodes, BodySlot, ContactState, ImpulseStepper, NodeWarp, Row, Scratch, GAUSS_4,
};

impl ImpulseStepper {
    /// Step 6: stored energies with the mid-step rate (see the file docs);
    /// the scratch's `rate_change` receives the end rates. Returns the
    /// primary's energy before clamping at 0 (for the impact time).
    pub(super) fn update_energies(&mut self, primary: usize, threshold: f64) -> f64 {
        let mut primary_energy_raw = self.state[primary].energy;
        for (i, (row, (s, x))) in self
            .rows
            .iter()
            .zip(self.state.iter_mut().zip(&mut self.scratch))
            .enumerate()
        {
            if !row.movable {
                continue;
            }
            let raw = spend(row, (s, x), &self.body_slots, &mut self.velocity, threshold);
            if let (Some(raw), true) = (raw, i == primary) {
                primary_energy_raw = raw;
            }
        }
        primary_energy_raw
    }

    /// Impact time of the step, dt = ∫ dP_p / F_p(E_p), and its first
    /// moment ∫ σ dt over the step's fraction σ ∈ [0, 1] (s).
    ///
    /// The fixed step takes E_p linear in P_p over the step (exact at the
    /// singular start E_p = 0; its steps are short). The adaptive step's can
    /// be long: there E_p(σ) = E₀ − dP_p (δ̇₀ σ + Δ σ²/2)/η is quadratic (δ̇
    /// is linear in σ, η = 1 in compression, e² in expansion) and the
    /// integral is taken by Gauss–Legendre quadrature on each half of the
    /// step, with σ = s^k (k = 1/(1 − α/(α+1)) = α+1) near an end where
    /// E_p = 0, which makes the integrable singularity E^(−α/(α+1)) smooth.
    pub(super) fn impact_time(&self, primary: usize, e0: f64, e1_raw: f64) -> (f64, f64) {
        let row = &self.rows[primary];
        let x = &self.scratch[primary];
        let inc = x.increment;
        if inc == 0.0 {
            return (0.0, 0.0);
        }
        if !self.adaptive {
            return linear_time(row, inc, e0, e1_raw);
        }
        // E(σ) = e0 + a σ + b σ², through E(1) = e1_raw with the mid-step
        // rate's energy change split by the start and end rates
        let (r0, r1) = (x.rate, x.rate_change);
        let eta = if e1_raw >= e0 || row.restitution == 0.0 {
            1.0
        } else {
            row.restitution * row.restitution
        };
        let quadratic = (e0, -inc * r0 / eta, -inc * 0.5 * (r1 - r0) / eta);
        let k = 1.0 / (1.0 - row.power);
        let warp = if k == self.warp.0 {
            self.warp.1
        } else {
            warped_nodes(k)
        };
        let (t0, t1) = quadrature(row, quadratic, e1_raw.max(0.0), &warp);
        (inc * t0, inc * t1)
    }

    /// Step 7: the gaps of the contacts that carry no energy advance by
    /// ∫ δ̇ dt = δ̇₀ dt + Δ ∫ σ dt (δ̇ linear in σ, `moment` = ∫ σ dt); a held
    /// contact that nothing holds any more and that separates is released.
    pub(super) fn update_gaps(&mut self, dt: f64, moment: f64, threshold: f64) {
        for (row, (s, x)) in self
            .rows
            .iter()
            .zip(self.state.iter_mut().zip(&self.scratch))
        {
            if s.held && x.held_step == 0.0 && x.rate_change > threshold {
                // nothing holds it any more and it separates
                s.held = false;
            }
            if row.movable && !s.held && x.increment == 0.0 && s.energy == 0.0 && dt.is_finite() {
                let change = x.rate_change - x.rate;
                let moved = x.rate * dt + change * moment;
                if self.adaptive && s.gap > 0.0 && s.gap + moved < 0.0 {
                    // The landing on this gap's closing, which takes the
                    // step's time as uniform in σ, came late: the fraction
                    // of the step the contact spent closed but without
                    // force joins the error estimate (adaptive mode).
                    let late = -(s.gap + moved) / moved.abs();
                    self.step_error = self.step_error.max(late);
                }
                s.gap += moved;
                // closed when what is left is rounding of the landing
                if s.gap <= 1e-9 * moved.abs() {
                    s.gap = 0.0;
                }
            }
        }
    }
}

/// One movable contact's energy after the step's normal increment (see the
/// file docs); `x.rate_change` receives its end rate. Returns its energy
/// before clamping at 0 if it took an increment.
#[inline]
fn spend(
    row: &Row,
    (s, x): (&mut ContactState, &mut Scratch),
    slots: &[BodySlot],
    velocity: &mut [[f64; 3]],
    threshold: f64,
) -> Option<f64> {
    let end = row.normal_rate(velocity);
    let inc = x.increment;
    if inc <= 0.0 {
        x.rate_change = end;
        return None;
    }
    let mid = 0.5 * (x.rate + end);
    // In expansion the impulse's work comes out of the stored energy, e² E
    // at most. Friction coupled into the normal can open a contact after
    // the landing test: cut the increment just enough that the mid-step rate
    // is what the energy pays for (zero for e = 0); the contact leaves the
    // step opening. The contact has then spent its energy (what is left of it
    // is dissipated, never created).
    let payable = row.restitution * row.restitution * s.energy;
    if mid > threshold && mid * inc > payable {
        let target = payable / inc;
        let cut = (2.0 * (mid - target) / row.w_nn).clamp(0.0, inc);
        row.apply(row.normal_axis(), -cut, slots, velocity);
        x.increment = inc - cut;
        s.normal_impulse += inc - cut;
        s.energy = 0.0;
        x.rate_change = row.normal_rate(velocity);
        return Some(0.0);
    }
    s.normal_impulse += inc;
    if mid <= threshold {
        // compression (or the neutral rounding band)
        s.energy -= mid * inc;
    } else if row.restitution > 0.0 {
        s.energy -= mid * inc / (row.restitution * row.restitution);
    } else {
        s.energy = 0.0;
    }
    let raw = s.energy;
    s.energy = s.energy.max(0.0);
    s.peak_energy = s.peak_energy.max(s.energy);
    x.rate_change = row.normal_rate(velocity);
    Some(raw)
}

/// The fixed step's impact time, E_p linear in P_p over the step: dt and
/// its first moment, taken as dt/2 (s).
fn linear_time(row: &Row, inc: f64, e0: f64, e1_raw: f64) -> (f64, f64) {
    let e1 = e1_raw.max(0.0);
    let slope = (e1_raw - e0) / inc;
    let rise = 1.0 - row.power;
    let dt = if (slope * inc).abs() <= 1e-12 * e0.max(e1) {
        inc / row.force(e0.max(e1))
    } else {
        // until E_p reaches zero if it runs out inside the step
        (e1.powf(rise) - e0.powf(rise)) / (row.force_coeff * rise * slope)
    };
    (dt, 0.5 * dt)
}

/// ∫₀¹ dσ / F(E(σ)) and ∫₀¹ σ dσ / F(E(σ)) (1/N) for E(σ) = e0 + a σ + b σ²
/// (`(e0, a, b)`, J) clamped at 0, by 4-point Gauss–Legendre on each half,
/// warped by `warp` at an end where E = 0 (`e1` = E(1) clamped).
fn quadrature(row: &Row, (e0, a, b): (f64, f64, f64), e1: f64, warp: &[NodeWarp; 4]) -> (f64, f64) {
    let energy = |sigma: f64| (e0 + sigma * (a + sigma * b)).max(0.0);
    let (mut t0, mut t1) = (0.0, 0.0);
    for ((node, weight), &(node_k, slope_k)) in GAUSS_4.into_iter().zip(warp) {
        // first half, σ = ½ s^k if E vanishes at 0, else σ = ½ s
        let (sigma, jac) = if e0 <= 0.0 {
            (0.5 * node_k, 0.5 * slope_k)
        } else {
            (0.5 * node, 0.5)
        };
        let f = row.force(energy(sigma));
        if f > 0.0 {
            t0 += weight * jac / f;
            t1 += weight * jac * sigma / f;
        }
        // second half, from the end
        let (sigma, jac) = if e1 <= 0.0 {
            (1.0 - 0.5 * node_k, 0.5 * slope_k)
        } else {
            (1.0 - 0.5 * node, 0.5)
        };
        let f = row.force(energy(sigma));
        if f > 0.0 {
            t0 += weight * jac / f;
            t1 += weight * jac * sigma / f;
        }
    }
    (t0, t1)
}
