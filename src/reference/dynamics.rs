//! The smooth phase (paper Eqs. 17–20): contact forces of the closed contacts
//! for a given contact *mode* (which contacts press, which stick, which slide
//! and in which direction), the accelerations they give, the active-set search
//! that finds the mode satisfying the complementarity conditions (Eqs. 18–20),
//! and the projections that keep persistent contacts exactly closed.
//!
//! Units: SI (m, s, kg, N). The Delassus matrix W M⁻¹ W is banded (a contact
//! couples two neighbouring blocks, rarely two a few places apart) and solved
//! by [`Band`] in O(contacts).

use super::band::Band;
use super::geometry::{geom, kin, Geom, Kin, Surface};
use crate::domino::{Ground, RowParams};

/// Friction state of a pressing contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Mode {
    /// No friction (μ = 0 at this surface).
    Frictionless,
    /// Tangential relative velocity held at zero, |F_t| ≤ μ_s F_n.
    Stick,
    /// Sliding with the sign `dir` = sgn v_t: F_t = −dir μ F_n.
    Slide(f64),
}

/// A pressing (active) contact: slot `slot` of block `block` in `mode`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Active {
    pub block: usize,
    pub slot: usize,
    pub mode: Mode,
}

/// Read-only view of the row: blocks lo..hi move and their state is in `y`
/// (x, y, φ, ẋ, ẏ, ω per block); the others are fixed at `pos`.
#[derive(Clone, Copy)]
pub(crate) struct View<'a> {
    pub lo: usize,
    pub hi: usize,
    pub y: &'a [f64],
    pub pos: &'a [[f64; 3]],
}

impl View<'_> {
    #[inline]
    pub fn q(&self, j: usize) -> [f64; 3] {
        if j >= self.lo && j < self.hi {
            let k = 6 * (j - self.lo);
            [self.y[k], self.y[k + 1], self.y[k + 2]]
        } else {
            self.pos[j]
        }
    }
    #[inline]
    pub fn v(&self, j: usize) -> [f64; 3] {
        if j >= self.lo && j < self.hi {
            let k = 6 * (j - self.lo) + 3;
            [self.y[k], self.y[k + 1], self.y[k + 2]]
        } else {
            [0.0; 3]
        }
    }
    #[inline]
    pub fn local(&self, j: Option<usize>) -> Option<usize> {
        j.filter(|&j| j >= self.lo && j < self.hi)
            .map(|j| j - self.lo)
    }
}

/// One unknown of a contact system: its free bodies (window-local), the
/// Jacobian row it constrains and the generalised-force column it acts by.
#[derive(Clone, Copy, Debug, Default)]
struct Unknown {
    bodies: [Option<usize>; 2],
    row: [[f64; 3]; 2],
    col: [[f64; 3]; 2],
}

/// Results and buffers of the contact-force computation.
#[derive(Debug, Default)]
pub(crate) struct Dynamics {
    band: Band,
    unknowns: Vec<Unknown>,
    /// M⁻¹ applied to each unknown's columns (`assemble`).
    minv_cols: Vec<[[f64; 3]; 2]>,
    geoms: Vec<Geom>,
    kins: Vec<Kin>,
    /// Normal force of each active contact (N).
    pub fn_: Vec<f64>,
    /// Tangential force of each active contact (N), along t.
    pub ft: Vec<f64>,
    /// Accelerations of the moving blocks (ẍ, ÿ, φ̈).
    pub acc: Vec<[f64; 3]>,
    /// Power of the contact forces Σ F_n δ̇ + F_t v_t (W); ≤ 0.
    pub power: f64,
    /// Tangential velocity of each active contact (m/s).
    pub vt: Vec<f64>,
    /// Gap of each active contact (m).
    pub gap: Vec<f64>,
    /// Whether each active contact still projects onto its face.
    pub valid: Vec<bool>,
    // buffers of `project`
    proj_start: Vec<f64>,
    /// Geometry and kinematics of each contact of the projection's active
    /// list at its start state, aligned with that list.
    proj_geoms: Vec<(Geom, Kin)>,
    proj_owner: Vec<(usize, bool)>,
    proj_drop: Vec<usize>,
    // buffers of `relaxed_forces`
    relax_rows: Vec<RelaxRow>,
    relax_acc: Vec<[f64; 3]>,
    /// The forces [F_n, F_t] of `relaxed_forces`, kept for its caller.
    relax_forces: Vec<[f64; 2]>,
}

/// One candidate contact in the relaxation of [`Dynamics::relaxed_forces`]:
/// its window-local bodies, Jacobian rows, velocity terms, the inverse of
/// its diagonal Delassus entries, its friction and its forces.
#[derive(Clone, Copy, Debug, Default)]
struct RelaxRow {
    bodies: [Option<usize>; 2],
    jn: [[f64; 3]; 2],
    jt: [[f64; 3]; 2],
    sn: f64,
    st: f64,
    inv_wnn: f64,
    inv_wtt: f64,
    mu: f64,
    mus: f64,
    /// Slipping faster than the stick threshold: sliding friction along −v_t.
    slip: Option<f64>,
    fnn: f64,
    ft: f64,
}

/// Constants of the row needed by the dynamics.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RowConst {
    pub p: RowParams,
    pub n: usize,
    pub inv_m: f64,
    pub inv_i: f64,
    /// Relative Tikhonov regularisation of the Delassus diagonal, for
    /// redundant contact sets (a block standing on λ points).
    pub reg: f64,
}

impl RowConst {
    pub fn new(p: RowParams, n: usize) -> Self {
        RowConst {
            p,
            n,
            inv_m: 1.0 / p.block.mass,
            inv_i: 1.0 / p.block.inertia(),
            reg: 1e-10,
        }
    }
    /// Sliding and sticking friction (μ, μ_s) of a slot in the smooth
    /// phase; both are ∞ on a no-slip ground ([`Ground::NoSlip`]), whose
    /// contacts are always in [`Mode::Stick`].
    #[inline]
    pub fn mu(&self, slot: usize) -> (f64, f64) {
        match super::geometry::surface(slot, self.p.lambda_points) {
            Surface::Ground if self.p.ground == Ground::NoSlip => (f64::INFINITY, f64::INFINITY),
            Surface::Ground => (self.p.mu2, self.p.mu2_stick),
            Surface::Block => (self.p.mu1, self.p.mu1_stick),
        }
    }

    /// How much the tangential force of a sticking contact exceeds its
    /// limit, |F_t| − μ_s F_n (N), for the mode search and the stick → slip
    /// event; −∞ without a limit (μ_s = ∞).
    #[inline]
    pub fn stick_excess(&self, slot: usize, ft: f64, fnn: f64) -> f64 {
        let (_, mus) = self.mu(slot);
        if mus == f64::INFINITY {
            f64::NEG_INFINITY
        } else {
            ft.abs() - mus * fnn
        }
    }
    #[inline]
    pub fn geom(&self, view: &View, block: usize, slot: usize) -> Option<Geom> {
        geom(
            &self.p.block,
            self.p.lambda_points,
            self.n,
            block,
            slot,
            |j| view.q(j),
        )
    }
    #[inline]
    pub fn kin(&self, view: &View, g: &Geom) -> Kin {
        kin(g, |j| view.q(j), |j| view.v(j))
    }
    #[inline]
    fn minv(&self, a: [f64; 3]) -> [f64; 3] {
        [a[0] * self.inv_m, a[1] * self.inv_m, a[2] * self.inv_i]
    }
}

#[inline]
/// The stuck contacts among `pulled` (indices into `active`) that slip at
/// all and may (μ_s finite) become sliding, along their slip v_t, or
/// frictionless where μ = 0 ([`Dynamics::project`]). Returns whether any did.
fn release_sticks(rc: &RowConst, view: &View, active: &mut [Active], pulled: &[usize]) -> bool {
    let mut released = false;
    for &c in pulled {
        let a = &mut active[c];
        let (mu, mus) = rc.mu(a.slot);
        if a.mode != Mode::Stick || !mus.is_finite() {
            continue;
        }
        let Some(g) = rc.geom(view, a.block, a.slot) else {
            continue;
        };
        let vt = rc.kin(view, &g).vt;
        if vt == 0.0 {
            continue;
        }
        a.mode = if mu > 0.0 {
            Mode::Slide(vt.signum())
        } else {
            Mode::Frictionless
        };
        released = true;
    }
    released
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn span(u: &Unknown) -> (usize, usize) {
    let mut lo = usize::MAX;
    let mut hi = 0;
    for b in u.bodies.iter().flatten() {
        lo = lo.min(*b);
        hi = hi.max(*b);
    }
    (lo, hi)
}

impl Dynamics {
    /// The buffer for [`Dynamics::relaxed_forces`]' output, emptied; give
    /// it back with [`Dynamics::keep_relax_forces`] (no allocation per
    /// call once it has grown).
    pub(crate) fn take_relax_forces(&mut self) -> Vec<[f64; 2]> {
        let mut v = std::mem::take(&mut self.relax_forces);
        v.clear();
        v
    }

    /// Keeps `forces` as the buffer of the next [`Dynamics::take_relax_forces`].
    pub(crate) fn keep_relax_forces(&mut self, forces: Vec<[f64; 2]>) {
        self.relax_forces = forces;
    }

    /// Assembles A = J M⁻¹ Cᵀ (+ reg · diag) of the current unknowns into the
    /// band (rhs untouched except resized) and returns false if nothing to do.
    fn assemble(&mut self, rc: &RowConst) {
        let m = self.unknowns.len();
        // The unknowns come sorted by the first block of their spans: every
        // contact is between moving blocks (a contact with a frozen block is
        // never active) and listed under its lower block, also between
        // blocks that are not neighbours. So the scan of each row can stop
        // at the first unknown beyond its span.
        debug_assert!(self
            .unknowns
            .windows(2)
            .all(|w| span(&w[0]).0 <= span(&w[1]).0));
        let mut bw = 0;
        for r in 0..m {
            let (_, hr) = span(&self.unknowns[r]);
            for s in r + 1..m {
                let (ls, _) = span(&self.unknowns[s]);
                if ls > hr {
                    break;
                }
                bw = bw.max(s - r);
            }
        }
        self.band.reset_matrix(m, bw, bw);
        self.band.rhs.resize(m, 0.0);
        // M⁻¹ Cᵀ of every unknown once, not once per entry of its column
        self.minv_cols.clear();
        self.minv_cols.extend(
            self.unknowns
                .iter()
                .map(|u| [rc.minv(u.col[0]), rc.minv(u.col[1])]),
        );
        for r in 0..m {
            let ur = self.unknowns[r];
            let lo = r.saturating_sub(bw);
            let hi = (r + bw).min(m - 1);
            let mut diag = 0.0;
            for s in lo..=hi {
                let ub = self.unknowns[s].bodies;
                let cols = &self.minv_cols[s];
                // Σ over the bodies the two unknowns share, in the order
                // (a, b) = (0, 0), (0, 1), (1, 0), (1, 1)
                let mut v = 0.0;
                for a in 0..2 {
                    let Some(ba) = ur.bodies[a] else { continue };
                    if ub[0] == Some(ba) {
                        v += dot3(ur.row[a], cols[0]);
                    }
                    if ub[1] == Some(ba) {
                        v += dot3(ur.row[a], cols[1]);
                    }
                }
                if v != 0.0 {
                    self.band.add(r, s, v);
                }
                if s == r {
                    diag = v;
                }
            }
            self.band.add(r, r, rc.reg * diag.abs().max(1e-30));
        }
    }

    /// Contact forces and accelerations of the moving blocks for the `active`
    /// contacts in their modes (Eqs. 17, 19, 20 with the mode fixed). Returns
    /// false if the contact system is singular.
    pub fn forces(&mut self, rc: &RowConst, view: &View, active: &[Active]) -> bool {
        let nb = view.hi - view.lo;
        let g = rc.p.gravity;
        self.unknowns.clear();
        self.geoms.clear();
        self.kins.clear();
        self.fn_.clear();
        self.ft.clear();
        self.vt.clear();
        self.gap.clear();
        self.valid.clear();
        self.band.rhs.clear();
        for a in active {
            let gm = rc.geom(view, a.block, a.slot).expect("active slot exists");
            let k = rc.kin(view, &gm);
            let bodies = [view.local(Some(gm.corner)), view.local(gm.face)];
            let (mu, _) = rc.mu(a.slot);
            let mut col = k.jn;
            if let Mode::Slide(dir) = a.mode {
                for (c, t) in col.iter_mut().zip(k.jt.iter()) {
                    for x in 0..3 {
                        c[x] -= dir * mu * t[x];
                    }
                }
            }
            let rhs_of = |row: &[[f64; 3]; 2], s: f64| {
                let mut r = -s;
                for (b, body) in bodies.iter().enumerate() {
                    if body.is_some() {
                        r += g * row[b][1] * 1.0; // −J M⁻¹ G with G = (0, −m g, 0)
                    }
                }
                r
            };
            self.unknowns.push(Unknown {
                bodies,
                row: k.jn,
                col,
            });
            self.band.rhs.push(rhs_of(&k.jn, k.sn));
            if a.mode == Mode::Stick {
                self.unknowns.push(Unknown {
                    bodies,
                    row: k.jt,
                    col: k.jt,
                });
                self.band.rhs.push(rhs_of(&k.jt, k.st));
            }
            self.vt.push(k.vt);
            self.gap.push(gm.gap);
            self.valid.push(gm.valid);
            self.geoms.push(gm);
            self.kins.push(k);
        }
        self.acc.clear();
        self.acc.resize(nb, [0.0, -g, 0.0]);
        self.power = 0.0;
        if self.unknowns.is_empty() {
            return true;
        }
        self.assemble(rc);
        if !self.band.solve() {
            return false;
        }
        let mut r = 0;
        for (c, a) in active.iter().enumerate() {
            let (mu, _) = rc.mu(a.slot);
            let fnn = self.band.rhs[r];
            r += 1;
            let ft = match a.mode {
                Mode::Frictionless => 0.0,
                Mode::Slide(dir) => -dir * mu * fnn,
                Mode::Stick => {
                    r += 1;
                    self.band.rhs[r - 1]
                }
            };
            self.fn_.push(fnn);
            self.ft.push(ft);
            let k = &self.kins[c];
            self.power += fnn * k.gdot + ft * k.vt;
            let bodies = [
                view.local(Some(self.geoms[c].corner)),
                view.local(self.geoms[c].face),
            ];
            for (b, body) in bodies.iter().enumerate() {
                if let Some(b_) = body {
                    let f = [
                        fnn * k.jn[b][0] + ft * k.jt[b][0],
                        fnn * k.jn[b][1] + ft * k.jt[b][1],
                        fnn * k.jn[b][2] + ft * k.jt[b][2],
                    ];
                    let d = rc.minv(f);
                    for x in 0..3 {
                        self.acc[*b_][x] += d[x];
                    }
                }
            }
        }
        true
    }

    /// Normal relative acceleration δ̈ = J q̈ + S of a candidate under the
    /// accelerations last computed.
    pub fn gddot(&self, view: &View, g: &Geom, k: &Kin) -> f64 {
        let mut s = k.sn;
        if let Some(a) = view.local(Some(g.corner)) {
            s += dot3(k.jn[0], self.acc[a]);
        }
        if let Some(b) = view.local(g.face) {
            s += dot3(k.jn[1], self.acc[b]);
        }
        s
    }

    /// Projects the moving blocks onto the constraints of the active contacts:
    /// velocities so that δ̇ = 0 and, for sticking contacts, v_t = 0, then
    /// positions so that every gap is 0 (one Gauss–Newton step with the metric
    /// M, so the change is the smallest in kinetic-energy norm). The velocity
    /// projection is unilateral: a contact that would have to be pulled
    /// harder than a contact separating at `v_tol` (m/s) is separating; it is
    /// removed from `active` and the projection repeated. A stuck contact
    /// that would be pulled so is first let slide (its mode becomes
    /// [`Mode::Slide`] along its slip, [`Mode::Frictionless`] without
    /// sliding friction) where it slips at all and can (μ_s finite), and the
    /// projection repeated: the tangential impulse of a stick row needs a
    /// normal impulse to bound it (|P_t| ≤ μ_s P_n), and a pull leaves it
    /// none. Works on `y` in place; returns whether `active` changed.
    ///
    /// `at_forces`: the last [`Dynamics::forces`] call was at this very
    /// state (`y`, `pos`, the window lo..hi) with this `active` list (the
    /// same contacts in the same order). Its geometry and kinematics are
    /// then taken instead of measured again: the same numbers, so the same
    /// bits. Whatever `at_forces`, the position pass takes the geometry of
    /// the velocity pass: that pass changes velocities only, and the gap
    /// and the normal Jacobian row are functions of the positions.
    #[allow(clippy::too_many_arguments)]
    pub fn project(
        &mut self,
        rc: &RowConst,
        lo: usize,
        hi: usize,
        y: &mut [f64],
        pos: &[[f64; 3]],
        active: &mut Vec<Active>,
        v_tol: f64,
        at_forces: bool,
    ) -> bool {
        // buffers kept between calls: this runs every step
        let mut y0 = std::mem::take(&mut self.proj_start);
        let mut owner = std::mem::take(&mut self.proj_owner);
        let mut drop = std::mem::take(&mut self.proj_drop);
        let mut pg = std::mem::take(&mut self.proj_geoms);
        pg.clear();
        if at_forces {
            debug_assert_eq!(self.geoms.len(), active.len());
            #[cfg(debug_assertions)]
            {
                let view = View { lo, hi, y, pos };
                for (a, g) in active.iter().zip(&self.geoms) {
                    let now = rc.geom(&view, a.block, a.slot).expect("slot exists");
                    debug_assert!(now.gap.to_bits() == g.gap.to_bits() && now.point == g.point);
                }
            }
            pg.extend(self.geoms.iter().copied().zip(self.kins.iter().copied()));
        } else {
            let view = View { lo, hi, y, pos };
            pg.extend(active.iter().map(|a| {
                let gm = rc.geom(&view, a.block, a.slot).expect("slot exists");
                (gm, rc.kin(&view, &gm))
            }));
        }
        let mut changed = false;
        'passes: for pass in 0..2 {
            let mut rounds = 0;
            loop {
                rounds += 1;
                if active.is_empty() {
                    break 'passes;
                }
                if pass == 0 {
                    if rounds == 1 {
                        y0.clear();
                        y0.extend_from_slice(y);
                    } else {
                        y.copy_from_slice(&y0);
                    }
                }
                self.unknowns.clear();
                self.band.rhs.clear();
                owner.clear();
                {
                    let view = View { lo, hi, y, pos };
                    for (c, a) in active.iter().enumerate() {
                        // the start state's geometry: pass 0 runs at it
                        // (each round from `y0`), pass 1 at its positions
                        let (gm, k) = pg[c];
                        let bodies = [view.local(Some(gm.corner)), view.local(gm.face)];
                        if bodies.iter().all(|b| b.is_none()) {
                            continue;
                        }
                        self.unknowns.push(Unknown {
                            bodies,
                            row: k.jn,
                            col: k.jn,
                        });
                        owner.push((c, true));
                        self.band
                            .rhs
                            .push(if pass == 1 { -gm.gap } else { -k.gdot });
                        if pass == 0 && a.mode == Mode::Stick {
                            self.unknowns.push(Unknown {
                                bodies,
                                row: k.jt,
                                col: k.jt,
                            });
                            owner.push((c, false));
                            self.band.rhs.push(-k.vt);
                        }
                    }
                }
                if self.unknowns.is_empty() {
                    break 'passes;
                }
                self.assemble(rc);
                if !self.band.solve() {
                    break 'passes;
                }
                if pass == 0 && rounds < 20 {
                    // drop the contacts that would be pulled together by more
                    // than the impulse that closes a contact separating at the
                    // velocity tolerance (a small pull is the persistence of a
                    // contact that separates slower than that)
                    let pull = 2.0 * rc.p.block.mass * v_tol;
                    drop.clear();
                    drop.extend(
                        owner
                            .iter()
                            .zip(self.band.rhs.iter())
                            .filter(|((_, normal), p)| *normal && **p < -pull)
                            .map(|((c, _), _)| *c),
                    );
                    if !drop.is_empty() {
                        drop.sort_unstable();
                        drop.dedup();
                        changed = true;
                        // a stuck contact that would be pulled first lets
                        // its slip go: the stick row asks for a tangential
                        // impulse with no normal impulse to bound it
                        if release_sticks(rc, &View { lo, hi, y, pos }, active, &drop) {
                            continue;
                        }
                        for &c in drop.iter().rev() {
                            active.remove(c);
                            pg.remove(c);
                        }
                        continue;
                    }
                }
                let off = if pass == 1 { 0 } else { 3 };
                for (u, mu) in self.unknowns.iter().zip(self.band.rhs.iter()) {
                    for (b, body) in u.bodies.iter().enumerate() {
                        if let Some(b_) = body {
                            let d = rc.minv(u.col[b]);
                            for x in 0..3 {
                                y[6 * b_ + off + x] += mu * d[x];
                            }
                        }
                    }
                }
                break;
            }
        }
        self.proj_start = y0;
        self.proj_owner = owner;
        self.proj_drop = drop;
        self.proj_geoms = pg;
        changed
    }

    /// The contact forces of every candidate (block, slot, v_t) by
    /// projected Gauss–Seidel relaxation of the frictional contact problem
    /// at acceleration level (Eqs. 18–20): each contact in turn takes the
    /// normal force that stops its own normal acceleration, at least 0, then
    /// the tangential force that stops its own slip acceleration, within
    /// ±μ_s F_n — or −μ F_n along v_t where it slips faster than `v_stick`
    /// (m/s). Every update is a projection in the metric of the inverse
    /// mass, so the relaxation does not cycle as a mode search can; after
    /// `sweeps` sweeps the forces give a mode to be checked. Returns the
    /// forces (normal, tangential), one pair per candidate, in `out`.
    pub fn relaxed_forces(
        &mut self,
        rc: &RowConst,
        view: &View,
        candidates: impl Iterator<Item = (usize, usize, f64)>,
        v_stick: f64,
        sweeps: usize,
        out: &mut Vec<[f64; 2]>,
    ) {
        let g = rc.p.gravity;
        let nb = view.hi - view.lo;
        self.relax_acc.clear();
        self.relax_acc.resize(nb, [0.0, -g, 0.0]);
        self.relax_rows.clear();
        for (block, slot, vt) in candidates {
            let gm = rc.geom(view, block, slot).expect("slot exists");
            let k = rc.kin(view, &gm);
            let bodies = [view.local(Some(gm.corner)), view.local(gm.face)];
            let w = |j: &[[f64; 3]; 2]| {
                let mut w = 0.0;
                for (b, body) in bodies.iter().enumerate() {
                    if body.is_some() {
                        w += dot3(j[b], rc.minv(j[b]));
                    }
                }
                w
            };
            let inv = |w: f64| if w > 0.0 { 1.0 / w } else { 0.0 };
            let (mu, mus) = rc.mu(slot);
            self.relax_rows.push(RelaxRow {
                bodies,
                jn: k.jn,
                jt: k.jt,
                sn: k.sn,
                st: k.st,
                inv_wnn: inv(w(&k.jn)),
                inv_wtt: inv(w(&k.jt)),
                mu,
                mus,
                slip: (vt.abs() > v_stick && mus.is_finite()).then_some(vt.signum()),
                fnn: 0.0,
                ft: 0.0,
            });
        }
        let rate = |acc: &[[f64; 3]], r: &RelaxRow, j: &[[f64; 3]; 2], s: f64| {
            let mut a = s;
            for (b, body) in r.bodies.iter().enumerate() {
                if let Some(b_) = body {
                    a += dot3(j[b], acc[*b_]);
                }
            }
            a
        };
        let push = |acc: &mut [[f64; 3]], r: &RelaxRow, j: &[[f64; 3]; 2], f: f64| {
            for (b, body) in r.bodies.iter().enumerate() {
                if let Some(b_) = body {
                    let d = rc.minv(j[b]);
                    for x in 0..3 {
                        acc[*b_][x] += f * d[x];
                    }
                }
            }
        };
        for _ in 0..sweeps {
            for c in 0..self.relax_rows.len() {
                let r = self.relax_rows[c];
                let an = rate(&self.relax_acc, &r, &r.jn, r.sn);
                let fnn = (r.fnn - an * r.inv_wnn).max(0.0);
                push(&mut self.relax_acc, &r, &r.jn, fnn - r.fnn);
                let ft = match r.slip {
                    Some(dir) => -dir * r.mu * fnn,
                    None if r.mus > 0.0 => {
                        let at = rate(&self.relax_acc, &r, &r.jt, r.st);
                        let free = r.ft - at * r.inv_wtt;
                        let limit = if fnn > 0.0 { r.mus * fnn } else { 0.0 };
                        free.clamp(-limit, limit)
                    }
                    None => 0.0,
                };
                push(&mut self.relax_acc, &r, &r.jt, ft - r.ft);
                self.relax_rows[c].fnn = fnn;
                self.relax_rows[c].ft = ft;
            }
        }
        out.clear();
        out.extend(self.relax_rows.iter().map(|r| [r.fnn, r.ft]));
    }
}
