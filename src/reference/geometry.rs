//! Contact candidates of a row (paper Sec. 2.1, Eqs. 2–13, generalised to every
//! corner–face pair a row needs): gap δ, normal and tangent, the Jacobian rows
//! W, N of Eq. 12 and the velocity terms Sⁿ, Sᵗ of Eq. 13.
//!
//! Conventions: a block's configuration is q = (x, y, φ) with φ counter-clockwise
//! (the paper's θ = −φ); a contact is a *corner* of one block against a *face*
//! of another block or the ground; the normal n points out of the face towards
//! the corner, the tangent is t = (−n_y, n_x) as in [`crate::impact::Contact`].
//! Then δ = n·(P − c) ≥ 0 is the gap, δ̇ = n·u with u the velocity of the corner
//! relative to the face material point under it, and v_t = t·u.

use crate::domino::Block;

/// Candidate slots per block for λ bottom points: slot p < λ is bottom point p
/// on the ground (p = 0 the heel, p = λ−1 the front corner A); slot λ the front
/// top corner B on the ground (a block lying on its face); slot λ+1 corner B of
/// block i on the back face of block i+1 (the paper's B_i); slot λ+2 the heel of
/// block i+1 on the front face of block i (used for the last pair only, see
/// the engine).
pub(crate) fn slots_per_block(lambda: usize) -> usize {
    lambda + 3
}

/// Which material a slot uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Surface {
    /// Block on ground (index 2 in Table 1).
    Ground,
    /// Block on block (index 1 in Table 1).
    Block,
}

/// The geometric state of one candidate.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Geom {
    /// Gap δ (m); negative is penetration.
    pub gap: f64,
    /// The corner, world (m).
    pub point: [f64; 2],
    /// Unit normal out of the face.
    pub normal: [f64; 2],
    /// Block owning the corner.
    pub corner: usize,
    /// Block owning the face; `None` for the ground.
    pub face: Option<usize>,
    /// The corner projects onto the face (always true on the ground).
    pub valid: bool,
}

/// Velocity-level terms of one candidate.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Kin {
    /// Normal Jacobian row for the corner body and the face body.
    pub jn: [[f64; 3]; 2],
    /// Tangential Jacobian row for the corner body and the face body.
    pub jt: [[f64; 3]; 2],
    /// δ̇ (m/s).
    pub gdot: f64,
    /// v_t (m/s).
    pub vt: f64,
    /// Sⁿ = d/dt(W)ᵀ q̇ (m/s²).
    pub sn: f64,
    /// Sᵗ (m/s²).
    pub st: f64,
}

#[inline]
fn rot(phi: f64, p: [f64; 2]) -> [f64; 2] {
    let (s, c) = turn(phi);
    [c * p[0] - s * p[1], s * p[0] + c * p[1]]
}

/// (sin φ, cos φ), remembered for the last few angles of this thread: the
/// candidates of one block ask for the same angle several times per
/// evaluation (one to three corners per slot, λ + 3 slots). Exact: a hit
/// returns what `sin_cos` gave for the same bits.
#[inline]
fn turn(phi: f64) -> (f64, f64) {
    use std::cell::Cell;
    const SLOTS: usize = 16;
    thread_local! {
        static SEEN: [Cell<(u64, f64, f64)>; SLOTS] =
            const { [const { Cell::new((u64::MAX, 0.0, 0.0)) }; SLOTS] };
    }
    let bits = phi.to_bits();
    let slot = ((bits ^ (bits >> 29) ^ (bits >> 47)) as usize) % SLOTS;
    SEEN.with(|seen| {
        let (key, s, c) = seen[slot].get();
        if key == bits {
            return (s, c);
        }
        let (s, c) = phi.sin_cos();
        seen[slot].set((bits, s, c));
        (s, c)
    })
}

#[inline]
pub(crate) fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

#[inline]
fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}

#[inline]
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// World position of body point `local` of a block at q.
#[inline]
pub(crate) fn world_point(q: [f64; 3], local: [f64; 2]) -> [f64; 2] {
    let r = rot(q[2], local);
    [q[0] + r[0], q[1] + r[1]]
}

/// Surface of a slot.
pub(crate) fn surface(slot: usize, lambda: usize) -> Surface {
    if slot <= lambda {
        Surface::Ground
    } else {
        Surface::Block
    }
}

/// Geometry of candidate `slot` of block `i`; `q(j)` gives block j's
/// configuration; `n` blocks in the row. `None` if the slot does not exist
/// (pair slots of the last block).
pub(crate) fn geom(
    block: &Block,
    lambda: usize,
    n: usize,
    i: usize,
    slot: usize,
    q: impl Fn(usize) -> [f64; 3],
) -> Option<Geom> {
    if slot <= lambda {
        let local = if slot < lambda {
            block.bottom_point(slot, lambda)
        } else {
            block.front_top()
        };
        let p = world_point(q(i), local);
        return Some(Geom {
            gap: p[1],
            point: p,
            normal: [0.0, 1.0],
            corner: i,
            face: None,
            valid: true,
        });
    }
    if i + 1 >= n {
        return None;
    }
    // (corner block, corner local, face block, face side ±1)
    let (cb, local, fb, side) = if slot == lambda + 1 {
        (i, block.front_top(), i + 1, -1.0)
    } else {
        (i + 1, block.back_bottom(), i, 1.0)
    };
    let p = world_point(q(cb), local);
    let qf = q(fb);
    let nrm = rot(qf[2], [side, 0.0]);
    let c = world_point(qf, [side * 0.5 * block.thickness, 0.0]);
    let r = [p[0] - c[0], p[1] - c[1]];
    let gap = dot(nrm, r);
    let along = dot(perp(nrm), r);
    Some(Geom {
        gap,
        point: p,
        normal: nrm,
        corner: cb,
        face: Some(fb),
        valid: along.abs() <= 0.5 * block.height && gap > -0.5 * block.thickness,
    })
}

/// Velocity terms of a candidate. `q(j)`, `v(j)` give block j's configuration
/// and velocity (vx, vy, ω); a fixed (frozen) block has v = 0.
pub(crate) fn kin(g: &Geom, q: impl Fn(usize) -> [f64; 3], v: impl Fn(usize) -> [f64; 3]) -> Kin {
    let n = g.normal;
    let t = perp(n);
    let qa = q(g.corner);
    let va = v(g.corner);
    let ra = [g.point[0] - qa[0], g.point[1] - qa[1]];
    let vpa = [va[0] - va[2] * ra[1], va[1] + va[2] * ra[0]];
    let (rb, vb) = match g.face {
        Some(f) => {
            let qb = q(f);
            ([g.point[0] - qb[0], g.point[1] - qb[1]], v(f))
        }
        None => ([0.0, 0.0], [0.0; 3]),
    };
    let vpb = [vb[0] - vb[2] * rb[1], vb[1] + vb[2] * rb[0]];
    let u = [vpa[0] - vpb[0], vpa[1] - vpb[1]];
    // ρ̇_b = velocity of the corner relative to the face body's centre
    let rbd = [vpa[0] - vb[0], vpa[1] - vb[1]];
    let wa = va[2];
    let wb = vb[2];
    let w = [
        -wa * wa * ra[0] + wb * rbd[1],
        -wa * wa * ra[1] - wb * rbd[0],
    ];
    let un = dot(n, u);
    let ut = dot(t, u);
    Kin {
        jn: [[n[0], n[1], cross(ra, n)], [-n[0], -n[1], -cross(rb, n)]],
        jt: [[t[0], t[1], cross(ra, t)], [-t[0], -t[1], -cross(rb, t)]],
        gdot: un,
        vt: ut,
        sn: wb * ut + dot(n, w),
        st: -wb * un + dot(t, w),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Two blocks in a generic configuration with generic velocities and
    // accelerations: δ̈ and v̇_t from central finite differences of δ(q(t)) and
    // v_t(q(t), q̇(t)) along a quadratic path must equal J q̈ + S (Eq. 13).
    #[test]
    fn jacobians_and_velocity_terms_match_finite_differences() {
        let block = Block::new(0.08, 0.0096);
        let lambda = 9;
        let q0 = [[0.003, 0.039, -0.6], [0.0262, 0.0395, -0.15]];
        let v0 = [[0.2, -0.1, -3.0], [0.05, 0.02, -1.3]];
        let a0 = [[1.0, -2.0, 15.0], [-0.5, 0.7, -8.0]];
        let at = |t: f64| {
            let mut q = [[0.0; 3]; 2];
            let mut v = [[0.0; 3]; 2];
            for b in 0..2 {
                for k in 0..3 {
                    q[b][k] = q0[b][k] + v0[b][k] * t + 0.5 * a0[b][k] * t * t;
                    v[b][k] = v0[b][k] + a0[b][k] * t;
                }
            }
            (q, v)
        };
        for slot in [0, 4, 8, 9, 10, 11] {
            let eval = |t: f64| {
                let (q, v) = at(t);
                let g = geom(&block, lambda, 2, 0, slot, |j| q[j]).unwrap();
                let k = kin(&g, |j| q[j], |j| v[j]);
                (g, k)
            };
            let h = 1e-4;
            let (gm, _) = eval(-h);
            let (g0, k0) = eval(0.0);
            let (gp, _) = eval(h);
            let gdot_fd = (gp.gap - gm.gap) / (2.0 * h);
            let gdd_fd = (gp.gap - 2.0 * g0.gap + gm.gap) / (h * h);
            assert!((gdot_fd - k0.gdot).abs() < 1e-6, "slot {slot}: δ̇");
            // J q̈ + S
            let mut jqdd = k0.sn;
            let mut jtqdd = k0.st;
            for k in 0..3 {
                jqdd += k0.jn[0][k] * a0[g0.corner][k];
                jtqdd += k0.jt[0][k] * a0[g0.corner][k];
                if let Some(f) = g0.face {
                    jqdd += k0.jn[1][k] * a0[f][k];
                    jtqdd += k0.jt[1][k] * a0[f][k];
                }
            }
            assert!(
                (gdd_fd - jqdd).abs() < 1e-4 * (1.0 + jqdd.abs()),
                "slot {slot}: δ̈ {gdd_fd} vs {jqdd}"
            );
            // v̇_t by differences of v_t
            let (_, km) = eval(-h);
            let (_, kp) = eval(h);
            let vtd_fd = (kp.vt - km.vt) / (2.0 * h);
            assert!(
                (vtd_fd - jtqdd).abs() < 1e-4 * (1.0 + jtqdd.abs()),
                "slot {slot}: v̇_t {vtd_fd} vs {jtqdd}"
            );
            // J q̇ = δ̇
            let (q, v) = at(0.0);
            let mut jv = 0.0;
            for k in 0..3 {
                jv += k0.jn[0][k] * v[g0.corner][k];
                if let Some(f) = g0.face {
                    jv += k0.jn[1][k] * v[f][k];
                }
            }
            let _ = q;
            assert!((jv - k0.gdot).abs() < 1e-12);
        }
    }

    #[test]
    fn upright_row_gaps() {
        let block = Block::new(0.08, 0.01);
        let pitch = 0.03;
        let q = |j: usize| [j as f64 * pitch, 0.04, 0.0];
        for p in 0..9 {
            assert!(geom(&block, 9, 2, 0, p, q).unwrap().gap.abs() < 1e-15);
        }
        let b = geom(&block, 9, 2, 0, 10, q).unwrap();
        assert!((b.gap - (pitch - 0.01)).abs() < 1e-15 && b.valid);
        assert_eq!(b.normal, [-1.0, 0.0]);
        assert!(geom(&block, 9, 2, 1, 10, q).is_none());
    }
}
