//! The direct stage of the plastic solve: the whole impact as one linear
//! complementarity problem, solved by Lemke's method (lemke.rs) when the
//! Gauss–Seidel sweeps have not converged within
//! [`PlasticSolver::DIRECT_AFTER`] sweeps.
//!
//! Unknowns (the planar friction cone is exactly two linear inequalities,
//! so the problem is linear; Stewart & Trinkle, "An implicit
//! time-stepping scheme for rigid body dynamics with inelastic collisions
//! and Coulomb friction", 1996): for every contact i its normal impulse
//! P_n,i, and for every contact with friction the two halves of its
//! tangential impulse P_t,i = β⁺_i − β⁻_i and a slip speed γ_i:
//!
//! * w_n = δ̇'_n = δ̇_n + W_nn P_n + W_nt P_t ≥ 0 ⊥ P_n ≥ 0 (no approach
//!   after the impact, P_n = 0 where the contact separates);
//! * γ + δ̇'_t ≥ 0 ⊥ β⁺ ≥ 0 and γ − δ̇'_t ≥ 0 ⊥ β⁻ ≥ 0, with δ̇'_t =
//!   δ̇_t + W_tn P_n + W_tt P_t (friction opposes the slip);
//! * μ P_n − β⁺ − β⁻ ≥ 0 ⊥ γ ≥ 0 (|P_t| ≤ μ P_n, and = μ P_n where the
//!   contact slips, at speed γ = |δ̇'_t|),
//!
//! with W = J M⁻¹ Jᵀ the Delassus operator of the contact rows (1/kg) and
//! μ the contact's sticking coefficient μ_s. Its answer is a plastic
//! impact with Coulomb friction at one coefficient: a contact sticks while
//! its friction stays within μ_s P_n, as in the sweeps, and one that slips
//! does so at μ_s P_n where the sweeps take μ P_n (μ ≤ μ_s: up to
//! (μ_s − μ) P_n more tangential impulse on a sliding contact, energy
//! removed, never added). Measured on the pile scene, solving it with μ
//! instead let sticking contacts slip between μ P_n and μ_s P_n, and the
//! pile moved on for longer afterwards (Rapier's steps cost twice as
//! much). Where rounding defeats the problem at μ_s (one of the thousand
//! random stacks of the tests: a pivot of 2·10⁻¹⁰ in a degenerate basis)
//! it is solved again at μ, a Coulomb law as well. It never raises the
//! kinetic energy: the normal impulses do no
//! work at the end velocities and friction only removes energy. A
//! contact with μ = ∞ (no slip) has no such row; an impact with one stays
//! with the sweeps.
//!
//! The answer is checked before it replaces the sweeps' (finite, no
//! contact approaching faster than [`PlasticSolver::DIRECT_APPROACH`] of
//! the impact's speed, no energy gained); otherwise the sweeps go on.

use super::lemke::Lemke;
use super::{PlasticSolver, Row};

/// Buffers of the direct stage.
#[derive(Debug, Default)]
pub(super) struct Direct {
    lemke: Lemke,
    /// The rows whose bodies can move (the others take no impulse), by
    /// row index.
    normal: Vec<usize>,
    /// Those of them with friction, by their place in `normal`.
    friction: Vec<usize>,
    /// The problem: M (row-major), q, z.
    m: Vec<f64>,
    q: Vec<f64>,
    z: Vec<f64>,
    /// The unknowns' scales c (the problem is solved for z / c).
    scale: Vec<f64>,
    /// One row's couplings to every normal row and to every friction
    /// row's tangent ([`PlasticSolver::couplings`]).
    w_n: Vec<f64>,
    w_t: Vec<f64>,
}

/// How a contact row `r` reads body slot `k`: −1 for its first body, +1
/// for its second, 0 otherwise.
#[inline]
fn side(r: &Row, k: usize) -> f64 {
    if k == r.b {
        1.0
    } else if k == r.a {
        -1.0
    } else {
        0.0
    }
}

impl PlasticSolver {
    /// Unknowns of the direct stage at most (its tableau has n (2n + 2)
    /// entries, and a pivot updates them all): larger impacts stay with the
    /// sweeps.
    pub const DIRECT_MAX_UNKNOWNS: usize = 160;
    /// Sweeps before the direct stage is tried: a solve that converges
    /// within them never pays for the direct stage.
    pub const DIRECT_AFTER: usize = 32;
    /// The direct stage's answer is taken only if no contact then
    /// approaches faster than this fraction of the impact's largest
    /// approach speed (dimensionless).
    pub const DIRECT_APPROACH: f64 = 1e-9;

    /// W between row `i` along (`di`, arms `ai`) and row `j` along (`dj`,
    /// arms `aj`): the rate change of the first per unit impulse of the
    /// second (1/kg).
    fn coupling(
        &self,
        ri: &Row,
        di: [f64; 2],
        ai: [f64; 2],
        rj: &Row,
        dj: [f64; 2],
        aj: [f64; 2],
    ) -> f64 {
        let dot = di[0] * dj[0] + di[1] * dj[1];
        let mut w = 0.0;
        for (k, arm_j) in [(rj.a, aj[0]), (rj.b, aj[1])] {
            let s = side(ri, k) * side(rj, k);
            if s != 0.0 {
                let arm_i = if k == ri.a { ai[0] } else { ai[1] };
                w += s * (self.inv_mass[k] * dot + self.inv_inertia[k] * arm_i * arm_j);
            }
        }
        w
    }

    /// W between row `ri` along (`di`, arms `ai`) and every normal row
    /// (into `d.w_n`) and every friction row's tangent (into `d.w_t`).
    fn couplings(&self, d: &mut Direct, ri: &Row, di: [f64; 2], ai: [f64; 2]) {
        d.w_n.clear();
        d.w_n.extend(d.normal.iter().map(|&col| {
            let rj = &self.rows[col];
            self.coupling(ri, di, ai, rj, rj.n, [rj.a_rn, rj.b_rn])
        }));
        d.w_t.clear();
        d.w_t.extend(d.friction.iter().map(|&j| {
            let rj = &self.rows[d.normal[j]];
            self.coupling(ri, di, ai, rj, rj.t, [rj.a_rt, rj.b_rt])
        }));
    }

    /// Tries the direct stage from the velocities the impact started with
    /// (`self.start`); on success the solver's velocities and impulses are
    /// its answer and the pivots taken are returned, otherwise the sweeps'
    /// state is put back.
    pub(super) fn solve_direct(&mut self) -> Option<usize> {
        if self.rows.iter().any(|r| r.stick_friction.is_infinite()) {
            return None;
        }
        self.keep_swept();
        let mut direct = std::mem::take(&mut self.direct);
        direct.normal.clear();
        direct
            .normal
            .extend((0..self.rows.len()).filter(|&k| self.rows[k].inv_w_nn > 0.0));
        direct.friction.clear();
        let with_friction =
            (0..direct.normal.len()).filter(|&i| self.rows[direct.normal[i]].friction > 0.0);
        direct.friction.extend(with_friction);
        let n = direct.normal.len() + 3 * direct.friction.len();
        let mut answer = None;
        if n <= Self::DIRECT_MAX_UNKNOWNS {
            // at μ_s first; should rounding defeat that problem, at μ
            // (another problem, also a Coulomb law; see the module's text)
            let kinetic_differs = self.rows.iter().any(|r| r.friction != r.stick_friction);
            for sticking in [true, false] {
                if !sticking && !kinetic_differs {
                    break;
                }
                self.assemble(&mut direct, n, sticking);
                direct.z.resize(n, 0.0);
                let solved = direct.lemke.solve(&direct.m, &direct.q, &mut direct.z);
                for (z, c) in direct.z.iter_mut().zip(&direct.scale) {
                    *z *= c;
                }
                answer = solved.ok().filter(|_| self.take_direct(&direct, sticking));
                if answer.is_some() {
                    break;
                }
            }
        }
        self.direct = direct;
        if answer.is_none() {
            self.restore_swept();
        }
        answer
    }

    /// Fills M and q (see the module's text) from the start velocities,
    /// with μ_s (`sticking`) or μ as the friction coefficient.
    fn assemble(&mut self, d: &mut Direct, n: usize, sticking: bool) {
        self.velocity.copy_from_slice(&self.start);
        let rows = d.normal.len();
        let f = d.friction.len();
        d.m.clear();
        d.m.resize(n * n, 0.0);
        d.q.clear();
        d.q.resize(n, 0.0);
        // P_n rows: [W_nn | W_nt | −W_nt | 0]
        for i in 0..rows {
            let ri = self.rows[d.normal[i]];
            d.q[i] = self.rate(&ri, ri.n, ri.a_rn, ri.b_rn);
            self.couplings(d, &ri, ri.n, [ri.a_rn, ri.b_rn]);
            let row = &mut d.m[i * n..(i + 1) * n];
            row[..rows].copy_from_slice(&d.w_n);
            for (l, &w) in d.w_t.iter().enumerate() {
                row[rows + l] = w;
                row[rows + f + l] = -w;
            }
        }
        // β⁺ rows: [W_tn | W_tt | −W_tt | I], β⁻ rows their negatives but
        // for the same +I, γ rows [μ | −I | −I | 0]
        for k in 0..f {
            let i = d.friction[k];
            let ri = self.rows[d.normal[i]];
            let (plus, minus, slip) = (rows + k, rows + f + k, rows + 2 * f + k);
            let vt = self.rate(&ri, ri.t, ri.a_rt, ri.b_rt);
            d.q[plus] = vt;
            d.q[minus] = -vt;
            self.couplings(d, &ri, ri.t, [ri.a_rt, ri.b_rt]);
            for (j, &w) in d.w_n.iter().enumerate() {
                d.m[plus * n + j] = w;
                d.m[minus * n + j] = -w;
            }
            for (l, &w) in d.w_t.iter().enumerate() {
                d.m[plus * n + rows + l] = w;
                d.m[plus * n + rows + f + l] = -w;
                d.m[minus * n + rows + l] = -w;
                d.m[minus * n + rows + f + l] = w;
            }
            d.m[plus * n + slip] = 1.0;
            d.m[minus * n + slip] = 1.0;
            d.m[slip * n + i] = if sticking {
                ri.stick_friction
            } else {
                ri.friction
            };
            d.m[slip * n + plus] = -1.0;
            d.m[slip * n + minus] = -1.0;
        }
        Self::equilibrate(d, rows, n);
    }

    /// Scales the problem so that W's diagonal is 1 (the entries of the
    /// slip rows then 1 and about μ): unknown k is solved as z_k / c_k and
    /// its row multiplied by c_k, with c = 1/√W_nn for a normal impulse,
    /// 1/√W_tt for a half of a tangential one and √W_tt for a slip speed.
    /// Positive scalings of z and w keep the complementarity, and the
    /// pivots then compare numbers of one size whatever the masses.
    fn equilibrate(d: &mut Direct, rows: usize, n: usize) {
        let f = d.friction.len();
        d.scale.clear();
        d.scale.resize(n, 1.0);
        let inverse_root = |w: f64| if w > 0.0 { 1.0 / w.sqrt() } else { 1.0 };
        for i in 0..rows {
            d.scale[i] = inverse_root(d.m[i * n + i]);
        }
        for k in 0..f {
            let plus = rows + k;
            let c = inverse_root(d.m[plus * n + plus]);
            d.scale[plus] = c;
            d.scale[rows + f + k] = c;
            d.scale[rows + 2 * f + k] = 1.0 / c;
        }
        for i in 0..n {
            let ci = d.scale[i];
            d.q[i] *= ci;
            for (mij, cj) in d.m[i * n..(i + 1) * n].iter_mut().zip(&d.scale) {
                *mij *= ci * cj;
            }
        }
    }

    /// Applies the direct stage's impulses to the start velocities; whether
    /// the answer is finite and leaves no contact approaching faster than
    /// [`PlasticSolver::DIRECT_APPROACH`] of the impact's speed.
    fn take_direct(&mut self, d: &Direct, sticking: bool) -> bool {
        let rows = d.normal.len();
        let f = d.friction.len();
        self.velocity.copy_from_slice(&self.start);
        self.impulse.fill([0.0; 2]);
        for (i, &k) in d.normal.iter().enumerate() {
            let r = self.rows[k];
            let pn = d.z[i];
            self.push(r.a, r.b, r.n, [r.a_rn, r.b_rn], pn);
            self.impulse[k][0] = pn;
        }
        for (l, &i) in d.friction.iter().enumerate() {
            let k = d.normal[i];
            let r = self.rows[k];
            // the cone holds to the tableau's rounding; clamp that away
            let mu = if sticking {
                r.stick_friction
            } else {
                r.friction
            };
            let bound = mu * self.impulse[k][0];
            let pt = (d.z[rows + l] - d.z[rows + f + l]).clamp(-bound, bound);
            self.push(r.a, r.b, r.t, [r.a_rt, r.b_rt], pt);
            self.impulse[k][1] = pt;
        }
        let finite = self.velocity.iter().flatten().all(|v| v.is_finite());
        finite && self.worst_approach() <= Self::DIRECT_APPROACH * self.speed
    }

    /// Keeps the sweeps' velocities and impulses aside.
    pub(super) fn keep_swept(&mut self) {
        self.swept_velocity.clear();
        self.swept_velocity.extend_from_slice(&self.velocity);
        self.swept_impulse.clear();
        self.swept_impulse.extend_from_slice(&self.impulse);
    }

    /// Puts the sweeps' velocities and impulses back.
    pub(super) fn restore_swept(&mut self) {
        self.velocity.copy_from_slice(&self.swept_velocity);
        self.impulse.copy_from_slice(&self.swept_impulse);
    }

    /// The direct stage's cost in sweeps of the impact's contacts, for the
    /// work budget: its pivots update n (2n + 2) tableau entries each, and
    /// the assembly, the ratio tests, the refinement and the checks are
    /// counted as ten entries per entry of M. Calibrated by callgrind on
    /// the pile scene's 63 direct solves (`topple scene
    /// assets/scenes/pile-boxes.toml`): the stage took 87·10⁶ instructions
    /// for 21.0·10⁶ such entries (4.15 an entry), a sweep 249 a contact,
    /// so a contact's sweep is worth 60 entries.
    pub(super) fn direct_work(&self, pivots: usize) -> usize {
        let n = self.direct.normal.len() + 3 * self.direct.friction.len();
        self.direct_work_of(n, pivots)
    }

    /// [`Self::direct_work`] of a problem of `n` unknowns solved in
    /// `pivots` pivots.
    pub(super) fn direct_work_of(&self, n: usize, pivots: usize) -> usize {
        const ENTRIES_PER_CONTACT_SWEEP: usize = 60;
        let entries = pivots * n * (2 * n + 2) + 10 * n * n;
        entries.div_ceil(ENTRIES_PER_CONTACT_SWEEP * self.rows.len().max(1))
    }

    /// The rows the direct stage would solve for: those whose bodies can
    /// move, and how many of them have friction.
    pub(super) fn direct_unknowns(&self) -> (usize, usize) {
        self.rows
            .iter()
            .filter(|r| r.inv_w_nn > 0.0)
            .fold((0, 0), |(n, f), r| {
                (n + 1, f + usize::from(r.friction > 0.0))
            })
    }
}
