//! Lemke's complementary pivoting for a small dense linear complementarity
//! problem (LCP): given M (n × n) and q, find z ≥ 0 with w = M z + q ≥ 0
//! and wᵀ z = 0.
//!
//! The method (C. E. Lemke, "Bimatrix equilibrium points and mathematical
//! programming", 1965; Cottle, Pang & Stone, *The Linear Complementarity
//! Problem*, §4.4) adds an artificial variable z₀ with covering vector
//! e = (1, …, 1): w − M z − e z₀ = q. Starting from the basis of the w's
//! with z₀ just large enough to make every w ≥ 0, it pivots the complement
//! of the variable that left the basis into it, keeping the basic
//! variables non-negative by the ratio test, until z₀ leaves: the basic
//! solution is then complementary. It ends on a secondary ray only for
//! problems without a solution the method can reach; for the copositive
//! matrices of a plastic impact with Coulomb friction in the plane
//! (Stewart & Trinkle 1996) that is not expected, but the caller checks
//! the answer all the same.
//!
//! Dense tableau, Gauss–Jordan pivots over whole rows: n (2n + 2)
//! multiply–adds a pivot, contiguous (updating only the n + 1 non-basic
//! columns through an index list took twice the instructions on the pile
//! scene's solves). Reused buffers, no allocation once they are grown.

/// Why an LCP was not solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LcpFailure {
    /// The entering column had no positive entry (a secondary ray).
    Ray,
    /// The pivot limit was reached (cycling on a degenerate problem).
    Pivots,
}

/// Reusable solver (keeps its tableau between calls).
#[derive(Debug, Default)]
pub(crate) struct Lemke {
    n: usize,
    /// n rows of 2n + 2 columns: w (n), z (n), z₀, right-hand side.
    tableau: Vec<f64>,
    /// The variable basic in each row: 0..n are the w's, n..2n the z's,
    /// 2n is z₀.
    basis: Vec<usize>,
    /// The rows tied in a ratio test.
    ties: Vec<usize>,
    /// The residual of the refinement.
    residual: Vec<f64>,
}

impl Lemke {
    /// Solves the LCP of `m` (row-major, n × n) and `q` into `z` (length
    /// n); returns the pivots taken. A pivot element must exceed
    /// `1e-9` of the largest |M_ij| (and of 1) in magnitude.
    pub(crate) fn solve(
        &mut self,
        m: &[f64],
        q: &[f64],
        z: &mut [f64],
    ) -> Result<usize, LcpFailure> {
        let n = q.len();
        debug_assert_eq!(m.len(), n * n);
        debug_assert_eq!(z.len(), n);
        z.fill(0.0);
        let Some(start) = (0..n)
            .filter(|&i| q[i] < 0.0)
            .min_by(|&i, &j| q[i].total_cmp(&q[j]))
        else {
            return Ok(0); // q ≥ 0: z = 0 is the answer
        };
        self.load(m, q);
        let scale = m.iter().fold(1.0_f64, |s, x| s.max(x.abs()));
        let eps = 1e-9 * scale;
        let z0 = 2 * n;
        // at every vertex of the path all pairs but the entering one are
        // complementary, and that one is non-basic (both zero): a vertex
        // where z₀ has fallen to the rounding of q (10⁻¹³ of its largest
        // entry) is an answer, also when rounding kept z₀ from leaving in
        // the ratio test
        let done = 1e-13 * q.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
        self.pivot(start, z0);
        let z0_row = start; // z₀ stays basic in its row until it leaves
        let mut entering = n + start; // the complement of w_start, which left
        let limit = 50 * n + 100;
        for pivots in 1..=limit {
            let Some(row) = self.ratio_test(entering, eps) else {
                // a ray where z₀ is within 10⁻⁹ of q's scale: the vertex
                // solves the problem to that rounding (the caller checks
                // the velocities it gives)
                return if self.value(z0_row).abs() <= 1e4 * done {
                    self.read(m, q, z);
                    Ok(pivots)
                } else {
                    Err(LcpFailure::Ray)
                };
            };
            let leaving = self.basis[row];
            self.pivot(row, entering);
            if leaving == z0 {
                self.read(m, q, z);
                return Ok(pivots + 1);
            }
            if self.value(z0_row).abs() <= done {
                self.read(m, q, z);
                return Ok(pivots + 1);
            }
            entering = if leaving < n {
                leaving + n
            } else {
                leaving - n
            };
        }
        Err(LcpFailure::Pivots)
    }

    /// The tableau of w − M z − e z₀ = q with the w's basic.
    fn load(&mut self, m: &[f64], q: &[f64]) {
        let n = q.len();
        let width = 2 * n + 2;
        self.n = n;
        self.tableau.clear();
        self.tableau.resize(n * width, 0.0);
        self.basis.clear();
        self.basis.extend(0..n);
        for i in 0..n {
            let row = &mut self.tableau[i * width..(i + 1) * width];
            row[i] = 1.0;
            for (dst, &mij) in row[n..2 * n].iter_mut().zip(&m[i * n..(i + 1) * n]) {
                *dst = -mij;
            }
            row[2 * n] = -1.0;
            row[2 * n + 1] = q[i];
        }
    }

    /// The row whose basic variable first reaches zero as column `col`
    /// enters: the least ratio of the right-hand side to the column, ties
    /// (a degenerate basis: zero right-hand sides are common, the slip
    /// rows start at q = 0) broken by the lexicographic rule on the rows
    /// of B⁻¹ (the w columns), which cannot cycle; z₀ wins any tie of the
    /// first ratio, so that the method ends.
    fn ratio_test(&mut self, col: usize, eps: f64) -> Option<usize> {
        let (n, width) = (self.n, 2 * self.n + 2);
        let entry = |i: usize, c: usize| self.tableau[i * width + c];
        self.ties.clear();
        let mut least = f64::INFINITY;
        for i in 0..n {
            let d = entry(i, col);
            if d > eps {
                let ratio = entry(i, width - 1) / d;
                least = least.min(ratio);
                self.ties.push(i);
            }
        }
        let tie = |r: f64, least: f64| r <= least + 1e-12 * least.abs().max(1.0);
        self.ties.retain(|&i| {
            tie(
                self.tableau[i * width + width - 1] / self.tableau[i * width + col],
                least,
            )
        });
        if let Some(&i) = self.ties.iter().find(|&&i| self.basis[i] == 2 * n) {
            return Some(i);
        }
        let mut k = 0;
        while self.ties.len() > 1 && k < n {
            let ratio = |i: usize| self.tableau[i * width + k] / self.tableau[i * width + col];
            let least = self
                .ties
                .iter()
                .map(|&i| ratio(i))
                .fold(f64::INFINITY, f64::min);
            self.ties.retain(|&i| tie(ratio(i), least));
            k += 1;
        }
        self.ties.first().copied()
    }

    /// Gauss–Jordan pivot on (`row`, `col`): the variable of `col` becomes
    /// basic in `row`. Whole rows, contiguous, so that the update
    /// vectorises: the columns of the other basic variables are zero in
    /// the pivot row and come through unchanged.
    fn pivot(&mut self, row: usize, col: usize) {
        let width = 2 * self.n + 2;
        let (before, rest) = self.tableau.split_at_mut(row * width);
        let (pivot_row, after) = rest.split_at_mut(width);
        let inv = 1.0 / pivot_row[col];
        pivot_row.iter_mut().for_each(|x| *x *= inv);
        pivot_row[col] = 1.0;
        for other in before
            .chunks_exact_mut(width)
            .chain(after.chunks_exact_mut(width))
        {
            let f = other[col];
            if f != 0.0 {
                for (x, &p) in other.iter_mut().zip(pivot_row.iter()) {
                    *x -= f * p;
                }
                other[col] = 0.0;
            }
        }
        self.basis[row] = col;
    }

    /// The value of the variable basic in `row`.
    fn value(&self, row: usize) -> f64 {
        let width = 2 * self.n + 2;
        self.tableau[row * width + width - 1]
    }

    /// z from the basic solution (non-basic variables are zero; rounding
    /// below zero is clamped), after two rounds of iterative refinement:
    /// the residual r = q − A_B x_B of the basic columns of
    /// A = [I, −M, −e] is computed from `m` and `q` and x_B += B⁻¹ r with
    /// the tableau's B⁻¹ (its w columns), which takes back most of the
    /// rounding the pivots gathered.
    fn read(&mut self, m: &[f64], q: &[f64], z: &mut [f64]) {
        let (n, width) = (self.n, 2 * self.n + 2);
        for _ in 0..2 {
            // r = q − Σ_basic A_col x
            self.residual.clear();
            self.residual.extend_from_slice(q);
            for (i, &var) in self.basis.iter().enumerate() {
                let x = self.tableau[i * width + width - 1];
                if var < n {
                    self.residual[var] -= x;
                } else if var < 2 * n {
                    let j = var - n;
                    for (k, r) in self.residual.iter_mut().enumerate() {
                        *r += m[k * n + j] * x;
                    }
                } else {
                    self.residual.iter_mut().for_each(|r| *r += x);
                }
            }
            for i in 0..n {
                let row = &self.tableau[i * width..i * width + n];
                let dx: f64 = row.iter().zip(&self.residual).map(|(b, r)| b * r).sum();
                self.tableau[i * width + width - 1] += dx;
            }
        }
        for (i, &var) in self.basis.iter().enumerate() {
            if (n..2 * n).contains(&var) {
                z[var - n] = self.tableau[i * width + width - 1].max(0.0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checks z ≥ 0, w = M z + q ≥ 0 and w ⊥ z to `tol`.
    fn complementary(m: &[f64], q: &[f64], z: &[f64], tol: f64) {
        let n = q.len();
        for i in 0..n {
            let w: f64 = q[i] + (0..n).map(|j| m[i * n + j] * z[j]).sum::<f64>();
            assert!(z[i] >= 0.0 && w >= -tol, "row {i}: z {} w {w}", z[i]);
            assert!((w * z[i]).abs() <= tol, "row {i}: z {} w {w}", z[i]);
        }
    }

    /// A positive definite 2 × 2 problem with its answer by hand: with
    /// M = [[2, 1], [1, 2]], q = (−3, 1) the second w is positive and
    /// z = (1.5, 0), w = (0, 2.5).
    #[test]
    fn a_two_by_two_problem_by_hand() {
        let (m, q) = ([2.0, 1.0, 1.0, 2.0], [-3.0, 1.0]);
        let mut z = [0.0; 2];
        Lemke::default().solve(&m, &q, &mut z).unwrap();
        assert!((z[0] - 1.5).abs() < 1e-14 && z[1] == 0.0, "{z:?}");
    }

    /// q ≥ 0 needs no pivot: z = 0.
    #[test]
    fn a_non_negative_q_is_solved_by_zero() {
        let mut z = [7.0; 2];
        let pivots = Lemke::default()
            .solve(&[1.0, 0.0, 0.0, 1.0], &[0.0, 2.0], &mut z)
            .unwrap();
        assert_eq!((pivots, z), (0, [0.0; 2]));
    }

    /// Random symmetric positive semidefinite problems (rank-deficient, as
    /// collinear contact points make them) built around a known
    /// complementary pair z*, w* (q = w* − M z*): a feasible PSD problem,
    /// which Lemke's method solves (Cottle, Pang & Stone, Thm. 4.4.13);
    /// every answer is complementary (not necessarily z*: the solution
    /// of a singular M need not be unique).
    #[test]
    fn random_semidefinite_problems_are_solved() {
        let mut draw = super::super::tests::xorshift();
        let mut solver = Lemke::default();
        for trial in 0..300 {
            let n = 1 + trial % 15;
            let rank = 1 + trial % n;
            let a: Vec<f64> = (0..n * rank).map(|_| draw() - 0.5).collect();
            let mut m = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    m[i * n + j] = (0..rank).map(|k| a[i * rank + k] * a[j * rank + k]).sum();
                }
            }
            let (mut z_star, mut w_star) = (vec![0.0; n], vec![0.0; n]);
            for i in 0..n {
                if draw() < 0.5 {
                    z_star[i] = draw();
                } else {
                    w_star[i] = draw();
                }
            }
            let q: Vec<f64> = (0..n)
                .map(|i| w_star[i] - (0..n).map(|j| m[i * n + j] * z_star[j]).sum::<f64>())
                .collect();
            let mut z = vec![0.0; n];
            solver
                .solve(&m, &q, &mut z)
                .unwrap_or_else(|e| panic!("trial {trial}: {e:?}"));
            complementary(&m, &q, &z, 1e-9);
        }
    }
}
