//! The leaning train behind the leader (docs/theory.md, "Cooperative group"):
//! the sums that the group model's equation of motion and collision law need,
//! at one leader angle θ_0.
//!
//! Block 0 is the leader at θ_0; block k+1 leans on block k, so
//! θ_{k+1} = θ_k + asin(λ cos θ_k − d) (lengths over h). With
//! `Δ_k = θ_{k+1} − θ_k` and `x_k = sin Δ_k = λ cos θ_k − d`:
//!
//! - velocity ratio `g_k = 1 − λ sin θ_k / cos Δ_k`, `c_0 = 1`, `c_{k+1} = g_k c_k`
//!   (so `ω_k = c_k ω_0`);
//! - its derivative along the motion, `c'_k = dc_k/dθ_0`:
//!   `c'_{k+1} = g'_k c_k + g_k c'_k`, where by the chain rule (∂θ_k/∂θ_0 = c_k)
//!   `g'_k = −λ [cos θ_k c_k / cos Δ_k + sin θ_k x_k (c_{k+1} − c_k) / cos² Δ_k]`;
//! - friction weights `ρ_0 = 1`, `ρ_{k+1} = ρ_k α_{k+1}/β_{k+1}` with
//!   `α_{k+1} = cos Δ_k − λ sin θ_k − μ d` and `β_{k+1} = cos Δ_k + μ sin Δ_k`.
//!
//! `α_{k+1}` is the lever arm about block k's pivot of the contact force of
//! block k+1 (normal force at height `cos Δ_k − λ sin θ_k` up block k's back
//! face, friction `μN` pulling that face down at lever arm `d`); `β_{k+1}` is the
//! lever arm of the same force about block k+1's pivot. The friction direction
//! is docs/theory.md's: the rear block's top edge slides down the front block's
//! face. That is what every pair does while the train falls as long as the
//! far velocity ratio `1 − λ sin θ_∞` is positive; beyond (s/h > 0.886 for
//! d/h = 0.12) the ratios g_k turn negative and some pairs further back slide
//! slowly the other way for part of the cycle, which the model (like
//! docs/theory.md) ignores.
//!
//! The train is summed until a block's terms are below `TRAIN_TOLERANCE` times
//! the running sums of magnitudes for two blocks in a row. The terms fall off
//! geometrically (ratio → `1 − λ sin θ_∞ − μd` as θ_k → θ_∞), so the neglected
//! tail is below ~`TRAIN_TOLERANCE/(1 − ratio)` relative: 10⁻¹² or better for
//! every ratio below 0.99. A train needing more than `MAX_TRAIN` blocks is an
//! error rather than a silent truncation.

use super::{Geometry, TheoryError};

/// Relative size of the last summed terms (see the module doc).
pub(crate) const TRAIN_TOLERANCE: f64 = 1e-14;
/// Upper bound on the number of blocks summed.
pub(crate) const MAX_TRAIN: usize = 100_000;

/// Sums over the train at one leader angle.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TrainSums {
    /// Σ ρ_k c_k (dimensionless).
    pub rho_c: f64,
    /// Σ ρ_k τ_k, gravity torques in units of m g h.
    pub rho_tau: f64,
    /// Σ ρ_k c'_k (per radian).
    pub rho_dc: f64,
    /// Number of blocks summed, leader included.
    pub blocks: usize,
}

/// Sums the train whose leader is at `theta0` (rad), with friction `mu`
/// between blocks. `theta0` must lie in `[0, θ_∞]`.
pub(crate) fn train_sums(geom: &Geometry, mu: f64, theta0: f64) -> Result<TrainSums, TheoryError> {
    let lambda = geom.pitch();
    let d = geom.thickness_ratio();
    // sin θ_k and cos θ_k are carried by the angle-addition formulas
    // (sin Δ_k = x_k, cos Δ_k = √(1 − x_k²)): no trigonometric call per block.
    let (mut sin_t, mut cos_t) = theta0.sin_cos();
    let (sin_phi, cos_phi) = geom.tip_angle().sin_cos();
    let arm = geom.pivot_to_centre();
    let (mut c, mut dc, mut rho) = (1.0_f64, 0.0_f64, 1.0_f64);
    let mut sums = TrainSums::default();
    let (mut abs_c, mut abs_tau, mut abs_dc) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut small_in_a_row = 0;
    for k in 0..MAX_TRAIN {
        // gravity torque R sin(θ_k − φ)
        let tau = arm * (sin_t * cos_phi - cos_t * sin_phi);
        let (tc, tt, td) = (rho * c, rho * tau, rho * dc);
        sums.rho_c += tc;
        sums.rho_tau += tt;
        sums.rho_dc += td;
        abs_c += tc.abs();
        abs_tau += tt.abs();
        abs_dc += td.abs();
        sums.blocks = k + 1;
        let small = tc.abs() <= TRAIN_TOLERANCE * abs_c
            && tt.abs() <= TRAIN_TOLERANCE * abs_tau
            && td.abs() <= TRAIN_TOLERANCE * abs_dc;
        small_in_a_row = if small { small_in_a_row + 1 } else { 0 };
        if small_in_a_row >= 2 {
            return Ok(sums);
        }
        // Next block: leaning-pair relation and the recursions of the module doc.
        let x = lambda * cos_t - d; // sin Δ_k
        let cos_delta = (1.0 - x * x).sqrt();
        let g = 1.0 - lambda * sin_t / cos_delta;
        let c_next = g * c;
        let dg =
            -lambda * (cos_t * c / cos_delta + sin_t * x * (c_next - c) / (cos_delta * cos_delta));
        let alpha = cos_delta - lambda * sin_t - mu * d;
        let beta = cos_delta + mu * x;
        dc = dg * c + g * dc;
        c = c_next;
        rho *= alpha / beta;
        (sin_t, cos_t) = (sin_t * cos_delta + cos_t * x, cos_t * cos_delta - sin_t * x);
    }
    Err(TheoryError::NotConverged(format!(
        "the leaning train did not converge within {MAX_TRAIN} blocks"
    )))
}
