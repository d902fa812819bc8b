//! The Runge–Kutta pairs of the time-domain solver: their tableaus, stages,
//! error estimates and interpolants (stepped on the impact in rk.rs).
//!
//! Two embedded pairs, both first same as last (the last stage is evaluated
//! at the new state and is the next step's first), both with an
//! interpolant written as
//! y(θ) = r₁ + θ (r₂ + (1 − θ)(r₃ + θ (r₄ + (1 − θ) r₅))), which the event
//! stage searches for switches:
//!
//! - [`Dp54`]: the pair of Dormand and Prince (1980) of orders 5 and 4,
//!   seven stages, six evaluations per accepted step, with the continuous
//!   extension of order 4 given by Hairer, Nørsett and Wanner (*Solving
//!   Ordinary Differential Equations I*, 2nd ed., Sec. II.6, `contd5`).
//! - [`Bs32`]: the pair of Bogacki and Shampine (1989, "A 3(2) pair of
//!   Runge–Kutta formulas", Appl. Math. Lett. 2(4), 321–325; the pair of
//!   MATLAB's `ode23`, Shampine and Reichelt 1997) of orders 3 and 2, four
//!   stages, three evaluations per accepted step. Its interpolant is the
//!   cubic Hermite polynomial through y₀, y₁ and their slopes f₀, f₁ (r₅ =
//!   0), of order 3, the order of the step itself.

use crate::impact::dormand_prince;

/// An embedded first-same-as-last Runge–Kutta pair (compile-time tableau:
/// the stepping loop is monomorphised per pair).
pub(super) trait Pair {
    /// Stages, the last one at the new state.
    const STAGES: usize;
    /// Nodes c_s.
    const C: &'static [f64];
    /// a_sl (row s: its s coefficients, padded); the last row is the weights
    /// b of the higher order.
    const A: &'static [[f64; 6]];
    /// Error weights b − b̂.
    const E: &'static [f64];
    /// 1/(p̂ + 1), p̂ the lower order: the local error estimate scales as
    /// h^(p̂+1), so a step h·err^(−this) meets the tolerance.
    const EXPONENT: f64;
    /// Weights of the interpolant's last coefficient r₅ = h Σ d_s k_s
    /// (`None`: r₅ = 0, the cubic Hermite interpolant).
    const DENSE: Option<&'static [f64]>;
}

/// Dormand–Prince 5(4) (see the module docs).
pub(super) struct Dp54;

impl Pair for Dp54 {
    const STAGES: usize = 7;
    const C: &'static [f64] = &dormand_prince::C;
    const A: &'static [[f64; 6]] = &dormand_prince::A;
    const E: &'static [f64] = &dormand_prince::E;
    const EXPONENT: f64 = 0.2;
    const DENSE: Option<&'static [f64]> = Some(&dormand_prince::D);
}

/// Bogacki–Shampine 3(2) (see the module docs). Tableau (Bogacki and
/// Shampine 1989, Table 1): c = (0, 1/2, 3/4, 1); a₂₁ = 1/2; a₃₁ = 0,
/// a₃₂ = 3/4; b = a₄ = (2/9, 1/3, 4/9, 0); b̂ = (7/24, 1/4, 1/3, 1/8).
pub(super) struct Bs32;

/// The weights b of order 3 (the fourth stage's row).
const BS_B: [f64; 3] = [2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0];

impl Pair for Bs32 {
    const STAGES: usize = 4;
    const C: &'static [f64] = &[0.0, 0.5, 0.75, 1.0];
    const A: &'static [[f64; 6]] = &[
        [0.0; 6],
        [0.5, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.75, 0.0, 0.0, 0.0, 0.0],
        [BS_B[0], BS_B[1], BS_B[2], 0.0, 0.0, 0.0],
    ];
    /// b − b̂ = (2/9 − 7/24, 1/3 − 1/4, 4/9 − 1/3, −1/8).
    const E: &'static [f64] = &[-5.0 / 72.0, 1.0 / 12.0, 1.0 / 9.0, -1.0 / 8.0];
    const EXPONENT: f64 = 1.0 / 3.0;
    const DENSE: Option<&'static [f64]> = None;
}

/// Stage buffers of one step (all of the state's length).
#[derive(Debug, Default)]
pub(super) struct Rk {
    /// State at the step's start.
    pub y0: Vec<f64>,
    /// Stage derivatives k₁ … k_s (the last at the new state; a pair with
    /// fewer than seven stages leaves the rest unused).
    pub(super) k: [Vec<f64>; 7],
    pub(super) stage: Vec<f64>,
    /// The local error estimate of the velocities and compressions.
    pub(super) err: Vec<f64>,
    /// The new state (the higher order).
    pub y1: Vec<f64>,
    /// Step length of the last step (s).
    pub h: f64,
    /// k₁ holds dy/dt at `y0` (first same as last after an accepted step).
    pub fresh: bool,
    /// Interpolant coefficients r₁ … r₅ of the last step, once formed.
    dense: [Vec<f64>; 5],
    pub(super) dense_ready: bool,
    /// The pair's last stage and interpolant weights (set by `resize`).
    last: usize,
    dense_weights: Option<&'static [f64]>,
}

impl Rk {
    /// Sizes the buffers for a state of `len` and the pair `P`.
    pub fn resize<P: Pair>(&mut self, len: usize) {
        for v in self.k.iter_mut().chain(self.dense.iter_mut()) {
            v.resize(len, 0.0);
        }
        self.y0.resize(len, 0.0);
        self.stage.resize(len, 0.0);
        self.err.resize(len, 0.0);
        self.y1.resize(len, 0.0);
        self.fresh = false;
        self.last = P::STAGES - 1;
        self.dense_weights = P::DENSE;
    }

    /// The step was accepted whole: its end is the next step's start and
    /// its last stage the next step's first.
    pub fn advance(&mut self) {
        std::mem::swap(&mut self.y0, &mut self.y1);
        self.k.swap(0, self.last);
        self.fresh = true;
    }

    /// A component of the interpolated state at fraction θ ∈ [0, 1].
    #[inline]
    pub fn dense_at(&self, j: usize, theta: f64) -> f64 {
        let r = &self.dense;
        let s = 1.0 - theta;
        r[0][j] + theta * (r[1][j] + s * (r[2][j] + theta * (r[3][j] + s * r[4][j])))
    }

    /// The interpolant's coefficients of a linear functional Σ w_j y_j,
    /// given as (index, weight) pairs: the functional at θ is
    /// g₁ + θ (g₂ + (1 − θ)(g₃ + θ (g₄ + (1 − θ) g₅))).
    pub fn dense_functional(&self, terms: &[(usize, f64)]) -> [f64; 5] {
        let mut g = [0.0; 5];
        for &(j, w) in terms {
            for (m, gm) in g.iter_mut().enumerate() {
                *gm += w * self.dense[m][j];
            }
        }
        g
    }

    /// The whole interpolated state at θ into `out`.
    pub fn dense_state(&self, theta: f64, out: &mut [f64]) {
        for (j, o) in out.iter_mut().enumerate() {
            *o = self.dense_at(j, theta);
        }
    }

    /// Forms the interpolant of the last step (once per step).
    pub fn prepare_dense(&mut self) {
        if self.dense_ready {
            return;
        }
        let h = self.h;
        let [r1, r2, r3, r4, r5] = &mut self.dense;
        for j in 0..self.y0.len() {
            let (y0, y1) = (self.y0[j], self.y1[j]);
            let diff = y1 - y0;
            let first = h * self.k[0][j] - diff;
            r1[j] = y0;
            r2[j] = diff;
            r3[j] = first;
            r4[j] = diff - h * self.k[self.last][j] - first;
            r5[j] = match self.dense_weights {
                Some(weights) => {
                    let mut d = 0.0;
                    for (s, w) in weights.iter().enumerate() {
                        if *w != 0.0 {
                            d += w * self.k[s][j];
                        }
                    }
                    h * d
                }
                None => 0.0,
            };
        }
        self.dense_ready = true;
    }
}

/// y₀ + h Σ_l a_sl k_l over the components of `out`.
///
/// Summed stage by stage over contiguous slices (so that the loops
/// vectorise), each component in the order l = 0, 1, …, s − 1 from 0.0:
/// the same operations, in the same order, as a sum per component.
#[inline]
pub(super) fn stage_state<P: Pair>(
    out: &mut [f64],
    y0: &[f64],
    k: &[Vec<f64>; 7],
    s: usize,
    h: f64,
) {
    let n = out.len();
    out.fill(0.0);
    for (kl, &a) in k.iter().zip(&P::A[s]).take(s) {
        for (o, &v) in out.iter_mut().zip(&kl[..n]) {
            *o += a * v;
        }
    }
    for (o, &y) in out.iter_mut().zip(&y0[..n]) {
        *o = y + h * *o;
    }
}

/// h Σ_s (b_s − b̂_s) k_s over the components of `out` (the local error
/// estimate), summed as [`stage_state`] sums.
#[inline]
pub(super) fn error_estimate<P: Pair>(out: &mut [f64], k: &[Vec<f64>; 7], h: f64) {
    let n = out.len();
    out.fill(0.0);
    for (ks, &w) in k.iter().zip(P::E) {
        for (o, &v) in out.iter_mut().zip(&ks[..n]) {
            *o += w * v;
        }
    }
    for o in out.iter_mut() {
        *o *= h;
    }
}

/// Multiplies dy/dt by dt/dx (nothing to do for x = t; a NaN slope makes
/// the step's error NaN, so that it is rejected).
#[inline]
pub(super) fn scale(k: &mut [f64], slope: f64) {
    if slope != 1.0 {
        for v in k.iter_mut() {
            *v *= slope;
        }
    }
}
