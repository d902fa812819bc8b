//! Stage 3: the constraint rows — stuck friction patches and held points —
//! and their forces.
//!
//! A stuck patch keeps its slip rate v_t constant (zero, up to the rounding
//! left by the event that stuck it); a held point (an e = 0 point held
//! closed, [`crate::impact::ImpactSettings::e0_hold`]) keeps its normal rate
//! constant. With accelerations a = M⁻¹ (Jᵀ F) of the other forces, the row
//! forces f solve
//!
//!   A f = −J_S a,   A = J_S M⁻¹ D_Sᵀ,
//!
//! where J_S are the rows' velocity directions and D_S the directions their
//! forces push along (the same, except for a held point of a sliding patch,
//! whose normal force drags friction along: D = n − μ s t). W is constant
//! during the impact (positions are frozen), so A is factored once per set
//! of rows (LU with complete pivoting) and each evaluation costs one pair of
//! triangular solves. Rows that depend on others (more rows than a body
//! pair's degrees of freedom) have pivots below 10⁻¹¹ of the largest one;
//! their forces are set to zero, which solves the system whenever it is
//! consistent — and it always is: J_S a lies in the range of A.
//!
//! Whether each row's force is admissible (λ ≥ 0, |f| ≤ μ_s N) is not this
//! stage's business: the event stage watches it and changes the set.

use super::data::{push, rate, Axis, BodySlot};

/// What a constraint row holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Target {
    /// A held point (its index): no normal approach.
    Held(usize),
    /// A stuck patch (its index): no slip.
    Stick(usize),
}

/// One row: bodies, the velocity it holds and the direction it pushes.
#[derive(Clone, Copy, Debug)]
struct ConstraintRow {
    target: Target,
    a: usize,
    b: usize,
    velocity: Axis,
    push: Axis,
}

/// The constraint rows of the present modes and the factors of A.
#[derive(Debug, Default)]
pub(super) struct Constraints {
    rows: Vec<ConstraintRow>,
    /// LU factors of A (row-major, n × n), with row and column permutations.
    lu: Vec<f64>,
    row_perm: Vec<usize>,
    col_perm: Vec<usize>,
    /// Pivots above the rank threshold.
    rank: usize,
    /// Right-hand side and solution (solver order), forces (row order).
    rhs: Vec<f64>,
    forces: Vec<f64>,
}

impl Constraints {
    pub fn clear(&mut self) {
        self.rows.clear();
    }

    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Adds a row holding `velocity`'s rate, pushing along `push`.
    pub fn add(&mut self, target: Target, a: usize, b: usize, velocity: Axis, push: Axis) {
        self.rows.push(ConstraintRow {
            target,
            a,
            b,
            velocity,
            push,
        });
    }

    /// Row `k`'s target and its force from the last solve (N).
    pub fn force(&self, k: usize) -> (Target, f64) {
        (self.rows[k].target, self.forces[k])
    }

    /// Forms A = J_S M⁻¹ D_Sᵀ and factors it.
    pub fn factor(&mut self, bodies: &[BodySlot]) {
        let n = self.rows.len();
        self.lu.clear();
        self.lu.resize(n * n, 0.0);
        for (r, row) in self.rows.iter().enumerate() {
            for (c, col) in self.rows.iter().enumerate() {
                self.lu[r * n + c] = coupling(bodies, row, col);
            }
        }
        self.rhs.resize(n, 0.0);
        self.forces.resize(n, 0.0);
        self.decompose(n);
    }

    /// LU with complete pivoting, in place; stops at the first pivot below
    /// 10⁻¹¹ of the largest (the rank).
    fn decompose(&mut self, n: usize) {
        self.row_perm.clear();
        self.row_perm.extend(0..n);
        self.col_perm.clear();
        self.col_perm.extend(0..n);
        let a = &mut self.lu;
        let mut largest = 0.0f64;
        self.rank = 0;
        for k in 0..n {
            let (mut pr, mut pc, mut best) = (k, k, 0.0f64);
            for r in k..n {
                for c in k..n {
                    let v = a[r * n + c].abs();
                    if v > best {
                        (pr, pc, best) = (r, c, v);
                    }
                }
            }
            if k == 0 {
                largest = best;
            }
            if best <= 1e-11 * largest || best == 0.0 {
                break;
            }
            if pr != k {
                for c in 0..n {
                    a.swap(k * n + c, pr * n + c);
                }
                self.row_perm.swap(k, pr);
            }
            if pc != k {
                for r in 0..n {
                    a.swap(r * n + k, r * n + pc);
                }
                self.col_perm.swap(k, pc);
            }
            let pivot = a[k * n + k];
            for r in k + 1..n {
                let l = a[r * n + k] / pivot;
                a[r * n + k] = l;
                if l != 0.0 {
                    for c in k + 1..n {
                        a[r * n + c] -= l * a[k * n + c];
                    }
                }
            }
            self.rank = k + 1;
        }
    }

    /// Solves A f = −J_S `acc` and adds the row forces to `acc`.
    pub fn solve(&mut self, bodies: &[BodySlot], acc: &mut [f64]) {
        for (k, &r) in self.row_perm.iter().enumerate() {
            let row = &self.rows[r];
            self.rhs[k] = -rate(acc, row.a, row.b, &row.velocity);
        }
        self.substitute();
        for (row, &f) in self.rows.iter().zip(&self.forces) {
            if f != 0.0 {
                push(bodies, row.a, row.b, &row.push, f, acc);
            }
        }
    }

    /// Solves A p = −J_S `v` (an impulse that brings every row's rate to
    /// zero), adds it to the velocities `v` and returns it per row in
    /// [`Constraints::force`].
    pub fn project(&mut self, bodies: &[BodySlot], v: &mut [f64]) {
        self.solve(bodies, v);
    }

    /// Forward and back substitution on the first `rank` pivots; the other
    /// unknowns are zero.
    fn substitute(&mut self) {
        let n = self.rows.len();
        let r = self.rank;
        let a = &self.lu;
        let x = &mut self.rhs;
        for i in 0..r {
            let mut s = x[i];
            for j in 0..i {
                s -= a[i * n + j] * x[j];
            }
            x[i] = s;
        }
        for i in (0..r).rev() {
            let mut s = x[i];
            for j in i + 1..r {
                s -= a[i * n + j] * x[j];
            }
            x[i] = s / a[i * n + i];
        }
        for f in self.forces.iter_mut() {
            *f = 0.0;
        }
        for (k, &c) in self.col_perm.iter().enumerate().take(r) {
            self.forces[c] = x[k];
        }
    }
}

/// Rate change of row `r` per unit force of row `c`: J_r M⁻¹ D_cᵀ (1/kg).
fn coupling(bodies: &[BodySlot], r: &ConstraintRow, c: &ConstraintRow) -> f64 {
    // body slot, the row's sign and arm, the column's sign and arm
    let sides = |x: &ConstraintRow, axis: &Axis| [(x.a, -1.0, axis.arm_a), (x.b, 1.0, axis.arm_b)];
    let mut sum = 0.0;
    for (br, sr, ar) in sides(r, &r.velocity) {
        for (bc, sc, ac) in sides(c, &c.push) {
            if br == bc {
                let s = &bodies[br];
                let dot = r.velocity.dir[0] * c.push.dir[0] + r.velocity.dir[1] * c.push.dir[1];
                sum += sr * sc * (s.inv_mass * dot + s.inv_inertia * ar * ac);
            }
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slot(m: f64, i: f64) -> BodySlot {
        BodySlot {
            inv_mass: 1.0 / m,
            inv_inertia: 1.0 / i,
            gyration: (i / m).sqrt(),
        }
    }

    fn axis(dir: [f64; 2], arm_a: f64, arm_b: f64) -> Axis {
        Axis { dir, arm_a, arm_b }
    }

    #[test]
    fn a_stuck_row_cancels_the_slip_acceleration() {
        // body 0 pushed along x on the ground (world = slot 1)
        let bodies = [slot(2.0, 0.5), BodySlot::default()];
        let t = axis([1.0, 0.0], 0.0, 0.3);
        let mut c = Constraints::default();
        c.add(Target::Stick(0), 1, 0, t, t);
        c.factor(&bodies);
        let mut acc = [3.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        c.solve(&bodies, &mut acc);
        assert!(rate(&acc, 1, 0, &t).abs() < 1e-12);
        // f = −m_eff a_t with 1/m_eff = 1/m + r²/I
        let expected = -3.0 / (0.5 + 0.09 / 0.5);
        assert!((c.force(0).1 - expected).abs() < 1e-12);
    }

    #[test]
    fn dependent_rows_get_zero_force_and_are_still_held() {
        // two identical rows on one body: rank 1
        let bodies = [slot(1.0, 0.1), BodySlot::default()];
        let t = axis([1.0, 0.0], 0.0, 0.05);
        let mut c = Constraints::default();
        c.add(Target::Stick(0), 1, 0, t, t);
        c.add(Target::Stick(1), 1, 0, t, t);
        c.factor(&bodies);
        let mut acc = [1.0, 2.0, 0.5, 0.0, 0.0, 0.0];
        c.solve(&bodies, &mut acc);
        assert!(rate(&acc, 1, 0, &t).abs() < 1e-12);
        let (f0, f1) = (c.force(0).1, c.force(1).1);
        assert!(f0 == 0.0 || f1 == 0.0, "{f0} {f1}");
    }
}
