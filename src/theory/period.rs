//! The period integral `T = ∫ dθ/√u` of a leader whose squared angular velocity
//! u(θ) has a small minimum (near the spacing where the wave stalls, T grows
//! like the logarithm of 1/u_min), and the search for that minimum.
//!
//! Around the minimum θ* the integrand behaves like `1/√(u_m + ½u''(θ−θ*)²)`
//! (interior minimum) or `1/√(u_m + u'|θ−θ*|)` (minimum at an end). The
//! substitution `θ = θ* ± ε sinh z`, with ε the width of that peak
//! (`√(2u_m/u'')`, or `u_m/|u'|` at an end), makes the integrand smooth in z, and
//! Clenshaw–Curtis quadrature (see `chebyshev.rs`) converges spectrally again.
//! Each side is doubled until two successive values agree to 10⁻¹² relative,
//! or, very close to a stall, to the relative rounding noise of u at the peak,
//! `10 noise / u_min` (the caller says how large the rounding error of its u is);
//! beyond 10⁻⁶ (the accuracy promised) that is an
//! error rather than a less accurate answer.

use super::chebyshev;
use super::TheoryError;

/// Relative tolerance of each Clenshaw–Curtis integral.
const TOLERANCE: f64 = 1e-12;
/// Loosest tolerance accepted when rounding in u limits the accuracy.
const LOOSEST: f64 = 1e-6;
/// Largest Clenshaw–Curtis degree.
const MAX_DEGREE: usize = 1 << 14;

/// `∫_a^b f`, where `f` peaks where `u` has its minimum on [a, b], at `t_min`
/// (`u > 0` there); `noise` is the absolute rounding error of `u` near `t_min`.
pub(crate) fn peak_integral(
    f: impl Fn(f64) -> f64 + Copy,
    u: impl Fn(f64) -> f64,
    noise: f64,
    a: f64,
    t_min: f64,
    b: f64,
) -> Result<f64, TheoryError> {
    let span = b - a;
    let delta = 1e-4 * span;
    let um = u(t_min);
    let (lo, hi) = ((t_min - delta).max(a), (t_min + delta).min(b));
    let slope = ((u(hi) - u(lo)) / (hi - lo)).abs();
    let curvature = if t_min - delta >= a && t_min + delta <= b {
        ((u(hi) - 2.0 * um + u(lo)) / (delta * delta)).abs()
    } else {
        0.0
    };
    let tolerance = TOLERANCE.max(10.0 * noise / um);
    if tolerance.is_nan() || tolerance > LOOSEST {
        return Err(TheoryError::NotConverged(format!(
            "too close to a stall to resolve the period to {LOOSEST:e} \
             (minimum of u {um:e}, rounding error {noise:e})"
        )));
    }
    let mut eps = f64::INFINITY;
    if curvature > 0.0 {
        eps = eps.min((2.0 * um / curvature).sqrt());
    }
    if slope > 0.0 && (t_min - a < delta || b - t_min < delta) {
        eps = eps.min(um / slope);
    }
    let side = |length: f64, sign: f64| -> Result<f64, TheoryError> {
        if length <= 0.0 {
            return Ok(0.0);
        }
        let result = if eps < length {
            let z_max = (length / eps).asinh();
            chebyshev::integrate(
                |z| f(t_min + sign * eps * z.sinh()) * eps * z.cosh(),
                0.0,
                z_max,
                tolerance,
                MAX_DEGREE,
            )
        } else {
            chebyshev::integrate(|s| f(t_min + sign * s), 0.0, length, tolerance, MAX_DEGREE)
        };
        result.map(|(v, _)| v).ok_or_else(|| {
            TheoryError::NotConverged(format!(
                "period integral on [{a}, {b}] rad not converged to {tolerance:e}"
            ))
        })
    };
    Ok(side(b - t_min, 1.0)? + side(t_min - a, -1.0)?)
}

/// Location and value of the minimum of `f` on [lo, hi] (one minimum there):
/// golden-section search to 10⁻¹³ of the interval, compared with both ends.
pub(crate) fn golden_min(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> (f64, f64) {
    let (a, b) = (lo, hi);
    let (mut lo, mut hi) = (lo, hi);
    let ratio = 0.5 * (5.0_f64.sqrt() - 1.0);
    let mut x1 = hi - ratio * (hi - lo);
    let mut x2 = lo + ratio * (hi - lo);
    let (mut f1, mut f2) = (f(x1), f(x2));
    while hi - lo > 1e-13 * (b - a) {
        if f1 < f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - ratio * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + ratio * (hi - lo);
            f2 = f(x2);
        }
    }
    [
        (a, f(a)),
        (b, f(b)),
        if f1 < f2 { (x1, f1) } else { (x2, f2) },
    ]
    .into_iter()
    .fold(
        (a, f64::INFINITY),
        |best, c| if c.1 < best.1 { c } else { best },
    )
}

/// First point of [a, b] where `f` (positive at a) reaches 0: scan of `m`
/// intervals, then bisection to machine precision.
pub(crate) fn first_zero(f: impl Fn(f64) -> f64, a: f64, b: f64, m: usize) -> f64 {
    if f(a) <= 0.0 {
        return a;
    }
    let h = (b - a) / m as f64;
    let mut lo = a;
    for i in 1..=m {
        let t = a + h * i as f64;
        if f(t) <= 0.0 {
            let mut hi = t;
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if f(mid) > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return 0.5 * (lo + hi);
        }
        lo = t;
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫_{-1}^{1} dθ/√(m + θ²) = 2 asinh(1/√m), sharply peaked for small m.
    #[test]
    fn near_singular_peak() {
        for &m in &[1.0, 1e-4, 1e-10] {
            let u = move |t: f64| m + t * t;
            let v =
                peak_integral(move |t| 1.0 / u(t).sqrt(), u, 1e-16 * m, -1.0, 0.0, 1.0).unwrap();
            let exact = 2.0 * (1.0 / m.sqrt()).asinh();
            assert!((v - exact).abs() < 1e-10 * exact, "{m}: {v} vs {exact}");
        }
        // minimum at an end: ∫_0^1 dθ/√(m + θ) = 2(√(1+m) − √m)
        let m = 1e-9;
        let u = move |t: f64| m + t;
        let v = peak_integral(move |t| 1.0 / u(t).sqrt(), u, 1e-16 * m, 0.0, 0.0, 1.0).unwrap();
        let exact = 2.0 * ((1.0 + m).sqrt() - m.sqrt());
        assert!((v - exact).abs() < 1e-10 * exact, "{v} vs {exact}");
    }
}
