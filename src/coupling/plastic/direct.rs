//! The direct stage of the plastic solve: the impulses of the contacts
//! that carry load, solved together.
//!
//! Projected Gauss–Seidel moves momentum one contact at a time. Where a
//! heavy body lies on a light one (a stack with a mass ratio M/m), each
//! sweep drains only about m/M of the heavy body's approach through the
//! light one, so a stack with a ratio of a few hundred needs thousands of
//! sweeps and stops at the cap with contacts still approaching; the
//! friction rows of such a stack couple the same way. Every few sweeps
//! this stage takes the contacts that carry a normal impulse or approach
//! (the active set A), with their tangential rows (friction μ > 0), holds
//! every other impulse, and solves
//!
//! W_AA ΔP_A = −δ̇_A,   W_ij = J_i M⁻¹ J_jᵀ (kg⁻¹),
//!
//! for the change that stops every active row at once: the minimiser of
//! the kinetic energy over the impulses of A (the plastic condition
//! δ̇'_n = 0 on the contacts that stay loaded, no slip where they stick).
//! The step keeps every impulse where the sweeps keep it whether its
//! contact sticks or slides: P_n ≥ 0, a held friction impulse inside the
//! sliding cone (P_n ≥ |P_t| / μ) and an active one too (|P_t| ≤ μ P_n). A change that would leave that set is
//! cut where the first row reaches its bound (a step of an active-set
//! method on a convex quadratic, so the energy falls along it), and that
//! row leaves A: a normal row with its contact, a tangential row alone (its
//! friction then held, sliding at the cone). A row already at its bound
//! whose solution would cross it leaves A before the step. The energy is
//! checked after the step, which is undone should round-off have raised
//! it.
//!
//! Collinear contact points of one face (λ points) make W_AA singular: the
//! split of a face's load among its points is free. The Cholesky
//! factorisation skips a pivot below [`PIVOT`] of the largest diagonal
//! entry, which gives that row no change; the system is consistent (its
//! right-hand side is J_A u), so the other rows still stop the face.

use super::{PlasticSolver, Row};

/// Pivots below this fraction of the largest diagonal entry of W_AA are
/// taken as dependent rows (dimensionless; round-off of W is about 10⁻¹⁶
/// of its entries, a nearly collinear pair of points far above it).
const PIVOT: f64 = 1e-10;
/// Active-set steps of one call at most (each removes a contact from A).
const ROUNDS: usize = 8;
/// The stage's work in one solve at most, in sweeps of the group: twice
/// what the sweep cap costs (a call costs about m³/6 multiply-adds for the
/// factorisation of m rows and 12 m² for assembling W_AA and the two
/// triangular solves; a sweep [`SWEEP_WORK`] per contact point), so a
/// plastic solve costs at most three times what the sweeps alone could.
/// Where friction keeps the sweeps cycling the stage spends all of it and
/// leaves the contacts approaching less (seed 13's stack of the scene
/// sweep: 0.052 of a width beyond the tolerance's reference point at this
/// cap, 0.114 at half of it, 0.121 without the stage;
/// `tests/rapier/stress_checks.rs`).
const MAX_SWEEPS_WORTH: u64 = 2000;
/// Multiply-adds of one Gauss–Seidel sweep per contact point (two rows, each
/// a rate and a push over two bodies): converts the stage's work to sweeps
/// for the work budget.
pub(super) const SWEEP_WORK: u64 = 40;

/// Scratch of the direct stage, reused between calls.
#[derive(Debug, Default)]
pub(super) struct Direct {
    /// Rows of the active set: the contact and whether it is its
    /// tangential row.
    active: Vec<(usize, bool)>,
    /// Rows taken out of the active set in this call, per contact: its
    /// normal row (and with it the contact), its tangential row.
    excluded: Vec<[bool; 2]>,
    /// W_AA, then its Cholesky factor (row-major, lower triangle).
    w: Vec<f64>,
    /// −δ̇_A, then ΔP_A.
    x: Vec<f64>,
    /// Rows whose pivot was skipped.
    dependent: Vec<bool>,
    /// Velocities and active impulses before a step, to undo it.
    saved_velocity: Vec<[f64; 3]>,
    saved_impulse: Vec<f64>,
    /// Multiply-adds spent in this solve.
    pub(super) work: u64,
}

impl PlasticSolver {
    /// One call of the direct stage (see the module's text): up to
    /// [`ROUNDS`] active-set steps on the normal impulses.
    pub(super) fn solve_direct(&mut self) {
        let n = self.rows.len();
        self.direct.excluded.clear();
        self.direct.excluded.resize(n, [false; 2]);
        for _ in 0..ROUNDS {
            if !self.gather_active() {
                return;
            }
            let m = self.direct.active.len() as u64;
            let cost = m * m * m / 6 + 12 * m * m;
            let cap = MAX_SWEEPS_WORTH * SWEEP_WORK * self.rows.len() as u64;
            if self.direct.work + cost > cap {
                return;
            }
            self.direct.work += cost;
            self.assemble();
            self.factor_and_solve();
            match self.ratio_test() {
                Ratio::Drop => continue,
                Ratio::Step(alpha, blocking) => {
                    if !self.apply(alpha) {
                        return;
                    }
                    match blocking {
                        Some((k, tangential)) => {
                            self.direct.excluded[k][usize::from(tangential)] = true;
                        }
                        None => return,
                    }
                }
            }
        }
    }

    /// Fills the active set: the normal rows that can move, not excluded,
    /// with an impulse or an approach, and the tangential rows of those
    /// whose friction is inside the sticking cone. False when it is empty.
    fn gather_active(&mut self) -> bool {
        self.direct.active.clear();
        for k in 0..self.rows.len() {
            let r = self.rows[k];
            let [normal_out, tangent_out] = self.direct.excluded[k];
            if r.inv_w_nn == 0.0 || normal_out {
                continue;
            }
            if self.impulse[k][0] > 0.0 || self.rate(&r, r.n, r.a_rn, r.b_rn) < 0.0 {
                self.direct.active.push((k, false));
                if !tangent_out && r.inv_w_tt > 0.0 && r.friction > 0.0 {
                    self.direct.active.push((k, true));
                }
            }
        }
        !self.direct.active.is_empty()
    }

    /// A row's direction and moment arms on its two bodies.
    fn axis(r: &Row, tangential: bool) -> ([f64; 2], f64, f64) {
        if tangential {
            (r.t, r.a_rt, r.b_rt)
        } else {
            (r.n, r.a_rn, r.b_rn)
        }
    }

    /// W_AA and −δ̇_A.
    fn assemble(&mut self) {
        let m = self.direct.active.len();
        self.direct.w.clear();
        self.direct.w.resize(m * m, 0.0);
        self.direct.x.clear();
        for i in 0..m {
            let (ki, ti) = self.direct.active[i];
            for j in 0..=i {
                let (kj, tj) = self.direct.active[j];
                let w = self.coupling(&self.rows[ki], ti, &self.rows[kj], tj);
                self.direct.w[i * m + j] = w;
                self.direct.w[j * m + i] = w;
            }
            let r = self.rows[ki];
            let (dir, arm_a, arm_b) = Self::axis(&r, ti);
            self.direct.x.push(-self.rate(&r, dir, arm_a, arm_b));
        }
    }

    /// J_i M⁻¹ J_jᵀ of two rows (kg⁻¹): the change of row i's rate per unit
    /// impulse along row j.
    fn coupling(&self, ri: &Row, ti: bool, rj: &Row, tj: bool) -> f64 {
        let (di, ai, bi) = Self::axis(ri, ti);
        let (dj, aj, bj) = Self::axis(rj, tj);
        let dot = di[0] * dj[0] + di[1] * dj[1];
        let mut w = 0.0;
        for (si, sign_i, arm_i) in [(ri.a, -1.0, ai), (ri.b, 1.0, bi)] {
            for (sj, sign_j, arm_j) in [(rj.a, -1.0, aj), (rj.b, 1.0, bj)] {
                if si == sj {
                    w += sign_i
                        * sign_j
                        * (self.inv_mass[si] * dot + self.inv_inertia[si] * arm_i * arm_j);
                }
            }
        }
        w
    }

    /// Cholesky factorisation of W_AA with dependent rows skipped, then
    /// the two triangular solves: `x` becomes ΔP_A (0 on skipped rows).
    fn factor_and_solve(&mut self) {
        let d = &mut self.direct;
        let m = d.active.len();
        let largest = (0..m).map(|i| d.w[i * m + i]).fold(0.0, f64::max);
        d.dependent.clear();
        d.dependent.resize(m, false);
        for j in 0..m {
            let pivot = d.w[j * m + j] - (0..j).map(|k| d.w[j * m + k].powi(2)).sum::<f64>();
            if pivot <= PIVOT * largest {
                d.dependent[j] = true;
                for i in j..m {
                    d.w[i * m + j] = 0.0;
                }
                continue;
            }
            let l = pivot.sqrt();
            d.w[j * m + j] = l;
            for i in j + 1..m {
                let s: f64 = (0..j).map(|k| d.w[i * m + k] * d.w[j * m + k]).sum();
                d.w[i * m + j] = (d.w[i * m + j] - s) / l;
            }
        }
        for j in 0..m {
            let s: f64 = (0..j).map(|k| d.w[j * m + k] * d.x[k]).sum();
            d.x[j] = if d.dependent[j] {
                0.0
            } else {
                (d.x[j] - s) / d.w[j * m + j]
            };
        }
        for j in (0..m).rev() {
            let s: f64 = (j + 1..m).map(|i| d.w[i * m + j] * d.x[i]).sum();
            d.x[j] = if d.dependent[j] {
                0.0
            } else {
                (d.x[j] - s) / d.w[j * m + j]
            };
        }
    }

    /// How far along ΔP_A the impulses stay inside their set (P_n ≥ 0,
    /// |P_t| ≤ μ P_n); rows at a bound that the change would cross leave A.
    fn ratio_test(&mut self) -> Ratio {
        let (mut alpha, mut blocking, mut dropped) = (1.0_f64, None, false);
        let m = self.direct.active.len();
        for i in 0..m {
            let (k, tangential) = self.direct.active[i];
            // the contact's normal change (0 if its normal row is not in A:
            // it is always listed just before its tangential row)
            let dpn = if tangential {
                self.direct.x[i - 1]
            } else {
                self.direct.x[i]
            };
            let [pn, pt] = self.impulse[k];
            // the sliding coefficient bounds the step: an impulse inside μ P_n
            // is one the sweeps keep whether the contact sticks or slides
            // (a step to the sticking cone's edge would be thrown back to
            // μ P_n by the next sweep, raising the energy where μ_s > μ)
            let mu = self.rows[k].friction;
            let held_tangent = !tangential && !self.tangent_active(i);
            // each bound as g(α) = g0 + α g1 ≥ 0
            let mut bounds = [None, None];
            if tangential {
                if mu.is_finite() {
                    let dpt = self.direct.x[i];
                    bounds = [
                        Some((mu * pn - pt, mu * dpn - dpt)),
                        Some((mu * pn + pt, mu * dpn + dpt)),
                    ];
                }
            } else {
                let floor = if held_tangent && mu.is_finite() && mu > 0.0 {
                    pt.abs() / mu
                } else {
                    0.0
                };
                bounds[0] = Some((pn - floor, dpn));
            }
            for (g0, g1) in bounds.into_iter().flatten() {
                if g0 + g1 >= 0.0 {
                    continue;
                }
                if g0 <= 0.0 {
                    self.direct.excluded[k][usize::from(tangential)] = true;
                    dropped = true;
                } else if g0 / -g1 < alpha {
                    alpha = g0 / -g1;
                    blocking = Some((k, tangential));
                }
            }
        }
        if dropped {
            Ratio::Drop
        } else {
            Ratio::Step(alpha, blocking)
        }
    }

    /// Whether the active row after row `i` (a normal row) is its contact's
    /// tangential row.
    fn tangent_active(&self, i: usize) -> bool {
        let (k, _) = self.direct.active[i];
        self.direct.active.get(i + 1) == Some(&(k, true))
    }

    /// Applies α ΔP_A. Undoes it and returns false if the kinetic energy
    /// rose.
    fn apply(&mut self, alpha: f64) -> bool {
        let before = self.kinetic_energy();
        self.direct.saved_velocity.clone_from(&self.velocity);
        self.direct.saved_impulse.clear();
        for i in 0..self.direct.active.len() {
            let (k, tangential) = self.direct.active[i];
            let r = self.rows[k];
            let slot = usize::from(tangential);
            let p = self.impulse[k][slot];
            self.direct.saved_impulse.push(p);
            let step = p + alpha * self.direct.x[i];
            let new = if tangential { step } else { step.max(0.0) };
            let (dir, arm_a, arm_b) = Self::axis(&r, tangential);
            self.push(r.a, r.b, dir, [arm_a, arm_b], new - p);
            self.impulse[k][slot] = new;
        }
        if self.kinetic_energy() <= before {
            return true;
        }
        self.velocity.clone_from(&self.direct.saved_velocity);
        for (i, &(k, tangential)) in self.direct.active.iter().enumerate() {
            self.impulse[k][usize::from(tangential)] = self.direct.saved_impulse[i];
        }
        false
    }

    /// Kinetic energy of the movable bodies (J).
    pub(super) fn kinetic_energy(&self) -> f64 {
        let mut e = 0.0;
        for (s, v) in self.velocity.iter().enumerate() {
            if self.inv_mass[s] > 0.0 {
                e += (v[0] * v[0] + v[1] * v[1]) / self.inv_mass[s];
            }
            if self.inv_inertia[s] > 0.0 {
                e += v[2] * v[2] / self.inv_inertia[s];
            }
        }
        0.5 * e
    }
}

/// The outcome of the ratio test.
enum Ratio {
    /// A contact without load left A: solve again.
    Drop,
    /// Step by α; the row (contact, tangential) that reaches its bound
    /// first, if α < 1.
    Step(f64, Option<(usize, bool)>),
}
