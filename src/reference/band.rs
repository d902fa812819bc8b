//! A banded linear solver (Gaussian elimination with partial pivoting, like
//! LAPACK's gbsv) for the contact systems of a row: each contact couples at most
//! two neighbouring blocks, so the Delassus matrix W M⁻¹ W is banded and one
//! solve costs O(m · kl · (kl + ku)) for m unknowns.

/// Banded matrix of order m with kl sub- and ku super-diagonals, stored row by
/// row with room for the kl extra super-diagonals that pivoting fills in.
/// Buffers are kept between solves (no allocation once warm).
#[derive(Debug, Default)]
pub(crate) struct Band {
    m: usize,
    kl: usize,
    ku: usize,
    width: usize,
    a: Vec<f64>,
    /// Right-hand side on input to [`Band::solve`], solution on output.
    pub rhs: Vec<f64>,
}

impl Band {
    /// Resets to an m × m zero matrix with the given bandwidths and a zero
    /// right-hand side.
    #[cfg(test)]
    pub fn reset(&mut self, m: usize, kl: usize, ku: usize) {
        self.reset_matrix(m, kl, ku);
        self.rhs.clear();
        self.rhs.resize(m, 0.0);
    }

    #[inline]
    fn idx(&self, r: usize, c: usize) -> usize {
        debug_assert!(c + self.kl >= r && c <= r + self.kl + self.ku);
        r * self.width + (c + self.kl - r)
    }

    /// [`Band::reset`] of the matrix alone: `rhs` is left as it is (the
    /// caller fills it).
    pub fn reset_matrix(&mut self, m: usize, kl: usize, ku: usize) {
        self.m = m;
        self.kl = kl;
        self.ku = ku;
        self.width = 2 * kl + ku + 1;
        self.a.clear();
        self.a.resize(m * self.width, 0.0);
    }

    /// Adds `v` to entry (r, c), which must lie inside the band.
    #[inline]
    pub fn add(&mut self, r: usize, c: usize, v: f64) {
        let k = self.idx(r, c);
        self.a[k] += v;
    }

    /// Solves in place (the solution replaces `rhs`). Returns false if a pivot
    /// is zero or the result is not finite.
    pub fn solve(&mut self) -> bool {
        let m = self.m;
        let (kl, ku) = (self.kl, self.ku);
        for k in 0..m {
            let last = (k + kl).min(m - 1);
            // partial pivoting within the band
            let mut p = k;
            let mut best = self.a[self.idx(k, k)].abs();
            for r in k + 1..=last {
                let v = self.a[self.idx(r, k)].abs();
                if v > best {
                    best = v;
                    p = r;
                }
            }
            if best == 0.0 || !best.is_finite() {
                return false;
            }
            let cmax = (k + kl + ku).min(m - 1);
            if p != k {
                for c in k..=cmax {
                    let (i, j) = (self.idx(k, c), self.idx(p, c));
                    self.a.swap(i, j);
                }
                self.rhs.swap(k, p);
            }
            let piv = self.a[self.idx(k, k)];
            // row k's entries k..=cmax, and row r's below it: entry (r, c)
            // is at r (width − 1) + kl + c
            let start_k = self.idx(k, k);
            for r in k + 1..=last {
                let f = self.a[self.idx(r, k)] / piv;
                if f == 0.0 {
                    continue;
                }
                let start_r = self.idx(r, k);
                let (upper, lower) = self.a.split_at_mut(start_r);
                let row_k = &upper[start_k..=start_k + (cmax - k)];
                for (x, v) in lower[..=cmax - k].iter_mut().zip(row_k) {
                    *x -= f * v;
                }
                self.rhs[r] -= f * self.rhs[k];
            }
        }
        for k in (0..m).rev() {
            let cmax = (k + kl + ku).min(m - 1);
            let mut s = self.rhs[k];
            for c in k + 1..=cmax {
                s -= self.a[self.idx(k, c)] * self.rhs[c];
            }
            self.rhs[k] = s / self.a[self.idx(k, k)];
        }
        self.rhs.iter().all(|x| x.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // A tridiagonal-plus system with a zero leading diagonal (needs pivoting),
    // checked by multiplying the solution back.
    #[test]
    fn solves_banded_systems_with_pivoting() {
        let m = 7;
        let (kl, ku) = (2, 1);
        let entry = |r: usize, c: usize| -> f64 {
            if c + kl < r || c > r + ku || (r == c && r == 0) {
                0.0
            } else {
                1.0 + ((3 * r + 5 * c) % 7) as f64 - if r == c { 0.0 } else { 4.0 }
            }
        };
        let x: Vec<f64> = (0..m).map(|i| (i as f64 * 0.7).sin() + 0.1).collect();
        let mut band = Band::default();
        band.reset(m, kl, ku);
        for r in 0..m {
            for c in 0..m {
                let v = entry(r, c);
                if v != 0.0 {
                    band.add(r, c, v);
                }
            }
            band.rhs[r] = (0..m).map(|c| entry(r, c) * x[c]).sum();
        }
        assert!(band.solve());
        for i in 0..m {
            assert!((band.rhs[i] - x[i]).abs() < 1e-12, "{i}");
        }
    }
}
