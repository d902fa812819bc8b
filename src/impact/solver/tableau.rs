//! The Runge–Kutta pair of the time-domain solver: its tableau, stages,
//! error estimate and interpolant (stepped on the impact in rk.rs).
//!
//! The embedded pair of Dormand and Prince (1980) of orders 5 and 4 with
//! seven stages, the last evaluated at the new state (first same as last, so
//! six evaluations per accepted step), and the continuous extension of order
//! 4 given by Hairer, Nørsett and Wanner (*Solving Ordinary Differential
//! Equations I*, 2nd ed., Sec. II.6): the state anywhere inside the step from
//! five coefficient vectors, which the event stage searches for switches.

use crate::impact::dormand_prince::{A, D, E};

pub(super) use crate::impact::dormand_prince::C;

/// Stage buffers of one step (all of the state's length).
#[derive(Debug, Default)]
pub(super) struct Rk {
    /// State at the step's start.
    pub y0: Vec<f64>,
    /// Stage derivatives k₁ … k₇ (k₇ at the new state).
    pub(super) k: [Vec<f64>; 7],
    pub(super) stage: Vec<f64>,
    /// The local error estimate of the velocities and compressions.
    pub(super) err: Vec<f64>,
    /// The new state (order 5).
    pub y1: Vec<f64>,
    /// Step length of the last step (s).
    pub h: f64,
    /// k₁ holds dy/dt at `y0` (first same as last after an accepted step).
    pub fresh: bool,
    /// Interpolant coefficients r₁ … r₅ of the last step, once formed.
    dense: [Vec<f64>; 5],
    pub(super) dense_ready: bool,
}

impl Rk {
    pub fn resize(&mut self, len: usize) {
        for v in self.k.iter_mut().chain(self.dense.iter_mut()) {
            v.resize(len, 0.0);
        }
        self.y0.resize(len, 0.0);
        self.stage.resize(len, 0.0);
        self.err.resize(len, 0.0);
        self.y1.resize(len, 0.0);
        self.fresh = false;
    }

    /// The step was accepted whole: its end is the next step's start and
    /// k₇ its first stage.
    pub fn advance(&mut self) {
        std::mem::swap(&mut self.y0, &mut self.y1);
        self.k.swap(0, 6);
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
            r4[j] = diff - h * self.k[6][j] - first;
        }
        // r₅ = h Σ_s d_s k_s over the nonzero weights (d₂ = 0), in the
        // order of s
        let k = &self.k;
        let nonzero = [0, 2, 3, 4, 5, 6];
        const { assert!(D[1] == 0.0) };
        let n = r5.len();
        combine_slices(
            r5,
            None,
            nonzero.map(|s| &k[s][..n]),
            nonzero.map(|s| D[s]),
            h,
        );
        self.dense_ready = true;
    }
}

/// y₀ + h Σ_l a_sl k_l over the components of `out`.
///
/// Each component is summed in the order l = 0, 1, …, s − 1 from 0.0 (the
/// zero coefficient included), then y₀ + h · sum: the same operations in
/// the same order as a sum per component, fused into one pass over the
/// components with the sum kept in a register (the stage count is a
/// constant of each pass, so the terms unroll and the pass vectorises).
#[inline]
pub(super) fn stage_state(out: &mut [f64], y0: &[f64], k: &[Vec<f64>; 7], s: usize, h: f64) {
    let a = &A[s];
    match s {
        1 => combine::<1>(out, Some(y0), k, a, h),
        2 => combine::<2>(out, Some(y0), k, a, h),
        3 => combine::<3>(out, Some(y0), k, a, h),
        4 => combine::<4>(out, Some(y0), k, a, h),
        5 => combine::<5>(out, Some(y0), k, a, h),
        6 => combine::<6>(out, Some(y0), k, a, h),
        _ => unreachable!("stage {s} of seven"),
    }
}

/// h Σ_s (b_s − b̂_s) k_s over the components of `out` (the local error
/// estimate), summed per component in the order s = 0, …, 6 from 0.0, then
/// times h.
#[inline]
pub(super) fn error_estimate(out: &mut [f64], k: &[Vec<f64>; 7], h: f64) {
    combine::<7>(out, None, k, &E, h);
}

/// out_j = y0_j + h Σ_{l<S} w_l k_l,j, or h · Σ without `y0` (the sum from
/// 0.0, in the order of l).
#[inline(always)]
fn combine<const S: usize>(
    out: &mut [f64],
    y0: Option<&[f64]>,
    k: &[Vec<f64>; 7],
    w: &[f64],
    h: f64,
) {
    let n = out.len();
    let ks: [&[f64]; S] = std::array::from_fn(|l| &k[l][..n]);
    let w: [f64; S] = std::array::from_fn(|l| w[l]);
    combine_slices(out, y0, ks, w, h);
}

/// [`combine`] over the given terms (each of `out`'s length).
#[inline(always)]
fn combine_slices<const S: usize>(
    out: &mut [f64],
    y0: Option<&[f64]>,
    ks: [&[f64]; S],
    w: [f64; S],
    h: f64,
) {
    let n = out.len();
    let sum = |j: usize| {
        let mut o = 0.0;
        for l in 0..S {
            o += w[l] * ks[l][j];
        }
        o
    };
    match y0 {
        Some(y0) => {
            let y0 = &y0[..n];
            for (j, (o, &y)) in out.iter_mut().zip(y0).enumerate() {
                *o = y + h * sum(j);
            }
        }
        None => {
            for (j, o) in out.iter_mut().enumerate() {
                *o = sum(j) * h;
            }
        }
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
