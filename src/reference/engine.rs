//! The driver: the smooth phase integrated with the contact mode held fixed,
//! events located inside steps (contact closing, lift-off, stick ↔ slip, slip
//! reversal), impacts resolved by the LZB solver, and the time-varying set of
//! moving blocks (the paper's κ, Sec. 2.1): blocks ahead of the wave stand
//! frozen until struck, blocks at rest behind it are frozen until touched.

use std::time::Instant;

use super::dynamics::{Active, Dynamics, Mode, RowConst, View};
use super::geometry::{slots_per_block, Geom, Kin};
use super::modes::{initial_mode, select, Candidate, ModeTol};
use super::settings::{Integrator, Settings};
use super::stepper::{Stages, DOPRI5, HEUN};
use crate::domino::{BlockSeries, ChainReport, EnergyReport, RowSpec};
use crate::impact::ImpactSolver;

/// The whole row at one time.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Snapshot {
    /// Time (s).
    pub time: f64,
    /// (x, y, φ) of every block: centre (m) and counter-clockwise angle (rad).
    pub blocks: Vec<[f64; 3]>,
}

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum EngineError {
    /// The row is not usable.
    #[error("invalid row: {0}")]
    InvalidRow(String),
    /// The impact resolver failed.
    #[error("impact at t = {time} s: {source}")]
    Impact {
        /// Time (s).
        time: f64,
        /// The resolver's error.
        source: crate::impact::ImpactError,
    },
    /// The contact equations became singular or the state non-finite.
    #[error("the smooth phase failed at t = {0} s (singular contact system)")]
    Singular(f64),
}

/// The result of a run.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// The engine-independent report (hit times, speeds, energy, …).
    pub report: ChainReport,
    /// The snapshots asked for.
    pub snapshots: Vec<Snapshot>,
    /// Accepted time steps.
    pub steps: usize,
    /// Right-hand-side evaluations (contact-force solves).
    pub evaluations: usize,
}

/// The state of a running simulation.
pub(crate) struct Engine {
    pub rc: RowConst,
    pub row: RowSpec,
    pub s: Settings,
    pub k_slots: usize,
    /// Configuration and velocity of every block (window blocks: see `y`).
    pub pos: Vec<[f64; 3]>,
    pub vel: Vec<[f64; 3]>,
    /// Moving blocks lo..hi.
    pub lo: usize,
    pub hi: usize,
    /// Window state (6 per block) + the contact work accumulator.
    pub y: Vec<f64>,
    pub k0: Vec<f64>,
    pub y1: Vec<f64>,
    pub ybest: Vec<f64>,
    pub t: f64,
    pub active: Vec<Active>,
    pub is_active: Vec<bool>,
    pub dynamics: Dynamics,
    pub stages: Stages,
    pub solver: ImpactSolver,
    pub(crate) impact_buffers: super::impacts::ImpactBuffers,
    pub hit: Vec<Option<f64>>,
    pub energy: EnergyReport,
    pub max_penetration: f64,
    pub impacts: usize,
    pub impact_fallbacks: usize,
    pub held_impacts: usize,
    pub reversed: Vec<bool>,
    /// Time (s) of the last impact, and how many `handle_events` calls in a
    /// row have found an impact at that same instant.
    last_impact_time: f64,
    impacts_at_this_instant: usize,
    pub steps: usize,
    pub evaluations: usize,
    // event references, per active contact
    ref_fn: Vec<f64>,
    ref_stick: Vec<f64>,
    ref_slide: Vec<f64>,
    candidates: Vec<Candidate>,
    mode_state: Vec<Option<Mode>>,
    new_active: Vec<Active>,
    // tolerances in SI
    pub eps_gap: f64,
    pub v_tol: f64,
    pub v_app: f64,
    pub tol: ModeTol,
    series: Vec<BlockSeries>,
    next_sample: f64,
    snapshots: Vec<Snapshot>,
    next_snapshot: usize,
    h_adapt: f64,
}

/// Slot `slot` of block `i` if it is a closed contact (gap ≤ `eps`, m)
/// between moving blocks, with its kinematics. Contacts with a frozen block
/// never press: a moving block that approaches a frozen one starts an
/// impact, which wakes it.
fn closed_between_moving(
    rc: &RowConst,
    view: &View,
    i: usize,
    slot: usize,
    eps: f64,
) -> Option<(Geom, Kin)> {
    let g = rc.geom(view, i, slot)?;
    if !g.valid || g.gap > eps {
        return None;
    }
    if view.local(Some(g.corner)).is_none() || (g.face.is_some() && view.local(g.face).is_none()) {
        return None;
    }
    let k = rc.kin(view, &g);
    Some((g, k))
}

fn rhs(
    dynamics: &mut Dynamics,
    rc: &RowConst,
    lo: usize,
    hi: usize,
    pos: &[[f64; 3]],
    active: &[Active],
    y: &[f64],
    dy: &mut [f64],
) -> bool {
    let view = View { lo, hi, y, pos };
    if !dynamics.forces(rc, &view, active) {
        return false;
    }
    for b in 0..hi - lo {
        for x in 0..3 {
            dy[6 * b + x] = y[6 * b + 3 + x];
            dy[6 * b + 3 + x] = dynamics.acc[b][x];
        }
    }
    let last = dy.len() - 1;
    dy[last] = -dynamics.power;
    dy.iter().all(|v| v.is_finite())
}

impl Engine {
    pub fn new(row: &RowSpec, settings: &Settings) -> Result<Engine, EngineError> {
        row.validate().map_err(EngineError::InvalidRow)?;
        let p = row.params;
        let n = row.n;
        let rc = RowConst::new(p, n);
        let k_slots = slots_per_block(p.lambda_points);
        let mut pos = Vec::with_capacity(n);
        for i in 0..n {
            let c = row.centre(i);
            pos.push([c[0], c[1], 0.0]);
        }
        let mut vel = vec![[0.0; 3]; n];
        let (v0, w0) = row.initial_velocity();
        vel[0] = [v0[0], v0[1], w0];
        let vbar = p.speed_scale();
        let m = p.block.mass;
        let mut e = Engine {
            rc,
            row: *row,
            s: settings.clone(),
            k_slots,
            pos,
            vel,
            lo: 0,
            hi: 1,
            y: Vec::new(),
            k0: Vec::new(),
            y1: Vec::new(),
            ybest: Vec::new(),
            t: 0.0,
            active: Vec::new(),
            is_active: vec![false; n * k_slots],
            dynamics: Dynamics::default(),
            stages: Stages::default(),
            solver: ImpactSolver::new(),
            impact_buffers: Default::default(),
            hit: vec![None; n],
            energy: EnergyReport::default(),
            max_penetration: 0.0,
            impacts: 0,
            impact_fallbacks: 0,
            held_impacts: 0,
            reversed: vec![false; n],
            last_impact_time: f64::NEG_INFINITY,
            impacts_at_this_instant: 0,
            steps: 0,
            evaluations: 0,
            ref_fn: Vec::new(),
            ref_stick: Vec::new(),
            ref_slide: Vec::new(),
            candidates: Vec::new(),
            mode_state: Vec::new(),
            new_active: Vec::new(),
            eps_gap: settings.gap_tolerance * p.block.height,
            v_tol: settings.velocity_tolerance * vbar,
            v_app: settings.approach_tolerance * vbar,
            tol: ModeTol {
                force: 1e-9 * m * p.gravity,
                accel: 1e-9 * p.gravity,
                velocity: settings.velocity_tolerance * vbar,
            },
            series: settings
                .series_blocks
                .iter()
                .map(|&b| BlockSeries {
                    block: b,
                    ..Default::default()
                })
                .collect(),
            next_sample: 0.0,
            snapshots: Vec::new(),
            next_snapshot: 0,
            h_adapt: 1e-4,
        };
        e.hit[0] = Some(0.0);
        e.sync_in();
        e.energy.initial = e.total_energy();
        Ok(e)
    }

    /// Kinetic and potential energy of the whole row (J).
    pub fn total_energy(&self) -> f64 {
        let (k, u) = self.energies();
        k + u
    }

    fn energies(&self) -> (f64, f64) {
        self.energies_of(0, self.row.n)
    }

    /// Kinetic + potential energy of the moving blocks only (J): what a
    /// projection or impact can change, in O(window).
    pub fn window_energy(&self) -> f64 {
        let (k, u) = self.energies_of(self.lo, self.hi);
        k + u
    }

    fn energies_of(&self, from: usize, to: usize) -> (f64, f64) {
        let b = &self.rc.p.block;
        let g = self.rc.p.gravity;
        let mut k = 0.0;
        let mut u = 0.0;
        for i in from..to {
            let (q, v) = self.state(i);
            k += 0.5 * b.mass * (v[0] * v[0] + v[1] * v[1]) + 0.5 * b.inertia() * v[2] * v[2];
            u += b.mass * g * q[1];
        }
        (k, u)
    }

    /// Configuration and velocity of block i (reads the window state).
    pub fn state(&self, i: usize) -> ([f64; 3], [f64; 3]) {
        if i >= self.lo && i < self.hi {
            let k = 6 * (i - self.lo);
            (
                [self.y[k], self.y[k + 1], self.y[k + 2]],
                [self.y[k + 3], self.y[k + 4], self.y[k + 5]],
            )
        } else {
            (self.pos[i], self.vel[i])
        }
    }

    /// Writes the window state back to `pos`/`vel`.
    pub fn sync_out(&mut self) {
        for i in self.lo..self.hi {
            let k = 6 * (i - self.lo);
            self.pos[i] = [self.y[k], self.y[k + 1], self.y[k + 2]];
            self.vel[i] = [self.y[k + 3], self.y[k + 4], self.y[k + 5]];
        }
    }

    /// Rebuilds the window state from `pos`/`vel`.
    pub fn sync_in(&mut self) {
        self.y.clear();
        for i in self.lo..self.hi {
            self.y.extend_from_slice(&self.pos[i]);
            self.y.extend_from_slice(&self.vel[i]);
        }
        self.y.push(0.0);
    }

    pub fn view(&self) -> View<'_> {
        View {
            lo: self.lo,
            hi: self.hi,
            y: &self.y,
            pos: &self.pos,
        }
    }

    /// Every (block, slot) pair that can involve a moving block, sorted by block.
    pub fn for_each_slot(&self, mut f: impl FnMut(usize, usize)) {
        let lambda = self.rc.p.lambda_points;
        let first = self.lo.saturating_sub(1);
        for i in first..self.hi.min(self.row.n) {
            if i >= self.lo {
                for slot in 0..=lambda {
                    f(i, slot);
                }
            }
            if i + 1 < self.row.n {
                f(i, lambda + 1);
            }
            // The heel of block i+1 on the front face of block i: by default
            // only for the last pair, where the last block lies on the ground.
            // Inside the row the pair converges to face-to-face contact at the
            // rest angle, where the two corner contacts make the contact and
            // impact problems degenerate (the paper's model has only A_i and
            // B_i there); `Settings::heel_contacts` turns them on everywhere.
            if i + 2 == self.row.n || (self.s.heel_contacts && i + 1 < self.row.n) {
                f(i, lambda + 2);
            }
        }
    }

    fn eval_k0(&mut self) -> Result<(), EngineError> {
        self.k0.resize(self.y.len(), 0.0);
        self.evaluations += 1;
        if !rhs(
            &mut self.dynamics,
            &self.rc,
            self.lo,
            self.hi,
            &self.pos,
            &self.active,
            &self.y,
            &mut self.k0,
        ) {
            return Err(EngineError::Singular(self.t));
        }
        // event references at the start of the step
        self.ref_fn.clear();
        self.ref_stick.clear();
        self.ref_slide.clear();
        for (c, a) in self.active.iter().enumerate() {
            let fnn = self.dynamics.fn_[c];
            self.ref_fn.push(fnn.min(0.0));
            self.ref_stick.push(
                self.rc
                    .stick_excess(a.slot, self.dynamics.ft[c], fnn)
                    .max(0.0),
            );
            let dir = match a.mode {
                Mode::Slide(d) => d,
                _ => 0.0,
            };
            self.ref_slide.push((dir * self.dynamics.vt[c]).min(0.0));
        }
        Ok(())
    }

    /// True if any event happened in state `y1` (the dynamics must hold the
    /// forces at `y1`). Also tracks the deepest penetration.
    fn events_at(&mut self, y1: &[f64]) -> bool {
        let mut event = false;
        for (c, a) in self.active.iter().enumerate() {
            let d = &self.dynamics;
            let fnn = d.fn_[c];
            if !d.valid[c] || fnn < self.ref_fn[c] - self.tol.force {
                event = true;
            }
            match a.mode {
                Mode::Stick => {
                    if self.rc.stick_excess(a.slot, d.ft[c], fnn)
                        > self.ref_stick[c] + self.tol.force
                    {
                        event = true;
                    }
                }
                Mode::Slide(dir) => {
                    if dir * d.vt[c] < self.ref_slide[c] - 0.5 * self.v_tol {
                        event = true;
                    }
                }
                Mode::Frictionless => {}
            }
        }
        let view = View {
            lo: self.lo,
            hi: self.hi,
            y: y1,
            pos: &self.pos,
        };
        let mut deepest = self.dynamics.gap.iter().cloned().fold(0.0f64, f64::min);
        let k = self.k_slots;
        let rc = &self.rc;
        let is_active = &self.is_active;
        let eps = self.eps_gap;
        let vapp = self.v_app;
        self.for_each_slot(|i, slot| {
            if is_active[i * k + slot] || event {
                return;
            }
            let Some(g) = rc.geom(&view, i, slot) else {
                return;
            };
            if !g.valid {
                return;
            }
            deepest = deepest.min(g.gap);
            if g.gap >= -eps {
                return;
            }
            let kk = rc.kin(&view, &g);
            if kk.gdot < -vapp {
                event = true;
            }
        });
        // The heel-on-front-face pairs inside the row are not contacts (see
        // for_each_slot) but their overlap is measured, so that the reported
        // penetration covers every corner the row can drive into a neighbour.
        let lambda = self.rc.p.lambda_points;
        for i in self.lo.saturating_sub(1)..self.hi.min(self.row.n.saturating_sub(2)) {
            if let Some(g) = rc.geom(&view, i, lambda + 2) {
                if g.valid {
                    deepest = deepest.min(g.gap);
                }
            }
        }
        self.max_penetration = self.max_penetration.max(-deepest);
        event
    }

    fn set_active(&mut self) {
        for a in &self.active {
            self.is_active[a.block * self.k_slots + a.slot] = false;
        }
        std::mem::swap(&mut self.active, &mut self.new_active);
        for a in &self.active {
            self.is_active[a.block * self.k_slots + a.slot] = true;
        }
    }

    /// Impacts, contact mode, projection; then the derivative for the next step.
    fn handle_events(&mut self) -> Result<(), EngineError> {
        self.sync_out();
        let mut impacted = false;
        for _ in 0..20 {
            if !self.resolve_impacts()? {
                break;
            }
            impacted = true;
        }
        if impacted {
            if self.t - self.last_impact_time <= self.s.event_time_tolerance {
                self.impacts_at_this_instant += 1;
            } else {
                self.impacts_at_this_instant = 0;
            }
            self.last_impact_time = self.t;
        }
        self.record_hits();
        // candidates: closed, valid, neither approaching nor separating
        let mut cands = std::mem::take(&mut self.candidates);
        cands.clear();
        {
            let view = self.view();
            let rc = &self.rc;
            let eps = self.eps_gap;
            let vt = self.v_tol;
            let vapp = self.v_app;
            self.for_each_slot(|i, slot| {
                let Some((_, k)) = closed_between_moving(rc, &view, i, slot, eps) else {
                    return;
                };
                if k.gdot >= -vapp && k.gdot <= vt {
                    cands.push(Candidate {
                        block: i,
                        slot,
                        vt: k.vt,
                    });
                }
            });
        }
        {
            let view = View {
                lo: self.lo,
                hi: self.hi,
                y: &self.y,
                pos: &self.pos,
            };
            // a search that does not converge keeps its last mode minus any
            // pulling contact (see `select`); the events of the next step
            // correct it
            let _ = select(
                &mut self.dynamics,
                &self.rc,
                &view,
                &cands,
                &mut self.mode_state,
                &mut self.new_active,
                &self.tol,
            );
        }
        self.candidates = cands;
        self.set_active();
        if self.impacts_at_this_instant >= 2 {
            self.project_unilateral();
        } else {
            self.project();
        }
        self.eval_k0()
    }

    /// [`Engine::project`], then the closed contacts left out of the active
    /// set that the projection drives into approach join it and the
    /// projection is repeated from the same state: the velocities end on
    /// {active: δ̇ = 0, other closed contacts: δ̇ ≥ 0}.
    ///
    /// Used once impacts repeat at one instant (`handle_events`): a
    /// face-to-face pair (B_i and the heel contact closed together) can
    /// cycle there. The impact leaves the heel separating at 10⁻⁷ m/s, the
    /// mode search (acceleration level) does not need it, the projection of
    /// B_i turns the pair so that the heel approaches at 4·10⁻⁵ m/s, and the
    /// impact that follows at the same instant starts the cycle again (ideal
    /// Domino T rows with `heel_contacts`). Not used otherwise: where blocks
    /// chatter at the back of a Table 1 row, contacts joined this way are
    /// dropped by the next mode search and joined again thousands of times.
    fn project_unilateral(&mut self) {
        let start = self.y.clone();
        let booked = self.energy.projection;
        for _ in 0..4 {
            self.project();
            let mut joined = std::mem::take(&mut self.new_active);
            joined.clear();
            {
                let view = self.view();
                let (rc, tol, eps, vapp) = (&self.rc, &self.tol, self.eps_gap, self.v_app);
                let k = self.k_slots;
                let is_active = &self.is_active;
                self.for_each_slot(|i, slot| {
                    if is_active[i * k + slot] {
                        return;
                    }
                    let Some((_, kk)) = closed_between_moving(rc, &view, i, slot, eps) else {
                        return;
                    };
                    if kk.gdot < -vapp {
                        joined.push(Active {
                            block: i,
                            slot,
                            mode: initial_mode(rc, slot, kk.vt, tol),
                        });
                    }
                });
            }
            if joined.is_empty() {
                self.new_active = joined;
                break;
            }
            joined.extend_from_slice(&self.active);
            // the band solve wants the contacts sorted by block
            joined.sort_by_key(|a| (a.block, a.slot));
            self.new_active = joined;
            self.set_active();
            self.y.copy_from_slice(&start);
            self.energy.projection = booked;
        }
    }

    /// Projection onto the active constraints, with its energy change booked.
    fn project(&mut self) {
        let before = self.window_energy();
        let (lo, hi) = (self.lo, self.hi);
        let mut act = std::mem::take(&mut self.new_active);
        act.clear();
        act.extend_from_slice(&self.active);
        let n_before = act.len();
        self.dynamics.project(
            &self.rc,
            lo,
            hi,
            &mut self.y,
            &self.pos,
            &mut act,
            self.v_tol,
        );
        self.new_active = act;
        if self.new_active.len() != n_before {
            self.set_active();
        }
        let after = self.window_energy();
        self.energy.projection += before - after;
    }

    /// Records the first time a pair contact (block i on block i+1) closed.
    fn record_hits(&mut self) {
        let lambda = self.rc.p.lambda_points;
        let view = self.view();
        let mut found: Vec<usize> = Vec::new();
        let first = self.lo.saturating_sub(1);
        for i in first..self.hi.min(self.row.n - 1) {
            if self.hit[i + 1].is_some() {
                continue;
            }
            for slot in [lambda + 1, lambda + 2] {
                if let Some(g) = self.rc.geom(&view, i, slot) {
                    if g.valid && g.gap <= self.eps_gap {
                        found.push(i + 1);
                    }
                }
            }
        }
        for j in found {
            self.hit[j] = Some(self.t);
        }
    }

    /// Freezes blocks at rest at the back of the window.
    fn freeze(&mut self) -> Result<bool, EngineError> {
        let vf = self.s.freeze_tolerance * self.rc.p.speed_scale();
        let af = self.s.freeze_tolerance * self.rc.p.gravity;
        let h = self.rc.p.block.height;
        let mut changed = false;
        let base = self.lo;
        self.sync_out();
        while self.lo < self.hi {
            let v = self.vel[self.lo];
            let a = self.dynamics.acc[self.lo - base];
            let slow = v[0].abs() < vf && v[1].abs() < vf && (v[2] * h).abs() < vf;
            let still = a[0].abs() < af && a[1].abs() < af && (a[2] * h).abs() < af;
            if !(slow && still) {
                break;
            }
            let b = &self.rc.p.block;
            self.energy.frozen +=
                0.5 * b.mass * (v[0] * v[0] + v[1] * v[1]) + 0.5 * b.inertia() * v[2] * v[2];
            self.vel[self.lo] = [0.0; 3];
            self.lo += 1;
            changed = true;
        }
        if changed {
            self.rebuild_window()?;
        }
        Ok(changed)
    }

    /// After lo/hi changed: drops contacts without a moving block, rebuilds the
    /// state vector and the derivative.
    pub fn rebuild_window(&mut self) -> Result<(), EngineError> {
        let (lo, hi) = (self.lo, self.hi);
        let lambda = self.rc.p.lambda_points;
        self.new_active.clear();
        for a in &self.active {
            let moving = |j: usize| j >= lo && j < hi;
            let keep = if a.slot <= lambda {
                moving(a.block)
            } else {
                moving(a.block) && moving(a.block + 1)
            };
            if keep {
                self.new_active.push(*a);
            }
        }
        self.set_active();
        self.sync_in();
        self.eval_k0()
    }

    fn record(&mut self) {
        let tbar = self.rc.p.time_scale();
        for i in self.lo..self.hi {
            let (_, v) = self.state(i);
            if v[2] * tbar > 0.02 {
                self.reversed[i] = true;
            }
        }
        if !self.series.is_empty() && self.t >= self.next_sample {
            self.next_sample = self.t + self.s.series_interval;
            for k in 0..self.series.len() {
                let b = self.series[k].block;
                if b == 0 || b > self.row.n {
                    continue;
                }
                let (q, v) = self.state(b - 1);
                let s = &mut self.series[k];
                s.time.push(self.t);
                s.theta.push(-q[2]);
                s.theta_dot.push(-v[2]);
            }
        }
        while self.next_snapshot < self.s.snapshot_times.len()
            && self.t >= self.s.snapshot_times[self.next_snapshot]
        {
            self.next_snapshot += 1;
            let blocks = (0..self.row.n).map(|i| self.state(i).0).collect();
            self.snapshots.push(Snapshot {
                time: self.t,
                blocks,
            });
        }
    }

    fn error_norm(&self) -> f64 {
        let Integrator::Adaptive { tolerance } = self.s.integrator else {
            return 0.0;
        };
        let p = &self.rc.p;
        let scales = [
            p.block.height,
            p.block.height,
            1.0,
            p.speed_scale(),
            p.speed_scale(),
            p.speed_scale() / p.block.height,
        ];
        let mut worst = 0.0f64;
        let n = self.y.len() - 1;
        for x in 0..n {
            let e = self.stages.err[x].abs() / (tolerance * scales[x % 6]);
            worst = worst.max(e);
        }
        let ework = p.block.mass * p.gravity * p.block.height;
        worst.max(self.stages.err[n].abs() / (tolerance * ework))
    }

    /// One trial step of size h from `y` into `y1`; false if singular.
    fn trial(&mut self, h: f64) -> bool {
        let tab = match self.s.integrator {
            Integrator::Paper { .. } => &HEUN,
            Integrator::Adaptive { .. } => &DOPRI5,
        };
        let dynamics = &mut self.dynamics;
        let rc = &self.rc;
        let (lo, hi) = (self.lo, self.hi);
        let pos = &self.pos;
        let active = &self.active;
        let mut evals = 0;
        let ok = self
            .stages
            .step(tab, h, &self.y, &self.k0, &mut self.y1, |y, dy| {
                evals += 1;
                rhs(dynamics, rc, lo, hi, pos, active, y, dy)
            });
        self.evaluations += evals;
        ok
    }

    /// Forces at y1 into the dynamics (for the event test).
    fn forces_at_y1(&mut self) -> bool {
        let view = View {
            lo: self.lo,
            hi: self.hi,
            y: &self.y1,
            pos: &self.pos,
        };
        self.evaluations += 1;
        self.dynamics.forces(&self.rc, &view, &self.active)
    }

    /// Advances by one accepted step (possibly shortened to an event).
    fn advance(&mut self, t_end: f64) -> Result<(), EngineError> {
        let mut h = match self.s.integrator {
            Integrator::Paper { dt } => dt,
            Integrator::Adaptive { .. } => self.h_adapt,
        };
        h = h.min(t_end - self.t).max(1e-14);
        // error control
        let mut tries = 0;
        let mut h_next = h;
        loop {
            tries += 1;
            if tries > 60 {
                return Err(EngineError::Singular(self.t));
            }
            if !self.trial(h) {
                h *= 0.5;
                continue;
            }
            let err = self.error_norm();
            if err > 1.0 {
                h *= (0.9 * err.powf(-0.2)).clamp(0.1, 0.5);
                continue;
            }
            if let Integrator::Adaptive { .. } = self.s.integrator {
                let grow = if err > 0.0 {
                    (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
                } else {
                    5.0
                };
                h_next = (h * grow).min(0.002 * self.rc.p.time_scale());
            }
            break;
        }
        // events
        let mut event = false;
        if !self.forces_at_y1() {
            return Err(EngineError::Singular(self.t));
        }
        let y1 = std::mem::take(&mut self.y1);
        let ev = self.events_at(&y1);
        self.y1 = y1;
        if ev {
            event = true;
            let (mut a, mut b) = (0.0, h);
            self.ybest.clone_from(&self.y1);
            while b - a > self.s.event_time_tolerance {
                let mid = 0.5 * (a + b);
                let ok = self.trial(mid) && self.forces_at_y1();
                let y1 = std::mem::take(&mut self.y1);
                let ev = !ok || self.events_at(&y1);
                self.y1 = y1;
                if ev {
                    b = mid;
                    self.ybest.clone_from(&self.y1);
                } else {
                    a = mid;
                }
            }
            h = b;
            std::mem::swap(&mut self.y1, &mut self.ybest);
            h_next = h_next.max(1e-3 * self.rc.p.time_scale().min(h_next));
        }
        std::mem::swap(&mut self.y, &mut self.y1);
        self.t += h;
        self.steps += 1;
        let last = self.y.len() - 1;
        self.energy.friction += self.y[last];
        self.y[last] = 0.0;
        self.h_adapt = h_next;
        if event {
            self.handle_events()?;
        } else {
            self.project();
            self.eval_k0()?;
        }
        self.freeze()?;
        self.record();
        Ok(())
    }
}

/// Runs the reference engine on a row.
///
/// ```no_run
/// use topple::domino::{Preset, RowSpec};
/// use topple::reference::{run, Settings};
/// let p = Preset::T.params().ideal();
/// let row = RowSpec::new(p, 0.35 * p.block.height, 30, 1.0);
/// let out = run(&row, &Settings::default()).unwrap();
/// println!("v_na = {:?}", out.report.natural_speed);
/// ```
pub fn run(row: &RowSpec, settings: &Settings) -> Result<RunResult, EngineError> {
    run_with_progress(row, settings, |_| {})
}

/// [`run`], calling `progress` with the number of blocks hit so far each time
/// the wave reaches another block (for a progress bar on long rows).
///
/// ```
/// use topple::domino::{Preset, RowSpec};
/// use topple::reference::{run_with_progress, Settings};
/// let p = Preset::T.params().ideal();
/// let row = RowSpec::new(p, 0.5 * p.block.height, 4, 1.0);
/// let mut seen = Vec::new();
/// let out = run_with_progress(&row, &Settings::default(), |hit| seen.push(hit)).unwrap();
/// assert_eq!(seen, (1..=out.report.hit_times.len()).collect::<Vec<_>>());
/// ```
pub fn run_with_progress(
    row: &RowSpec,
    settings: &Settings,
    mut progress: impl FnMut(usize),
) -> Result<RunResult, EngineError> {
    let start = Instant::now();
    let mut e = Engine::new(row, settings)?;
    let t_max = settings
        .t_max
        .unwrap_or(40.0 * row.params.time_scale() * (row.n as f64 + 5.0));
    e.handle_events()?;
    e.record();
    let mut stopped_early = false;
    let mut hits_seen = 0;
    while e.lo < e.hi && e.t < t_max {
        if settings.stop_at_last_hit && e.hit[row.n - 1].is_some() {
            break;
        }
        if let Some(limit) = settings.wall_time_limit {
            if start.elapsed().as_secs_f64() > limit {
                stopped_early = true;
                break;
            }
        }
        e.advance(t_max)?;
        while hits_seen < row.n && e.hit[hits_seen].is_some() {
            hits_seen += 1;
            progress(hits_seen);
        }
    }
    e.sync_out();
    let hits: Vec<f64> = e.hit.iter().map_while(|h| *h).collect();
    let mut report = ChainReport::new("reference", row, hits);
    let (k, u) = e.energies();
    e.energy.kinetic = k;
    e.energy.potential = u;
    let en = &mut e.energy;
    en.residual = en.initial
        - (en.kinetic + en.potential + en.impacts + en.friction + en.projection + en.frozen);
    report.energy = Some(e.energy);
    report.max_penetration = Some(e.max_penetration);
    report.impacts = e.impacts;
    report.stopped_early = stopped_early;
    report.impact_fallbacks = e.impact_fallbacks;
    report.held_impacts = e.held_impacts;
    report.reversed_blocks = (0..row.n)
        .filter(|&i| e.reversed[i])
        .map(|i| i + 1)
        .collect();
    report.simulated_time = e.t;
    report.run_time = start.elapsed().as_secs_f64();
    report.series = std::mem::take(&mut e.series);
    Ok(RunResult {
        report,
        snapshots: e.snapshots,
        steps: e.steps,
        evaluations: e.evaluations,
    })
}
