//! Chebyshev interpolation on Chebyshev–Lobatto points: the quadrature of the
//! theory models (spectral accuracy for the smooth functions of θ they integrate).
//!
//! A function sampled at `t_j = a + (b − a)(1 + x_j)/2`, `x_j = cos(π j / n)`,
//! `j = 0..=n`, is represented by its interpolant `Σ_k a_k T_k(x)`; its
//! indefinite integral is again a Chebyshev series (Trefethen, *Approximation
//! Theory and Approximation Practice*, ch. 19), and integrating the interpolant
//! over [a, b] is Clenshaw–Curtis quadrature. Doubling `n` keeps the old
//! points (`x_{2j}` of `2n` equals `x_j` of `n`), so a caller can check
//! convergence without wasting samples.

use std::f64::consts::PI;

/// The Chebyshev–Lobatto points of degree `n`, mapped to `[a, b]`, from `b` (j = 0)
/// down to `a` (j = n).
pub(crate) fn points(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|j| {
            let x = (PI * j as f64 / n as f64).cos();
            a + 0.5 * (b - a) * (1.0 + x)
        })
        .collect()
}

/// A Chebyshev series on `[a, b]`.
#[derive(Clone, Debug)]
pub(crate) struct Series {
    coeffs: Vec<f64>,
    a: f64,
    b: f64,
}

impl Series {
    /// The interpolant of `values` taken at [`points`]`(a, b, n)`, `n = values.len() − 1 ≥ 1`.
    pub fn interpolate(a: f64, b: f64, values: &[f64]) -> Self {
        let n = values.len() - 1;
        let nf = n as f64;
        let cos_table: Vec<f64> = (0..2 * n).map(|m| (PI * m as f64 / nf).cos()).collect();
        let coeffs = (0..=n)
            .map(|k| {
                let mut sum = 0.0;
                for (j, v) in values.iter().enumerate() {
                    let w = if j == 0 || j == n { 0.5 } else { 1.0 };
                    // cos(π j k / n) with the argument reduced exactly
                    let m = (j * k) % (2 * n);
                    sum += w * v * cos_table[m];
                }
                let scale = if k == 0 || k == n { 1.0 / nf } else { 2.0 / nf };
                scale * sum
            })
            .collect();
        Self { coeffs, a, b }
    }

    /// The indefinite integral `F(t) = ∫_a^t f`, itself a series (one degree more).
    pub fn integral(&self) -> Self {
        let a = &self.coeffs;
        let n = a.len() - 1;
        let get = |k: usize| a.get(k).copied().unwrap_or(0.0);
        let half_width = 0.5 * (self.b - self.a);
        let mut out = vec![0.0; n + 2];
        out[1] = half_width * (get(0) - 0.5 * get(2));
        for (k, o) in out.iter_mut().enumerate().skip(2) {
            *o = half_width * (get(k - 1) - get(k + 1)) / (2.0 * k as f64);
        }
        // F(a) = F(x = −1) = 0
        out[0] = -out
            .iter()
            .enumerate()
            .skip(1)
            .map(|(k, c)| if k % 2 == 0 { *c } else { -*c })
            .sum::<f64>();
        Self {
            coeffs: out,
            a: self.a,
            b: self.b,
        }
    }

    /// Value at `t` in `[a, b]` (Clenshaw's recurrence).
    pub fn eval(&self, t: f64) -> f64 {
        let x = (2.0 * t - self.a - self.b) / (self.b - self.a);
        let (mut b1, mut b2) = (0.0, 0.0);
        for &c in self.coeffs.iter().skip(1).rev() {
            let b0 = 2.0 * x * b1 - b2 + c;
            b2 = b1;
            b1 = b0;
        }
        x * b1 - b2 + self.coeffs[0]
    }
}

/// Clenshaw–Curtis weights on [−1, 1] for the points `x_j = cos(π j / n)`,
/// n even (Trefethen, *Spectral Methods in MATLAB*, `clencurt`): cached per n
/// and thread, so a quadrature costs O(n) after the first.
fn weights(n: usize) -> std::rc::Rc<Vec<f64>> {
    thread_local! {
        static CACHE: std::cell::RefCell<std::collections::HashMap<usize, std::rc::Rc<Vec<f64>>>> =
            std::cell::RefCell::new(std::collections::HashMap::new());
    }
    CACHE.with(|cache| {
        cache
            .borrow_mut()
            .entry(n)
            .or_insert_with(|| {
                let nf = n as f64;
                let w = (0..=n)
                    .map(|j| {
                        let mut v = 1.0;
                        for k in 1..=n / 2 {
                            let b = if 2 * k == n { 1.0 } else { 2.0 };
                            let kf = k as f64;
                            v -= b / (4.0 * kf * kf - 1.0) * (2.0 * PI * kf * j as f64 / nf).cos();
                        }
                        let c = if j == 0 || j == n { 1.0 } else { 2.0 };
                        c * v / nf
                    })
                    .collect();
                std::rc::Rc::new(w)
            })
            .clone()
    })
}

/// Clenshaw–Curtis integral of `f` over `[a, b]`, doubling the degree from 16
/// until two successive results agree to `rel_tol` (relative), at most degree
/// `max_n`. Returns the integral and the degree used, or `None` if it did not
/// converge.
pub(crate) fn integrate(
    f: impl Fn(f64) -> f64,
    a: f64,
    b: f64,
    rel_tol: f64,
    max_n: usize,
) -> Option<(f64, usize)> {
    let half_width = 0.5 * (b - a);
    let sum = |values: &[f64]| {
        let w = weights(values.len() - 1);
        half_width * values.iter().zip(w.iter()).map(|(v, w)| v * w).sum::<f64>()
    };
    let mut n = 16;
    let mut values: Vec<f64> = points(a, b, n).into_iter().map(&f).collect();
    let mut last = sum(&values);
    while n < max_n {
        let finer = points(a, b, 2 * n);
        let mut next = Vec::with_capacity(2 * n + 1);
        for (j, t) in finer.iter().enumerate() {
            next.push(if j % 2 == 0 { values[j / 2] } else { f(*t) });
        }
        values = next;
        n *= 2;
        let value = sum(&values);
        if (value - last).abs() <= rel_tol * value.abs() {
            return Some((value, n));
        }
        last = value;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integral_of_exp_and_cos() {
        let (a, b) = (0.3, 1.7);
        let n = 24;
        let values: Vec<f64> = points(a, b, n).iter().map(|t| t.exp()).collect();
        let f = Series::interpolate(a, b, &values);
        assert!((f.eval(1.1) - 1.1_f64.exp()).abs() < 1e-13);
        let int = f.integral();
        assert!((int.eval(a)).abs() < 1e-14);
        assert!((int.eval(1.2) - (1.2_f64.exp() - a.exp())).abs() < 1e-13);
        let (v, _) = integrate(|t| t.cos(), 0.0, 2.0, 1e-13, 256).unwrap();
        assert!((v - 2.0_f64.sin()).abs() < 1e-13);
        // the weights integrate the interpolant exactly: same as its series integral
        for n in [16, 64] {
            let vals: Vec<f64> = points(a, b, n)
                .iter()
                .map(|t| (3.0 * t).sin() / (1.0 + t))
                .collect();
            let series = Series::interpolate(a, b, &vals).integral().eval(b);
            let w = weights(n);
            let cc: f64 =
                0.5 * (b - a) * vals.iter().zip(w.iter()).map(|(v, w)| v * w).sum::<f64>();
            assert!((series - cc).abs() < 1e-13, "{n}: {series} vs {cc}");
        }
    }
}
