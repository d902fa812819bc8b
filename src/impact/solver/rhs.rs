//! Stage 2: the right-hand side dy/dt of the impact's equations of motion.
//!
//! M dv/dt = Σ J_nᵀ F + Σ J_tᵀ F_t (paper Eq. 21 divided by dt), with
//!
//! * F = k q^α at every loaded point (compression or expansion);
//! * sliding friction F_t = −μ s (F + λ) at every point of a sliding patch
//!   (s the sign of its slip, fixed between events; paper Eq. 20 in
//!   differential form, docs/model.md §4);
//! * the forces of the constraint rows — stuck patches (no slip) and held
//!   points (no approach) — solved so that their rates stay constant
//!   (constraints.rs);
//!
//! and dq/dt from the contact law (law.rs), dP_n/dt = F + λ and dP_t/dt the
//! friction force of each point (a stuck patch's force is shared among its
//! points in proportion to their normal forces, so that each point satisfies
//! Coulomb's bound when the patch does).
//!
//! Every mode (open, compression, expansion, held, stick, slide) is fixed
//! between events, so the right-hand side is smooth within a step; the probe
//! notes every trial point where a mode's own condition fails, and the
//! event stage (events.rs) locates the switch on the step's interpolant.

use super::data::{normal_rate, push_slots, rate, slot_rate, PatchMode, PointMode};
use super::Integrator;

impl Integrator {
    /// Whether point `i` starting to load must be a switch whatever its
    /// rate: its patch has no slip and no load yet (it sticks from then on).
    #[inline]
    pub(super) fn onset_matters(&self, i: usize) -> bool {
        let p = self.rows[i].patch;
        matches!(self.patch_modes[p], PatchMode::Idle) && !self.patches[p].frictionless()
    }

    /// Whether point `i`, touching with no compression (q = 0) at state
    /// `y`, starts to load from rest: it approaches slower than the onset
    /// speed and no friction patch waits for its load. Its force then grows
    /// smoothly (q ∝ t², F ∝ t^(2α)), so its start needs no switch of its
    /// own; e = 0 points pushed again after their compression ended start
    /// this way, cycle after cycle.
    pub(super) fn loads_from_rest(&self, i: usize, y: &[f64]) -> bool {
        normal_rate(&self.rows[i], y) >= -self.scales.onset && !self.onset_matters(i)
    }

    /// Whether point `i`, touching within the rounding of zero at the
    /// start of a step at time `now` (s), has an onset still to be landed
    /// on: it does not load from rest, and its closing was not just landed
    /// on at this instant with its patch settled (a patch that still waits
    /// for the load keeps its onset watched). Without the last condition a
    /// closing landed a rounding inside contact was landed on a second time,
    /// a step's 10⁻⁴ later, where q passes the rounding of zero.
    pub(super) fn onset_due(&self, i: usize, y: &[f64], now: f64) -> bool {
        if self.onset_matters(i) {
            return true;
        }
        !self.loads_from_rest(i, y) && self.points[i].closed_at != now
    }

    /// dy/dt at state `y` into `dy`. With `probe`, notes the points and
    /// patches whose mode's condition fails at `y` (see events.rs).
    pub(super) fn eval(&mut self, y: &[f64], dy: &mut [f64], probe: bool) {
        let lay = self.layout;
        let (acc, rest) = dy.split_at_mut(3 * lay.bodies);
        acc.fill(0.0);
        // 1. normal forces, with the friction of sliding patches
        let n = lay.contacts;
        let qs = &y[lay.q(0)..lay.q(0) + n];
        let (slots, _) = acc.as_chunks_mut::<3>();
        for ((row, point), &q) in self.rows.iter().zip(self.points.iter_mut()).zip(qs) {
            point.held_force = 0.0;
            let f = match point.mode {
                PointMode::Compress if q > 0.0 => row.law.force(q),
                PointMode::Expand => row.law.force(q),
                _ => 0.0,
            };
            point.force = f;
            if f != 0.0 {
                push_slots(row.inverse, row.a, row.b, &row.drive, f, slots);
            }
        }
        // 2. constraint forces
        if !self.constraints.is_empty() {
            self.constraints.solve(&self.bodies, acc);
            self.constraint_forces();
            self.stuck_loads();
        }
        // 3. compressions and impulses
        let (dq, rest) = rest.split_at_mut(n);
        let (dpn, rest) = rest.split_at_mut(n);
        let (dpt, time) = rest.split_at_mut(n);
        time[0] = 1.0;
        let (velocities, _) = y[..3 * lay.bodies].as_chunks::<3>();
        let rates = &mut self.rates[..n];
        let outputs = dq.iter_mut().zip(dpn.iter_mut()).zip(dpt.iter_mut());
        let inputs = self.rows.iter().zip(&self.points).zip(rates.iter_mut());
        for (((row, point), rate_out), ((dq, dpn), dpt)) in inputs.zip(outputs) {
            let rate = slot_rate(velocities, row.a, row.b, &row.normal);
            *rate_out = rate;
            let normal = point.force + point.held_force;
            *dq = match point.mode {
                PointMode::Held => 0.0,
                PointMode::Expand => row.law.compression_rate(rate, true),
                PointMode::Compress => -rate,
            };
            *dpn = normal;
            *dpt = match self.patch_modes[row.patch] {
                // shared in proportion to the load, or equally while the
                // patch carries none (its rows are identical, so any share
                // books the force the bodies received)
                PatchMode::Stick => {
                    let load = &self.patch_states[row.patch];
                    if load.normal > 0.0 {
                        load.friction * normal / load.normal
                    } else {
                        load.friction / self.patches[row.patch].count as f64
                    }
                }
                _ => row.slide * normal,
            };
        }
        if probe {
            let pns = &y[lay.pn(0)..lay.pn(0) + n];
            for (i, (&q, &pn)) in qs.iter().zip(pns).enumerate() {
                let rate = self.rates[i];
                self.probe_point(i, q, rate, pn);
            }
            self.probe_patches(y);
        }
    }

    /// The solved constraint forces: λ of held points, the friction of
    /// stuck patches.
    fn constraint_forces(&mut self) {
        for k in 0..self.constraints.len() {
            let (target, force) = self.constraints.force(k);
            match target {
                super::constraints::Target::Held(i) => self.points[i].held_force = force,
                super::constraints::Target::Stick(p) => self.patch_states[p].friction = force,
            }
        }
    }

    /// The normal load N = Σ (F + λ) of each stuck patch (N); only stuck
    /// patches need it (their friction is shared in proportion, and bounded
    /// by μ_s N).
    fn stuck_loads(&mut self) {
        for (p, patch) in self.patches.iter().enumerate() {
            if matches!(self.patch_modes[p], PatchMode::Stick) {
                let members = &self.members[patch.first..patch.first + patch.count];
                self.patch_states[p].normal = members
                    .iter()
                    .map(|&i| self.points[i].force + self.points[i].held_force)
                    .sum();
            }
        }
    }

    /// Notes a point whose mode's condition fails at a trial point (see
    /// events.rs).
    #[inline]
    fn probe_point(&mut self, i: usize, q: f64, rate: f64, pn: f64) {
        let thr = self.scales.rate;
        let point = &self.points[i];
        let row = &self.rows[i];
        let fails = match point.mode {
            PointMode::Compress => {
                (rate > thr && q > row.q_load)
                    || (point.open
                        && q > point.close_at
                        && (rate < -self.scales.onset || self.onset_matters(i)))
            }
            PointMode::Expand => rate < -thr || q < -row.q_zero,
            PointMode::Held => point.held_force < 0.0 || pn > point.hold_limit,
        };
        if fails {
            self.suspect_point(i);
        }
    }

    /// Whether any point of patch `p` carries force at the last evaluation.
    fn patch_loaded(&self, p: usize) -> bool {
        let patch = &self.patches[p];
        self.members[patch.first..patch.first + patch.count]
            .iter()
            .any(|&i| self.points[i].force != 0.0 || self.points[i].held_force != 0.0)
    }

    /// Notes the patches whose mode's condition fails at a trial point.
    fn probe_patches(&mut self, y: &[f64]) {
        let thr = self.scales.rate;
        for p in 0..self.patches.len() {
            let patch = &self.patches[p];
            let fails = match self.patch_modes[p] {
                PatchMode::Idle => false,
                PatchMode::Slide(s) => {
                    // the slip's rate first: the cheaper of two pure conditions
                    s * rate(y, patch.a, patch.b, &patch.tangent) < -thr && self.patch_loaded(p)
                }
                PatchMode::Stick => {
                    let load = &self.patch_states[p];
                    !patch.no_slip() && load.friction.abs() > patch.stick_bound * load.normal
                }
            };
            if fails {
                self.suspect_patch(p);
            }
        }
    }
}
