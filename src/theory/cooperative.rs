//! The group models: cooperative (μ = 0, Stronge & Shu 1988, van Leeuwen 2010)
//! and extended (friction μ between blocks, van Leeuwen 2010; Fujii et al.).
//! One implementation with μ as a parameter; formulas from docs/theory.md,
//! "Cooperative group" (train sums in [`super::train`]).
//!
//! ## Between collisions
//! Weighting each block's angular momentum equation by ρ_k removes the contact
//! forces:
//! `θ̈_0 = [Σ ρ_k τ_k / I − θ̇_0² Σ ρ_k c'_k] / Σ ρ_k c_k`.
//! With `u = θ̇_0²` and `du/dθ_0 = 2 θ̈_0` this is linear in u:
//! `u' = a(θ) − b(θ) u`, `a = 2 Σρτ / (I Σρc)`, `b = 2 Σρc' / Σρc`, so
//! `u(θ) = e^{−Φ(θ)} (u_0 + Ψ(θ))` with `Φ = ∫_0^θ b` and `Ψ = ∫_0^θ a e^Φ`.
//!
//! ## Collision
//! Fully inelastic, the old train keeps leaning on the new leader:
//! `ω_new = r ω_old`, `r = (J − 1)/J`,
//! `J − 1 = [(cos θ_c − μ d)/(cos θ_c + μ sin θ_c)] Σ ρ_j c_j` (old train at θ_c),
//! which is `K/(K + 1)`, `K = Σ c_j²`, for μ = 0.
//!
//! ## Fixed point (closed form)
//! One cycle maps u_0 to `r² e^{−Φ(θ_c)} (u_0 + Ψ(θ_c))`, an affine map
//! `u_0 ↦ q (u_0 + Ψ_c)` with `q = r² e^{−Φ_c}`, so
//! `u_0* = q Ψ_c / (1 − q)`. There is a wave when `q < 1`, `Ψ_c > 0` and
//! `u_0* + Ψ(θ) > 0` on `[0, θ_c]` (else the leader stalls). The period is
//! `T = ∫_0^θc dθ / √u` and the natural speed `v/√(gh) = (λ/h)/(T/√(h/g))`.
//!
//! ## Accuracy (target 10⁻⁶ relative on v; achieved ~10⁻¹⁰)
//! - train: summed to relative 10⁻¹⁴ per term (see [`super::train`]; typically
//!   50–300 blocks);
//! - a(θ), b(θ) are sampled at n + 1 Chebyshev–Lobatto points on [0, θ_c] and
//!   Φ, Ψ are the exact integrals of their interpolants (spectral accuracy);
//!   n doubles from 8 (reusing the samples) until two successive natural speeds
//!   agree to `SPEED_TOLERANCE` = 10⁻¹⁰ relative, at most n = 512;
//! - T is a Clenshaw–Curtis integral of 1/√u, split at the minimum of u and
//!   stretched there by a sinh map (see `period.rs`), doubled until converged
//!   to 10⁻¹²;
//! - the fixed point is exact (closed form), no iteration.

use super::chebyshev::{self, Series};
use super::outcome::{NoWave, Outcome, TheoryError, Wave};
use super::period::{first_zero, golden_min, peak_integral};
use super::train::train_sums;
use super::Geometry;

/// Relative agreement of two successive natural speeds that ends the refinement.
pub(crate) const SPEED_TOLERANCE: f64 = 1e-10;
/// Largest Chebyshev degree tried.
pub(crate) const MAX_NODES: usize = 512;

/// Solves the group model with friction `mu` between blocks (μ = 0: cooperative).
pub(crate) fn solve_group(geom: &Geometry, mu: f64) -> Result<Outcome, TheoryError> {
    let Some(theta_c) = geom.collision_angle() else {
        return Ok(Outcome::NoWave(NoWave::NoCollision));
    };
    let theta_inf = geom.rest_angle();
    if theta_c >= theta_inf {
        return Ok(Outcome::NoWave(NoWave::CollisionPastRest));
    }
    let d = geom.thickness_ratio();
    let (sin_c, cos_c) = theta_c.sin_cos();
    let alpha_c = cos_c - mu * d;
    let beta_c = cos_c + mu * sin_c;
    if alpha_c <= 0.0 {
        return Ok(Outcome::NoWave(NoWave::FrictionBlocksImpact));
    }
    // Far down the train Δ_k → 0 and ρ_{k+1}/ρ_k → 1 − λ sin θ_∞ − μ d; the
    // weighted sums exist only if that ratio is below 1 in size.
    let far_ratio = 1.0 - geom.pitch() * theta_inf.sin() - mu * d;
    if far_ratio.abs() >= 0.999 {
        return Err(TheoryError::OutsideModel(format!(
            "the friction weights of the leaning train do not decay (rho_(k+1)/rho_k -> {far_ratio:.4} \
             at the rest angle): the group model needs |1 - (lambda/h) sin theta_inf - mu d/h| < 1"
        )));
    }
    let inertia = geom.pivot_inertia();

    // Samples (a_j, b_j) at the Chebyshev–Lobatto points of degree n.
    let sample = |theta: f64, blocks: &mut usize| -> Result<(f64, f64, f64), TheoryError> {
        let s = train_sums(geom, mu, theta)?;
        *blocks = (*blocks).max(s.blocks);
        if s.rho_c <= 0.0 {
            return Err(TheoryError::OutsideModel(format!(
                "the weighted train inertia sum rho_k c_k = {} is not positive at theta_0 = {theta} \
                 with friction mu = {mu}",
                s.rho_c
            )));
        }
        Ok((
            2.0 * s.rho_tau / (inertia * s.rho_c),
            2.0 * s.rho_dc / s.rho_c,
            s.rho_c,
        ))
    };

    let mut blocks = 0;
    let mut n = 8;
    let mut samples = Vec::with_capacity(n + 1);
    for t in chebyshev::points(0.0, theta_c, n) {
        samples.push(sample(t, &mut blocks)?);
    }
    // Σρc of the old train at θ_c is the sample at j = 0 (θ = θ_c).
    let rho_c_at_collision = samples[0].2;
    let r = rho_c_at_collision / (rho_c_at_collision + beta_c / alpha_c);

    let mut last: Option<Outcome> = None;
    loop {
        // A coarse interpolant may put a spurious near-stall in the period
        // integral; that is refined like any other disagreement.
        let outcome = match cycle(geom, theta_c, theta_inf, r, &samples, blocks, n) {
            Ok(o) => Some(o),
            Err(TheoryError::NotConverged(_)) if n < MAX_NODES => None,
            Err(e) => return Err(e),
        };
        if let (Some(prev), Some(outcome)) = (&last, &outcome) {
            let agree = match (prev, outcome) {
                (Outcome::Wave(a), Outcome::Wave(b)) => {
                    (a.natural_speed - b.natural_speed).abs() <= SPEED_TOLERANCE * b.natural_speed
                }
                (Outcome::NoWave(_), Outcome::NoWave(_)) => true,
                _ => false,
            };
            if agree {
                return Ok(outcome.clone());
            }
        }
        if n >= MAX_NODES {
            return Err(TheoryError::NotConverged(format!(
                "natural speed not converged to {SPEED_TOLERANCE:e} with {n} Chebyshev points \
                 (d/h = {d}, s/h = {}, mu = {mu})",
                geom.spacing_ratio()
            )));
        }
        last = outcome;
        let finer = chebyshev::points(0.0, theta_c, 2 * n);
        let mut next = Vec::with_capacity(2 * n + 1);
        for (j, t) in finer.iter().enumerate() {
            next.push(if j % 2 == 0 {
                samples[j / 2]
            } else {
                sample(*t, &mut blocks)?
            });
        }
        samples = next;
        n *= 2;
    }
}

/// One evaluation of the fixed point and the period from samples of degree `n`.
fn cycle(
    geom: &Geometry,
    theta_c: f64,
    theta_inf: f64,
    r: f64,
    samples: &[(f64, f64, f64)],
    blocks: usize,
    n: usize,
) -> Result<Outcome, TheoryError> {
    let thetas = chebyshev::points(0.0, theta_c, n);
    let b: Vec<f64> = samples.iter().map(|s| s.1).collect();
    let phi = Series::interpolate(0.0, theta_c, &b).integral();
    let a_e_phi: Vec<f64> = samples
        .iter()
        .zip(&thetas)
        .map(|(s, t)| s.0 * phi.eval(*t).exp())
        .collect();
    let psi = Series::interpolate(0.0, theta_c, &a_e_phi).integral();
    let phi_c = phi.eval(theta_c);
    let psi_c = psi.eval(theta_c);
    let q = r * r * (-phi_c).exp();
    if psi_c <= 0.0 || q >= 1.0 {
        return Ok(Outcome::NoWave(NoWave::NoEnergyGain));
    }
    let u0 = q * psi_c / (1.0 - q);

    // Minimum of u0 + Ψ on [0, θ_c]: at an end, or where Ψ' = a e^Φ (known at
    // the points, which run down from θ_c) turns from negative to positive;
    // each such interval is searched by golden section.
    let (mut theta_min, mut psi_min) = if psi_c < 0.0 {
        (theta_c, psi_c)
    } else {
        (0.0, 0.0)
    };
    for j in 0..n {
        let (lo, hi) = (thetas[j + 1], thetas[j]);
        if a_e_phi[j + 1] <= 0.0 && a_e_phi[j] >= 0.0 {
            let (t, v) = golden_min(|t| psi.eval(t), lo, hi);
            if v < psi_min {
                (theta_min, psi_min) = (t, v);
            }
        }
    }
    if u0 + psi_min <= 0.0 {
        let angle = first_zero(|t| u0 + psi.eval(t), 0.0, theta_min, 8 * n);
        return Ok(Outcome::NoWave(NoWave::LeaderStalls { angle }));
    }
    let integrand = |t: f64| (0.5 * phi.eval(t)).exp() / (u0 + psi.eval(t)).sqrt();
    // rounding error of u0 + Ψ: that of the Chebyshev sum, ~10⁻¹⁴ of its size
    let noise = 1e-14 * (u0 + psi_c.abs() + psi_min.abs());
    let period = peak_integral(
        integrand,
        |t| u0 + psi.eval(t),
        noise,
        0.0,
        theta_min,
        theta_c,
    )?;
    let u_c = (-phi_c).exp() * (u0 + psi_c);
    Ok(Outcome::Wave(Wave {
        natural_speed: geom.pitch() / period,
        omega_after: u0.sqrt(),
        omega_before: u_c.sqrt(),
        period,
        theta_c,
        theta_inf,
        train_blocks: blocks,
        nodes: n,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The c'_k recursion against a finite difference of Σ c_k²/2 (μ = 0: Σ c c').
    #[test]
    fn train_derivative_matches_finite_difference() {
        let geom = Geometry::new(0.15, 0.35).unwrap();
        let k2 = |t: f64| {
            // Σ c_k² by the plain recursion, independent of train_sums
            let (mut th, mut c, mut sum) = (t, 1.0_f64, 0.0);
            for _ in 0..2000 {
                sum += c * c;
                let x = geom.pitch() * th.cos() - geom.thickness_ratio();
                c *= 1.0 - geom.pitch() * th.sin() / (1.0 - x * x).sqrt();
                th += x.asin();
            }
            sum
        };
        for &t in &[0.0, 0.1, 0.3] {
            let h = 1e-5;
            let fd = (k2(t + h) - k2(t - h)) / (4.0 * h);
            let s = train_sums(&geom, 0.0, t).unwrap();
            assert!(
                (s.rho_dc - fd).abs() < 1e-7 * fd.abs().max(1.0),
                "{} vs {fd}",
                s.rho_dc
            );
            assert!((s.rho_c - k2(t)).abs() < 1e-12 * k2(t));
        }
    }
}
