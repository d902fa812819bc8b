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

use super::load::{Axis, BodySlot, Row};
use super::{Integrator, PatchMode, PointMode};

/// Adds force `f` along `axis` (−f on body `a`, +f on body `b`) to the
/// accelerations `acc` ([ax, ay, α] per body slot).
#[inline]
pub(super) fn push(bodies: &[BodySlot], a: usize, b: usize, axis: &Axis, f: f64, acc: &mut [f64]) {
    let (sa, sb) = (&bodies[a], &bodies[b]);
    let (ma, ia) = (sa.inv_mass * f, sa.inv_inertia * f);
    acc[3 * a] -= ma * axis.dir[0];
    acc[3 * a + 1] -= ma * axis.dir[1];
    acc[3 * a + 2] -= ia * axis.arm_a;
    let (mb, ib) = (sb.inv_mass * f, sb.inv_inertia * f);
    acc[3 * b] += mb * axis.dir[0];
    acc[3 * b + 1] += mb * axis.dir[1];
    acc[3 * b + 2] += ib * axis.arm_b;
}

/// Relative rate along `axis` of body `b` against body `a` in the velocities
/// (or accelerations) `v`: dir·(v_b − v_a) + ω_b arm_b − ω_a arm_a.
#[inline]
pub(super) fn rate(v: &[f64], a: usize, b: usize, axis: &Axis) -> f64 {
    axis.dir[0] * (v[3 * b] - v[3 * a]) + axis.dir[1] * (v[3 * b + 1] - v[3 * a + 1])
        + v[3 * b + 2] * axis.arm_b
        - v[3 * a + 2] * axis.arm_a
}

/// Normal rate δ̇ of a row (m/s).
#[inline]
pub(super) fn normal_rate(row: &Row, v: &[f64]) -> f64 {
    rate(v, row.a, row.b, &row.normal)
}

impl Integrator {
    /// Whether point `i` starting to load must be a switch whatever its
    /// rate: its patch has no slip and no load yet (it sticks from then on).
    #[inline]
    pub(super) fn onset_matters(&self, i: usize) -> bool {
        let p = self.rows[i].patch;
        self.patches[p].no_slip() && self.patch_modes[p] == PatchMode::Idle
    }

    /// dy/dt at state `y` into `dy`. With `probe`, notes the points and
    /// patches whose mode's condition fails at `y` (see [`Integrator::suspect`]).
    pub(super) fn eval(&mut self, y: &[f64], dy: &mut [f64], probe: bool) {
        let lay = self.layout;
        dy[..3 * lay.bodies].fill(0.0);
        self.normal_forces(y, dy);
        if !self.constraints.is_empty() {
            self.constraints.solve(&self.bodies, dy);
            self.constraint_forces();
        }
        self.patch_states();
        dy[lay.time()] = 1.0;
        for i in 0..lay.contacts {
            let row = &self.rows[i];
            let point = &self.points[i];
            let rate = normal_rate(row, y);
            let normal = point.force + point.held_force;
            dy[lay.q(i)] = match point.mode {
                PointMode::Held => 0.0,
                PointMode::Expand => row.law.compression_rate(rate, true),
                PointMode::Compress => row.law.compression_rate(rate, false),
            };
            dy[lay.pn(i)] = normal;
            dy[lay.pt(i)] = match self.patch_modes[row.patch] {
                PatchMode::Idle => 0.0,
                PatchMode::Slide(s) => -self.patches[row.patch].friction * s * normal,
                PatchMode::Stick => {
                    let load = &self.patch_states[row.patch];
                    if load.normal > 0.0 {
                        load.friction * normal / load.normal
                    } else {
                        0.0
                    }
                }
            };
            if probe {
                self.probe_point(i, y[lay.q(i)], rate);
            }
        }
        if probe {
            self.probe_patches(y);
        }
    }

    /// Normal forces of the loaded points and the friction of sliding
    /// patches, into the accelerations.
    fn normal_forces(&mut self, y: &[f64], acc: &mut [f64]) {
        let lay = self.layout;
        for i in 0..lay.contacts {
            let row = &self.rows[i];
            let point = &mut self.points[i];
            point.held_force = 0.0;
            point.force = match point.mode {
                PointMode::Compress => row.law.force(y[lay.q(i)].max(0.0)),
                PointMode::Expand => row.law.force(y[lay.q(i)]),
                PointMode::Held => 0.0,
            };
            let f = point.force;
            if f == 0.0 {
                continue;
            }
            push(&self.bodies, row.a, row.b, &row.normal, f, acc);
            if let PatchMode::Slide(s) = self.patch_modes[row.patch] {
                let patch = &self.patches[row.patch];
                push(&self.bodies, row.a, row.b, &patch.tangent, -patch.friction * s * f, acc);
            }
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

    /// Each patch's normal load N = Σ (F + λ) of its points (N).
    fn patch_states(&mut self) {
        for (p, patch) in self.patches.iter().enumerate() {
            let members = &self.members[patch.first..patch.first + patch.count];
            let load = &mut self.patch_states[p];
            load.normal = members
                .iter()
                .map(|&i| self.points[i].force + self.points[i].held_force)
                .sum();
            if self.patch_modes[p] != PatchMode::Stick {
                load.friction = 0.0;
            }
        }
    }

    /// Notes a point whose mode's condition fails at a trial point (see
    /// events.rs).
    #[inline]
    fn probe_point(&mut self, i: usize, q: f64, rate: f64) {
        let thr = self.scales.rate;
        let point = &self.points[i];
        let row = &self.rows[i];
        let fails = match point.mode {
            PointMode::Compress => {
                (rate > thr && q > row.q_load)
                    || (point.open && q > 0.0 && (rate < -self.scales.onset || self.onset_matters(i)))
            }
            PointMode::Expand => rate < -thr || q < -row.q_zero,
            PointMode::Held => point.held_force < 0.0,
        };
        if fails {
            self.suspect_point(i);
        }
    }

    /// Notes the patches whose mode's condition fails at a trial point.
    fn probe_patches(&mut self, y: &[f64]) {
        let thr = self.scales.rate;
        for p in 0..self.patches.len() {
            let patch = &self.patches[p];
            let fails = match self.patch_modes[p] {
                PatchMode::Idle => false,
                PatchMode::Slide(s) => {
                    self.patch_states[p].normal > 0.0
                        && s * rate(y, patch.a, patch.b, &patch.tangent) < -thr
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
