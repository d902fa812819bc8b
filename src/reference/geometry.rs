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

/// A corner of a block, body frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Corner {
    /// Back bottom (the heel).
    BackBottom,
    /// Front bottom (A, the pivot).
    FrontBottom,
    /// Front top (B, strikes the next block).
    FrontTop,
    /// Back top.
    BackTop,
}

/// A face of a block; its outward normal in the body frame is −x, +x, −y, +y.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Face {
    /// −x, facing the block behind.
    Back,
    /// +x, facing the block ahead (the direction of the wave).
    Front,
    /// −y, standing on the ground.
    Bottom,
    /// +y, the top end.
    Top,
}

/// Whose corner a pair slot of block i holds: block i's on a face of block
/// i+1 (`Behind`), or block i+1's on a face of block i (`Ahead`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Side {
    /// The corner is block i's, the face block i+1's.
    Behind,
    /// The corner is block i+1's, the face block i's.
    Ahead,
}

const CORNERS: [Corner; 4] = [
    Corner::BackBottom,
    Corner::FrontBottom,
    Corner::FrontTop,
    Corner::BackTop,
];
const FACES: [Face; 4] = [Face::Back, Face::Front, Face::Bottom, Face::Top];

/// Every corner of either block of a pair against every face of the other:
/// 2 × 4 × 4 contacts. The first two are the paper's B_i (block i's front
/// top corner on the back face of block i+1) and the heel of block i+1 on
/// the front face of block i; the other 30 follow in a fixed order.
pub(crate) const PAIR_SLOTS: [(Side, Corner, Face); 32] = pair_table();

const fn pair_table() -> [(Side, Corner, Face); 32] {
    let mut t = [(Side::Behind, Corner::FrontTop, Face::Back); 32];
    t[1] = (Side::Ahead, Corner::BackBottom, Face::Front);
    let mut k = 2;
    let mut s = 0;
    while s < 2 {
        let side = if s == 0 { Side::Behind } else { Side::Ahead };
        let mut c = 0;
        while c < 4 {
            let mut f = 0;
            while f < 4 {
                let e = (side, CORNERS[c], FACES[f]);
                let first = matches!(e, (Side::Behind, Corner::FrontTop, Face::Back));
                let heel = matches!(e, (Side::Ahead, Corner::BackBottom, Face::Front));
                if !first && !heel {
                    t[k] = e;
                    k += 1;
                }
                f += 1;
            }
            c += 1;
        }
        s += 1;
    }
    t
}

/// Candidate slots per block, for λ bottom points:
///
/// | slot | contact |
/// | --- | --- |
/// | p < λ | bottom point p on the ground (p = 0 the heel, p = λ−1 the front corner A) |
/// | λ | the front top corner B on the ground (a block lying on its face) |
/// | λ+1 | [`PAIR_SLOTS`]\[0\]: B of block i on the back face of block i+1 (the paper's B_i) |
/// | λ+2 | [`PAIR_SLOTS`]\[1\]: the heel of block i+1 on the front face of block i (the engine uses it for the last pair, or everywhere with `heel_contacts`) |
/// | λ+3 | the back top corner on the ground (a block lying on its back) |
/// | λ+4 … λ+33 | [`PAIR_SLOTS`]\[2…31\]: every other corner of blocks i and i+1 on every face of the other |
///
/// Beyond these, the slots of block i from `slots_per_block(λ)` on hold the
/// pairs with blocks that are not its neighbour ([`far_slot`]): pair k of
/// [`PAIR_SLOTS`] between block i and block i + d, d ≥ 2, with `Behind`
/// meaning block i's corner on block i + d's face.
pub(crate) fn slots_per_block(lambda: usize) -> usize {
    lambda + 4 + PAIR_SLOTS.len() - 2
}

/// The slot of block i that holds pair contact `k` of [`PAIR_SLOTS`]
/// between block i and block i + `offset`, `offset` ≥ 2 (blocks that are
/// not neighbours: a block lying flat, sliding back or rebounding can reach
/// one several places away).
#[inline]
pub(crate) fn far_slot(offset: usize, k: usize, lambda: usize) -> usize {
    debug_assert!(offset >= 2 && k < PAIR_SLOTS.len());
    slots_per_block(lambda) + (offset - 2) * PAIR_SLOTS.len() + k
}

/// The block that holds the face or corner facing block `i` in pair slot
/// `slot` of block i (i + 1 for a neighbour's slot, i + d for a far slot);
/// `None` for a ground slot.
#[inline]
pub(crate) fn partner(i: usize, slot: usize, lambda: usize) -> Option<usize> {
    pair_of(slot, lambda).map(|(offset, _)| i + offset)
}

/// The slot of block i that holds pair contact `k` of [`PAIR_SLOTS`].
#[inline]
pub(crate) fn pair_slot(k: usize, lambda: usize) -> usize {
    if k < 2 {
        lambda + 1 + k
    } else {
        lambda + 2 + k
    }
}

/// The pair contact a slot holds, if it is one: the offset d of the other
/// block (1 for the neighbour, ≥ 2 for a far slot) and the index into
/// [`PAIR_SLOTS`].
#[inline]
pub(crate) fn pair_of(slot: usize, lambda: usize) -> Option<(usize, usize)> {
    let near = slots_per_block(lambda);
    if slot == lambda + 1 || slot == lambda + 2 {
        Some((1, slot - lambda - 1))
    } else if slot >= near {
        let far = slot - near;
        Some((2 + far / PAIR_SLOTS.len(), far % PAIR_SLOTS.len()))
    } else if slot >= lambda + 4 {
        Some((1, slot - lambda - 2))
    } else {
        None
    }
}

/// The slot of the back top corner on the ground.
#[inline]
pub(crate) fn back_top_slot(lambda: usize) -> usize {
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
    const SLOTS: usize = 64;
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
    turned_point(q, turn(q[2]), local)
}

/// [`world_point`] with (sin φ, cos φ) of the block's angle given: the same
/// operations, so the same bits.
#[inline]
fn turned_point(q: [f64; 3], (s, c): (f64, f64), local: [f64; 2]) -> [f64; 2] {
    let r = [c * local[0] - s * local[1], s * local[0] + c * local[1]];
    [q[0] + r[0], q[1] + r[1]]
}

/// Surface of a slot.
pub(crate) fn surface(slot: usize, lambda: usize) -> Surface {
    if slot <= lambda || slot == back_top_slot(lambda) {
        Surface::Ground
    } else {
        Surface::Block
    }
}

/// A corner's position in the body frame.
#[inline]
fn corner_local(block: &Block, c: Corner) -> [f64; 2] {
    match c {
        Corner::BackBottom => block.back_bottom(),
        Corner::FrontBottom => block.front_bottom(),
        Corner::FrontTop => block.front_top(),
        Corner::BackTop => block.back_top(),
    }
}

/// A face in the body frame: outward unit normal, the sign and size of its
/// offset from the centre along that normal (half the thickness or half the
/// height), and the half length along it.
#[inline]
fn face_local(block: &Block, f: Face) -> ([f64; 2], f64, f64) {
    let (hd, hh) = (0.5 * block.thickness, 0.5 * block.height);
    match f {
        Face::Back => ([-1.0, 0.0], hd, hh),
        Face::Front => ([1.0, 0.0], hd, hh),
        Face::Bottom => ([0.0, -1.0], hh, hd),
        Face::Top => ([0.0, 1.0], hh, hd),
    }
}

/// Whether a corner at signed distance `gap` from a face (positive outside)
/// and `along` its tangent from the face's middle belongs to that face: it
/// projects onto the face, and it is outside, or inside the block with this
/// face the nearest (the separating axis of least penetration; the other
/// faces are at `2 depth + gap` and `half_length ∓ along`).
#[inline]
fn on_face(gap: f64, along: f64, depth: f64, half_length: f64) -> bool {
    let lateral = half_length - along.abs();
    lateral >= 0.0 && (gap >= 0.0 || (-gap <= depth && -gap <= lateral))
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
    let Some((offset, k)) = pair_of(slot, lambda) else {
        let local = if slot < lambda {
            block.bottom_point(slot, lambda)
        } else if slot == lambda {
            block.front_top()
        } else {
            block.back_top()
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
    };
    let j = i + offset;
    if j >= n {
        return None;
    }
    let (side, corner, face) = PAIR_SLOTS[k];
    let (cb, fb) = match side {
        Side::Behind => (i, j),
        Side::Ahead => (j, i),
    };
    let p = world_point(q(cb), corner_local(block, corner));
    let qf = q(fb);
    let (nl, depth, half_length) = face_local(block, face);
    let nrm = rot(qf[2], nl);
    let c = world_point(qf, [nl[0] * depth, nl[1] * depth]);
    let r = [p[0] - c[0], p[1] - c[1]];
    let gap = dot(nrm, r);
    let along = dot(perp(nrm), r);
    Some(Geom {
        gap,
        point: p,
        normal: nrm,
        corner: cb,
        face: Some(fb),
        valid: on_face(gap, along, depth, half_length),
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

/// The pair contacts k of [`PAIR_SLOTS`] between blocks i and j > i (at
/// `qi`, `qj`) that can be within `margin` (m) of closing, given to `f`: each
/// corner of either block taken into the other's frame, and, if it lies
/// within `margin` of that block's outline, its contact with the nearest
/// face (the one [`geom`] finds valid). A cheap filter: a pair of blocks
/// has at most eight such contacts, usually none.
pub(crate) fn near_pair_contacts(
    block: &Block,
    qi: [f64; 3],
    qj: [f64; 3],
    margin: f64,
    mut f: impl FnMut(usize),
) {
    let (hd, hh) = (0.5 * block.thickness, 0.5 * block.height);
    let (turn_i, turn_j) = (turn(qi[2]), turn(qj[2]));
    for (side, (qc, qf), (tc, tf)) in [
        (Side::Behind, (qi, qj), (turn_i, turn_j)),
        (Side::Ahead, (qj, qi), (turn_j, turn_i)),
    ] {
        let (s, c) = tf;
        for corner in CORNERS {
            // `world_point` with the corner block's turn looked up once
            let p = turned_point(qc, tc, corner_local(block, corner));
            let r = [p[0] - qf[0], p[1] - qf[1]];
            // the corner in the face block's frame
            let (u, v) = (c * r[0] + s * r[1], -s * r[0] + c * r[1]);
            let (ou, ov) = (u.abs() - hd, v.abs() - hh);
            if ou > margin || ov > margin {
                continue;
            }
            // outside: the face whose slab holds it; inside: the face of
            // least depth (back/front at −ou, bottom/top at −ov); beyond a
            // corner of the face block no face holds it ([`on_face`])
            let x_face = match (ou > 0.0, ov > 0.0) {
                (true, true) => continue,
                (true, false) => true,
                (false, true) => false,
                (false, false) => ou >= ov,
            };
            let face = match (x_face, u < 0.0, v < 0.0) {
                (true, true, _) => Face::Back,
                (true, false, _) => Face::Front,
                (false, _, true) => Face::Bottom,
                (false, _, false) => Face::Top,
            };
            if let Some(k) = PAIR_SLOTS.iter().position(|e| *e == (side, corner, face)) {
                f(k);
            }
        }
    }
}

/// The extent along x (m) of a block at `q`: its centre's x ∓ the half
/// width of its outline's projection, d/2 |cos φ| + h/2 |sin φ|.
#[inline]
pub(crate) fn x_extent(block: &Block, q: [f64; 3]) -> (f64, f64) {
    let (s, c) = turn(q[2]);
    let half = 0.5 * (block.thickness * c.abs() + block.height * s.abs());
    (q[0] - half, q[0] + half)
}

/// Whether two blocks at `qa`, `qb` can be within `margin` (m) of touching:
/// no face normal of either block separates their outlines by more than
/// `margin` (the separating-axis test, exact for two rectangles). The
/// outline of a block grown by `margin` reaches at most √2 `margin` further
/// along any axis, so a pair with a corner within `margin` of the other's
/// outline ([`near_pair_contacts`]) passes with `2 margin`.
#[inline]
pub(crate) fn outlines_within(block: &Block, qa: [f64; 3], qb: [f64; 3], margin: f64) -> bool {
    let (hd, hh) = (0.5 * block.thickness, 0.5 * block.height);
    let (sa, ca) = turn(qa[2]);
    let (sb, cb) = turn(qb[2]);
    // the relative angle: cos, sin of φb − φa
    let (c, s) = ((ca * cb + sa * sb).abs(), (sb * ca - sa * cb).abs());
    // the other block's half extent along one's own x and y axes
    let along_x = hd * c + hh * s;
    let along_y = hd * s + hh * c;
    let r = [qb[0] - qa[0], qb[1] - qa[1]];
    // the centre offset in a's frame, then in b's
    let (ua, va) = (ca * r[0] + sa * r[1], -sa * r[0] + ca * r[1]);
    let (ub, vb) = (cb * r[0] + sb * r[1], -sb * r[0] + cb * r[1]);
    ua.abs() <= hd + along_x + margin
        && va.abs() <= hh + along_y + margin
        && ub.abs() <= hd + along_x + margin
        && vb.abs() <= hh + along_y + margin
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
        for slot in 0..slots_per_block(lambda) {
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

    /// Every corner–face contact of a pair, checked against a brute-force
    /// search over random configurations: [`geom`] finds a corner on a face
    /// exactly when the corner, taken into the face block's frame, projects
    /// onto that face from outside or is inside with that face the nearest;
    /// and [`near_pair_contacts`] hands on every contact within its margin
    /// that [`geom`] finds valid, whose two blocks [`outlines_within`]
    /// passes.
    #[test]
    fn pair_contacts_match_a_brute_force_search() {
        let block = Block::new(0.08, 0.012);
        let (hd, hh) = (0.006, 0.04);
        let lambda = 5;
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut unit = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let margin = 1e-3 * block.height;
        let mut seen_valid = 0;
        for _ in 0..20_000 {
            let qi = [0.0, 0.04, (unit() - 0.5) * 7.0];
            let qj = [
                (unit() - 0.5) * 0.12,
                0.04 + (unit() - 0.5) * 0.1,
                (unit() - 0.5) * 7.0,
            ];
            let q = |j: usize| if j == 0 { qi } else { qj };
            let mut near = Vec::new();
            near_pair_contacts(&block, qi, qj, margin, |k| near.push(k));
            for k in 0..PAIR_SLOTS.len() {
                let g = geom(&block, lambda, 2, 0, pair_slot(k, lambda), q).unwrap();
                let (side, corner, face) = PAIR_SLOTS[k];
                let (qc, qf) = match side {
                    Side::Behind => (qi, qj),
                    Side::Ahead => (qj, qi),
                };
                // brute force: the corner in the face block's frame
                let p = world_point(qc, corner_local(&block, corner));
                let (s, c) = qf[2].sin_cos();
                let r = [p[0] - qf[0], p[1] - qf[1]];
                let (u, v) = (c * r[0] + s * r[1], -s * r[0] + c * r[1]);
                let depths = [u + hd, hd - u, v + hh, hh - v]; // back, front, bottom, top
                let f = face as usize;
                let inside = depths.iter().all(|d| *d > 0.0);
                let projects = if f < 2 { v.abs() <= hh } else { u.abs() <= hd };
                let nearest = depths.iter().all(|d| depths[f] <= *d);
                let expected = if inside {
                    nearest
                } else {
                    projects && depths[f] <= 0.0
                };
                // away from ties, where rounding decides
                let tie = depths.iter().any(|d| d.abs() < 1e-12)
                    || (0..4).any(|o| o != f && (depths[o] - depths[f]).abs() < 1e-12);
                if !tie {
                    assert_eq!(g.valid, expected, "k {k}: u {u} v {v} gap {}", g.gap);
                    if g.valid {
                        assert!((g.gap + depths[f]).abs() < 1e-12, "k {k}: gap {}", g.gap);
                    }
                }
                if g.valid {
                    seen_valid += 1;
                }
                if g.valid && g.gap <= 0.5 * margin && !tie {
                    assert!(outlines_within(&block, qi, qj, 2.0 * margin));
                    assert!(
                        near.contains(&k),
                        "k {k} valid at gap {} not handed on",
                        g.gap
                    );
                }
            }
        }
        assert!(seen_valid > 1000, "{seen_valid}");
    }

    /// A far slot (block i against block i + d) is the neighbour's pair
    /// slot with block i + d put where block i + 1 was: the same gap,
    /// point, normal and validity, and the same velocity terms; and
    /// [`pair_of`] and [`partner`] give back what [`far_slot`] encoded.
    #[test]
    fn far_slots_are_the_neighbour_pair_moved() {
        let block = Block::new(0.08, 0.0096);
        let lambda = 9;
        let near_q = [[0.003, 0.039, -0.6], [0.0262, 0.0395, -0.15]];
        let v = [[0.2, -0.1, -3.0], [0.05, 0.02, -1.3]];
        for d in 2..5 {
            let n = d + 1;
            let far_q = |j: usize| {
                if j == 0 {
                    near_q[0]
                } else if j == d {
                    near_q[1]
                } else {
                    [1.0 + j as f64, 0.04, 0.0]
                }
            };
            let far_v = |j: usize| if j == d { v[1] } else { v[0] };
            for k in 0..PAIR_SLOTS.len() {
                let slot = far_slot(d, k, lambda);
                assert_eq!(pair_of(slot, lambda), Some((d, k)));
                assert_eq!(partner(0, slot, lambda), Some(d));
                let g = geom(&block, lambda, n, 0, slot, far_q).unwrap();
                let gn = geom(&block, lambda, 2, 0, pair_slot(k, lambda), |j| near_q[j]).unwrap();
                assert_eq!(g.gap, gn.gap);
                assert_eq!(g.point, gn.point);
                assert_eq!(g.normal, gn.normal);
                assert_eq!(g.valid, gn.valid);
                let to_near = |j: usize| if j == d { 1 } else { j };
                assert_eq!(to_near(g.corner), gn.corner);
                assert_eq!(g.face.map(to_near), gn.face);
                let k1 = kin(&g, far_q, far_v);
                let k2 = kin(&gn, |j| near_q[j], |j| v[j]);
                assert_eq!(
                    (k1.gdot, k1.vt, k1.sn, k1.st),
                    (k2.gdot, k2.vt, k2.sn, k2.st)
                );
                // the slot does not exist for a row too short
                assert!(geom(&block, lambda, d, 0, slot, far_q).is_none());
            }
        }
        for k in 0..PAIR_SLOTS.len() {
            assert_eq!(pair_of(pair_slot(k, lambda), lambda), Some((1, k)));
        }
        assert_eq!(pair_of(back_top_slot(lambda), lambda), None);
    }

    /// [`x_extent`] is the range of the four corners' x, and
    /// [`outlines_within`] passes every pair of blocks with a corner of one
    /// inside the other, checked on random poses.
    #[test]
    fn extents_and_the_separating_axis_test_against_the_corners() {
        let block = Block::new(0.08, 0.012);
        let (hd, hh) = (0.006, 0.04);
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut unit = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let corners = |q: [f64; 3]| CORNERS.map(|c| world_point(q, corner_local(&block, c)));
        let inside = |p: [f64; 2], q: [f64; 3]| {
            let (s, c) = q[2].sin_cos();
            let r = [p[0] - q[0], p[1] - q[1]];
            let (u, v) = (c * r[0] + s * r[1], -s * r[0] + c * r[1]);
            u.abs() < hd && v.abs() < hh
        };
        let (mut overlapping, mut apart) = (0, 0);
        for _ in 0..20_000 {
            let qa = [0.0, 0.04, (unit() - 0.5) * 7.0];
            let qb = [
                (unit() - 0.5) * 0.2,
                0.04 + (unit() - 0.5) * 0.2,
                (unit() - 0.5) * 7.0,
            ];
            let (lo, hi) = x_extent(&block, qa);
            let xs = corners(qa).map(|p| p[0]);
            let (min, max) = xs
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(*x), b.max(*x)));
            assert!((lo - min).abs() < 1e-15 && (hi - max).abs() < 1e-15);
            let touch = corners(qa).iter().any(|p| inside(*p, qb))
                || corners(qb).iter().any(|p| inside(*p, qa));
            let within = outlines_within(&block, qa, qb, 0.0);
            if touch {
                assert!(within, "{qa:?} {qb:?}");
                overlapping += 1;
            }
            if !within {
                apart += 1;
                // separated: no point of a's outline (sampled along its
                // edges) lies inside b
                let c = corners(qa);
                for e in 0..4 {
                    let (p, q) = (c[e], c[(e + 1) % 4]);
                    for t in 0..=40 {
                        let t = t as f64 / 40.0;
                        let x = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
                        assert!(!inside(x, qb), "{qa:?} {qb:?}");
                    }
                }
            }
        }
        assert!(overlapping > 1000 && apart > 1000, "{overlapping} {apart}");
    }
}
