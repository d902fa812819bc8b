//! The single collision model (Stronge 1987; paper Sec. 3.2, dot-dash line of
//! Fig. 5): only the two blocks of each collision count. docs/theory.md states it in
//! words; the derivation below is ours.
//!
//! ## Geometry of the collision (lengths over h, origin at the striker's pivot)
//! The striker A rotates about its front bottom edge O_A = (0, 0); its top
//! front edge is at `C = (sin θ_c, cos θ_c)` when it meets the back face of the
//! upright block B, `x = s`, since `sin θ_c = s/h`. B pivots about its front
//! bottom edge `O_B = (λ, 0)`, so C seen from O_B is `(−d, cos θ_c)`: the
//! contact is at height `h cos θ_c` on B's back face. Normal `n = (1, 0)` (into
//! B), tangent `t = (0, 1)`.
//!
//! ## Velocities at C (clockwise, i.e. forward, rotation positive)
//! A point r from a pivot turning at ω moves at `ω (r_y, −r_x)`:
//! A's edge at `ω_A (cos θ_c, −sin θ_c)`, B's face point at `ω_B (cos θ_c, d)`.
//! Normal approach `v_n = cos θ_c (ω_A − ω_B)`, tangential slip of A on B
//! `v_t = −ω_A sin θ_c − ω_B d` (negative: A's edge slides down B's face).
//!
//! ## Impulse (angular impulse about each pivot; the pivots hold)
//! Impulse `(P_n, P_t)` on B at C, the opposite on A. About the pivots
//! (I = (h² + d²)/3, lengths over h):
//! `I Δω_B = P_n cos θ_c + P_t d`, `I Δω_A = P_t sin θ_c − P_n cos θ_c`.
//! Coulomb friction in differential form along the normal impulse:
//! while A slides down, `dP_t = −μ dP_n`, which gives the lever arms
//! `I dω_B = (cos θ_c − μ d) dP_n = α dP_n`,
//! `I dω_A = −(cos θ_c + μ sin θ_c) dP_n = −β dP_n` (the α, β of docs/theory.md at the
//! leading pair). If the slip stops before the impact ends, the contact sticks
//! (`dP_t/dP_n = κ = cos θ_c (sin θ_c − d)/(sin² θ_c + d²)` keeps `v_t = 0`)
//! when `|κ| ≤ μ`, otherwise slides up with `dP_t = +μ dP_n`.
//! Newton's restitution ends the impact: `v_n⁺ = −e v_n⁻`. Everything is linear
//! in ω_A⁻, so `ω_B⁺ = k ω_A⁻` with a ratio k of the geometry, μ and e; while
//! sliding throughout, `k = (1 + e) α / (α + β)`.
//!
//! ## Free fall and the fixed point
//! After the collision the striker is forgotten; B falls freely about its edge
//! from upright: `u(θ) = θ̇² = u_0 + (2 m g R / I)(cos φ − cos(θ − φ))`,
//! `R = √(h²+d²)/2`, `tan φ = d/h` (energy conservation). Over a cycle
//! `u_c ↦ k² u_c + G`, `G = (2mgR/I)(cos φ − cos(θ_c − φ))`, whose fixed point
//! is `u_c* = G/(1 − k²)`; there is a wave when `G > 0` (θ_c > 2φ) and B gets
//! over the top, `u_0* = k² u_c* > (2mgR/I)(1 − cos φ)`. The period
//! `T = ∫_0^θc dθ/√u` is a Clenshaw–Curtis integral split at θ = φ and
//! stretched there (see `period.rs`; 10⁻¹² relative); the natural speed is `v/√(gh) = (λ/h)/(T/√(h/g))`.

use super::outcome::{NoWave, Outcome, TheoryError, Wave};
use super::period::peak_integral;
use super::Geometry;

/// One single collision at `theta_c` (rad) with friction `mu` and Newton's
/// restitution `e` (see the module doc): returns `(ω_A⁺, ω_B⁺)/ω_A⁻`, the
/// striker's and the struck block's angular velocities after it per unit
/// striker velocity before. `None` when friction stops the struck block from
/// moving forward.
pub(crate) fn collision_ratio(
    geom: &Geometry,
    theta_c: f64,
    mu: f64,
    e: f64,
) -> Option<(f64, f64)> {
    let d = geom.thickness_ratio();
    let inertia = geom.pivot_inertia();
    let (sn, c) = theta_c.sin_cos();
    // state after normal impulse P: (ω_A, ω_B); start with ω_A⁻ = 1
    let (mut wa, mut wb) = (1.0_f64, 0.0_f64);
    let vn = |wa: f64, wb: f64| c * (wa - wb);
    let vt = |wa: f64, wb: f64| -wa * sn - wb * d;
    let target = -e * vn(wa, wb);
    // Rates per unit normal impulse for dP_t = κ dP_n.
    let rates = |kappa: f64| ((sn * kappa - c) / inertia, (c + d * kappa) / inertia);
    // Phase 1: sliding down (v_t < 0), κ = −μ.
    let (da, db) = rates(-mu);
    let dvn = c * (da - db);
    if dvn >= 0.0 {
        return None;
    }
    let p_end = (target - vn(wa, wb)) / dvn;
    let dvt = -sn * da - d * db;
    let p_stop = if dvt > 0.0 {
        -vt(wa, wb) / dvt
    } else {
        f64::INFINITY
    };
    if p_stop >= p_end {
        wa += da * p_end;
        wb += db * p_end;
    } else {
        wa += da * p_stop;
        wb += db * p_stop;
        let kappa_stick = c * (sn - d) / (sn * sn + d * d);
        let kappa = if kappa_stick.abs() <= mu {
            kappa_stick
        } else {
            mu
        };
        let (da, db) = rates(kappa);
        let dvn = c * (da - db);
        if dvn >= 0.0 {
            return None;
        }
        let p = (target - vn(wa, wb)) / dvn;
        wa += da * p;
        wb += db * p;
    }
    (wb > 0.0).then_some((wa, wb))
}

/// Solves the single collision model with friction `mu` and restitution `e`.
pub(crate) fn solve_single(geom: &Geometry, mu: f64, e: f64) -> Result<Outcome, TheoryError> {
    let Some(theta_c) = geom.collision_angle() else {
        return Ok(Outcome::NoWave(NoWave::NoCollision));
    };
    if theta_c.cos() - mu * geom.thickness_ratio() <= 0.0 {
        return Ok(Outcome::NoWave(NoWave::FrictionBlocksImpact));
    }
    let Some((_, k)) = collision_ratio(geom, theta_c, mu, e) else {
        return Ok(Outcome::NoWave(NoWave::FrictionBlocksImpact));
    };
    let phi = geom.tip_angle();
    let w = 2.0 * geom.pivot_to_centre() / geom.pivot_inertia(); // 2 m g R / I
    let gain = w * (phi.cos() - (theta_c - phi).cos());
    if gain <= 0.0 || k >= 1.0 {
        return Ok(Outcome::NoWave(NoWave::NoEnergyGain));
    }
    let u_c = gain / (1.0 - k * k);
    let u0 = k * k * u_c;
    // gain > 0 means θ_c > 2φ > φ: the minimum of u on [0, θ_c] is at φ,
    // u_min = u0 − w (1 − cos φ); written with sin² to avoid cancellation near a stall.
    let half = |x: f64| (0.5 * x).sin();
    let u_min = u0 - 2.0 * w * half(phi) * half(phi);
    let u = |t: f64| u_min + 2.0 * w * half(t - phi) * half(t - phi);
    if u_min <= 0.0 {
        // u falls from u0 at 0 to its minimum at φ: the first zero is in (0, φ].
        let angle = phi - (phi.cos() + u0 / w).clamp(-1.0, 1.0).acos();
        return Ok(Outcome::NoWave(NoWave::LeaderStalls { angle }));
    }
    let period = peak_integral(|t| 1.0 / u(t).sqrt(), u, 1e-15 * u_min, 0.0, phi, theta_c)?;
    Ok(Outcome::Wave(Wave {
        natural_speed: geom.pitch() / period,
        omega_after: u0.sqrt(),
        omega_before: u_c.sqrt(),
        period,
        theta_c,
        theta_inf: geom.rest_angle(),
        train_blocks: 1,
        nodes: 0,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Kinetic energy (∝ ω_A² + ω_B², equal inertias) never grows in a collision,
    /// and with μ = 0 the struck block gets (1 + e)/2 of the striker's velocity
    /// (equal lever arms h cos θ_c about both pivots).
    #[test]
    fn collision_dissipates_and_frictionless_limit() {
        for &d in &[0.05, 0.12, 0.3] {
            for i in 1..20 {
                let s = 0.05 * i as f64;
                let geom = Geometry::new(d, s).unwrap();
                let tc = geom.collision_angle().unwrap();
                for &mu in &[0.0, 0.1, 0.3, 0.6] {
                    for &e in &[0.0, 0.5, 1.0] {
                        if let Some((wa, wb)) = collision_ratio(&geom, tc, mu, e) {
                            assert!(wa * wa + wb * wb <= 1.0 + 1e-12, "{d} {s} {mu} {e}");
                        }
                    }
                }
                for &e in &[0.0, 0.62, 1.0] {
                    let (wa, wb) = collision_ratio(&geom, tc, 0.0, e).unwrap();
                    assert!((wb - 0.5 * (1.0 + e)).abs() < 1e-14);
                    assert!((wa - 0.5 * (1.0 - e)).abs() < 1e-14);
                }
            }
        }
    }
}
