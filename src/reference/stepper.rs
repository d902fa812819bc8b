//! Explicit Runge–Kutta steps for the smooth phase with the contact mode held
//! fixed: the paper's improved Euler (Heun, order 2; Sec. 3.1) and the
//! Dormand–Prince 5(4) pair with an embedded error estimate (Dormand & Prince
//! 1980; the coefficients in `impact/dormand_prince.rs`).

use crate::impact::dormand_prince as dp;

/// A Butcher tableau.
pub(crate) struct Tableau {
    /// Stage nodes c_i.
    pub c: &'static [f64],
    /// Lower-triangular a_ij: row i holds the i coefficients of stage i,
    /// padded with zeros (skipped in the sums).
    pub a: &'static [[f64; 6]],
    /// Weights of the propagated solution.
    pub b: &'static [f64],
    /// Weights of the error estimate (b − b̂), if the pair has one.
    pub e: Option<&'static [f64]>,
}

/// Improved Euler (Heun's method), the paper's integrator.
pub(crate) const HEUN: Tableau = Tableau {
    c: &[0.0, 1.0],
    a: &[[0.0; 6], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]],
    b: &[0.5, 0.5],
    e: None,
};

/// Dormand–Prince 5(4), the crate's one definition
/// (`impact/dormand_prince.rs`).
pub(crate) const DOPRI5: Tableau = Tableau {
    c: &dp::C,
    a: &dp::A,
    b: &dp::B,
    e: Some(&dp::E),
};

/// Stage buffers, reused between steps.
#[derive(Debug, Default)]
pub(crate) struct Stages {
    k: Vec<Vec<f64>>,
    tmp: Vec<f64>,
    /// Error estimate of the last step (absolute, per component).
    pub err: Vec<f64>,
}

impl Stages {
    /// One step of size `h` from `y0` with derivative `k0 = f(y0)`; the result
    /// goes to `y1`. `f(y, dy)` returns false if the derivative cannot be
    /// computed. Returns false in that case.
    pub fn step(
        &mut self,
        tab: &Tableau,
        h: f64,
        y0: &[f64],
        k0: &[f64],
        y1: &mut Vec<f64>,
        mut f: impl FnMut(&[f64], &mut [f64]) -> bool,
    ) -> bool {
        let n = y0.len();
        if tab.is_heun() {
            return self.heun(h, y0, k0, y1, f);
        }
        let s = tab.c.len();
        if self.k.len() < s {
            self.k.resize(s, Vec::new());
        }
        for k in self.k.iter_mut() {
            k.resize(n, 0.0);
        }
        self.tmp.resize(n, 0.0);
        self.k[0].copy_from_slice(k0);
        for i in 1..s {
            let ai = &tab.a[i];
            for x in 0..n {
                let mut acc = 0.0;
                for (j, aij) in ai.iter().enumerate().take(i) {
                    if *aij != 0.0 {
                        acc += aij * self.k[j][x];
                    }
                }
                self.tmp[x] = y0[x] + h * acc;
            }
            let (head, tail) = self.k.split_at_mut(i);
            let _ = head;
            if !f(&self.tmp, &mut tail[0]) {
                return false;
            }
        }
        y1.resize(n, 0.0);
        for x in 0..n {
            let mut acc = 0.0;
            for (j, bj) in tab.b.iter().enumerate() {
                if *bj != 0.0 {
                    acc += bj * self.k[j][x];
                }
            }
            y1[x] = y0[x] + h * acc;
        }
        self.err.resize(n, 0.0);
        if let Some(e) = tab.e {
            for x in 0..n {
                let mut acc = 0.0;
                for (j, ej) in e.iter().enumerate() {
                    acc += ej * self.k[j][x];
                }
                self.err[x] = h * acc;
            }
        } else {
            self.err.iter_mut().for_each(|v| *v = 0.0);
        }
        true
    }
}

impl Tableau {
    /// Whether this is [`HEUN`]'s tableau.
    fn is_heun(&self) -> bool {
        self.c == HEUN.c && self.a == HEUN.a && self.b == HEUN.b && self.e.is_none()
    }
}

impl Stages {
    /// [`Stages::step`] for [`HEUN`], written out: the same operations in
    /// the same order as the tableau loop (so the same bits), without its
    /// indexing (the paper's integrator runs this at every step and at every
    /// trial of an event's location).
    fn heun(
        &mut self,
        h: f64,
        y0: &[f64],
        k0: &[f64],
        y1: &mut Vec<f64>,
        mut f: impl FnMut(&[f64], &mut [f64]) -> bool,
    ) -> bool {
        let n = y0.len();
        if self.k.len() < 2 {
            self.k.resize(2, Vec::new());
        }
        self.tmp.resize(n, 0.0);
        let k1 = &mut self.k[1];
        k1.resize(n, 0.0);
        for ((t, y), k) in self.tmp.iter_mut().zip(y0).zip(k0) {
            *t = y + h * (0.0 + 1.0 * k);
        }
        if !f(&self.tmp, k1) {
            return false;
        }
        y1.resize(n, 0.0);
        for (((out, y), a), b) in y1.iter_mut().zip(y0).zip(k0).zip(k1.iter()) {
            *out = y + h * (0.0 + 0.5 * a + 0.5 * b);
        }
        self.err.clear();
        self.err.resize(n, 0.0);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The written-out Heun step gives the tableau loop's bits: the same
    // tableau with an (all-zero) error row takes the loop.
    #[test]
    fn heun_written_out_matches_the_tableau_loop() {
        const LOOPED: Tableau = Tableau {
            c: HEUN.c,
            a: HEUN.a,
            b: HEUN.b,
            e: Some(&[0.0, 0.0]),
        };
        assert!(HEUN.is_heun() && !LOOPED.is_heun() && !DOPRI5.is_heun());
        let y0: Vec<f64> = (0..13).map(|i| (i as f64 * 0.37).sin() - 0.2).collect();
        let f = |y: &[f64], dy: &mut [f64]| {
            for (i, (d, v)) in dy.iter_mut().zip(y).enumerate() {
                *d = (v * (1.0 + i as f64)).cos() - 0.3 * v * v;
            }
            true
        };
        let mut k0 = vec![0.0; y0.len()];
        f(&y0, &mut k0);
        k0[3] = -0.0;
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let mut st = Stages::default();
        assert!(st.step(&HEUN, 0.013, &y0, &k0, &mut a, f));
        assert!(st.step(&LOOPED, 0.013, &y0, &k0, &mut b, f));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b));
    }

    // y' = −y: one step's error must shrink as h^(order+1).
    #[test]
    fn orders_of_heun_and_dopri5() {
        for (tab, order) in [(&HEUN, 2), (&DOPRI5, 5)] {
            let mut st = Stages::default();
            let mut errs = Vec::new();
            for h in [0.1f64, 0.05] {
                let mut y1 = Vec::new();
                let ok = st.step(tab, h, &[1.0], &[-1.0], &mut y1, |y, dy| {
                    dy[0] = -y[0];
                    true
                });
                assert!(ok);
                errs.push((y1[0] - (-h).exp()).abs());
            }
            let p = (errs[0] / errs[1]).log2();
            assert!((p - (order as f64 + 1.0)).abs() < 0.3, "order {order}: {p}");
        }
    }
}
