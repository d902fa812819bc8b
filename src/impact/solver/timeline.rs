//! Adaptive mode: the LZB model integrated in the time of its contact law.
//!
//! The LZB distributing law dP_i/dP_p = F_i(E_i)/F_p(E_p) (errata §1) says that
//! every contact's impulse grows at the rate F_i(E_i) in a common time. In
//! that time, with the energy-equivalent compression w_i defined by
//! E_i = k_i w_i^(α_i+1)/(α_i+1), the model reads
//!
//! ```text
//! F_i = k_i w_i^α_i                        (paper Eq. 25, w_i > 0)
//! dw_i/dt = −δ̇_i / η_i,  η_i = 1 in compression, e_i² in expansion (Eqs. 22–24)
//! M dv/dt = Σ_i J_iᵀ (F_i n_i + F_t,i t_i)                        (Eq. 21)
//! ```
//!
//! since dE = k w^α dw = −η⁻¹ δ̇ F dt. A contact with w ≤ 0 is open: −w is its
//! micro-gap, which follows dw/dt = −δ̇ until it closes. Friction is Coulomb's
//! law in time: F_t = −μ sgn(v_t) F_n while sliding; while sticking, F_t keeps
//! v̇_t = 0 (projected Gauss–Seidel on the sticking set) as long as
//! |F_t| ≤ μ_s F_n.
//!
//! The right-hand side is smooth between events, so an embedded Runge–Kutta
//! pair (Bogacki–Shampine 3(2)) with step-size control integrates it; each
//! step has frozen modes, and a step that would cross an event (compression
//! ends, energy runs out, a gap closes, slip reverses, a stuck contact breaks
//! loose) is shortened to land on it, where the mode switches. e = 0 releases
//! the energy at once when compression ends.

use super::{Axis, ContactState, ImpactError, ImpactOutcome, ImpactSolver, Row, StopReason};

/// Normal law of a contact during one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) enum Normal {
    /// w ≤ 0: no force; the gap −w changes at −δ̇.
    #[default]
    Open,
    /// Loaded, δ̇ < 0: η = 1.
    Compression,
    /// Loaded, δ̇ ≥ 0: η = e².
    Expansion,
}

/// Friction law of a contact during one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) enum Tangent {
    #[default]
    Stick,
    /// Sliding with slip along +t (1.0) or −t (−1.0).
    Slide(f64),
}

/// Buffers of the time integration (kept between impacts).
#[derive(Debug, Default)]
pub(super) struct Timeline {
    y: Vec<f64>,
    y_new: Vec<f64>,
    y_stage: Vec<f64>,
    error: Vec<f64>,
    k1: Vec<f64>,
    k2: Vec<f64>,
    k3: Vec<f64>,
    k4: Vec<f64>,
    normal: Vec<Normal>,
    tangent: Vec<Tangent>,
    force_n: Vec<f64>,
    force_t: Vec<f64>,
    start_n: Vec<f64>,
    start_t: Vec<f64>,
    slots: usize,
    contacts: usize,
}

// Bogacki–Shampine 3(2) coefficients.
const A21: f64 = 0.5;
const A32: f64 = 0.75;
const B1: f64 = 2.0 / 9.0;
const B2: f64 = 1.0 / 3.0;
const B3: f64 = 4.0 / 9.0;
const E1: f64 = 2.0 / 9.0 - 7.0 / 24.0;
const E2: f64 = 1.0 / 3.0 - 1.0 / 4.0;
const E3: f64 = 4.0 / 9.0 - 1.0 / 3.0;
const E4: f64 = -1.0 / 8.0;

/// Sticking Gauss–Seidel: sweeps at most, and the relative settling level.
const STICK_SWEEPS: usize = 200;
const STICK_SETTLED: f64 = 1e-14;

/// An event found inside a trial step.
#[derive(Clone, Copy, Debug)]
struct Event {
    contact: usize,
    /// Fraction of the step at which it happens.
    at: f64,
}

impl Timeline {
    fn w(&self) -> usize {
        3 * self.slots
    }
    fn pn(&self) -> usize {
        3 * self.slots + self.contacts
    }
    fn pt(&self) -> usize {
        3 * self.slots + 2 * self.contacts
    }
}

#[inline]
fn slot(y: &[f64], s: usize) -> [f64; 3] {
    [y[3 * s], y[3 * s + 1], y[3 * s + 2]]
}

/// Rate along `axis` of the row's relative motion, from a flat state.
#[inline]
fn rate(row: &Row, axis: Axis, y: &[f64]) -> f64 {
    let (va, vb) = (slot(y, row.a), slot(y, row.b));
    axis.dir[0] * (vb[0] - va[0]) + axis.dir[1] * (vb[1] - va[1]) + vb[2] * axis.arm_b
        - va[2] * axis.arm_a
}

#[inline]
fn push(row: &Row, axis: Axis, f: f64, inv_mass: &[f64], inv_inertia: &[f64], acc: &mut [f64]) {
    let (a, b) = (row.a, row.b);
    acc[3 * a] -= f * axis.dir[0] * inv_mass[a];
    acc[3 * a + 1] -= f * axis.dir[1] * inv_mass[a];
    acc[3 * a + 2] -= f * axis.arm_a * inv_inertia[a];
    acc[3 * b] += f * axis.dir[0] * inv_mass[b];
    acc[3 * b + 1] += f * axis.dir[1] * inv_mass[b];
    acc[3 * b + 2] += f * axis.arm_b * inv_inertia[b];
}

/// Friction mode of a contact that becomes loaded with slip `rt`.
#[inline]
fn friction_mode(rt: f64, threshold: f64) -> Tangent {
    if rt.abs() <= threshold {
        Tangent::Stick
    } else {
        Tangent::Slide(rt.signum())
    }
}

#[inline]
fn has_friction(row: &Row) -> bool {
    row.w_tt > 0.0 && (row.friction > 0.0 || row.stick_friction > 0.0)
}

impl ImpactSolver {
    /// Adaptive mode: see the module documentation.
    pub(super) fn run_timeline(
        &mut self,
        tolerance: f64,
        max_steps: usize,
        out: &mut ImpactOutcome,
    ) -> Result<StopReason, ImpactError> {
        self.timeline_load();
        let threshold = self.scales.threshold;
        let speed = self.scales.velocity;
        // Time scale: two-body contact duration of the fastest approach.
        let time_scale = self.contact_time_scale();
        let length = speed * time_scale;
        let mut h = time_scale * tolerance.cbrt().min(0.1) * 0.1;
        let h_min = time_scale * 1e-12;
        let mut t = 0.0;
        let mut attempts = 0usize;
        let mut landing = false;

        loop {
            if self.timeline_done(threshold) {
                break;
            }
            attempts += 1;
            if attempts >= max_steps {
                return Err(ImpactError::StepLimit { steps: out.steps });
            }
            // Free flight: nothing loaded, jump to the first closing gap.
            if self.timeline.normal.iter().all(|m| *m == Normal::Open) {
                match self.timeline_free_flight(threshold) {
                    Some((contact, dt)) => {
                        t += dt;
                        let row = &self.rows[contact];
                        let rt = rate(row, row.tangent_axis(), &self.timeline.y);
                        self.timeline.normal[contact] = Normal::Compression;
                        self.timeline.tangent[contact] = friction_mode(rt, threshold);
                        continue;
                    }
                    None => break,
                }
            }
            self.timeline_step(h);
            let error = self.timeline_error(speed, length);
            if error > tolerance && h > h_min {
                out.rejected_steps += 1;
                h = (h * (0.9 * (tolerance / error).cbrt()).clamp(0.1, 0.9)).max(h_min);
                continue;
            }
            // Land on the earliest event inside the step.
            if let Some(event) = self.timeline_event() {
                // A step aimed at an event lands on it when the event is found
                // in its last tenth; otherwise aim (just past) the event.
                let landed = if landing {
                    event.at >= 0.9
                } else {
                    event.at >= 1.0 - 1e-6
                };
                if !landed && h * event.at > h_min {
                    h *= event.at * (1.0 + 1e-6);
                    landing = true;
                    out.rejected_steps += 1;
                    continue;
                }
                landing = false;
                self.timeline_accept(&mut t, h, out);
                self.timeline_switch(event.contact);
            } else {
                landing = false;
                self.timeline_accept(&mut t, h, out);
            }
            let grow = if error > 0.0 {
                0.9 * (tolerance / error).cbrt()
            } else {
                5.0
            };
            h = (h * grow.clamp(0.2, 5.0)).max(h_min);
            if out.steps % 4096 == 0 && !self.timeline.y.iter().all(|x| x.is_finite()) {
                return Err(ImpactError::NonFinite { steps: out.steps });
            }
        }
        self.timeline_store(t);
        Ok(StopReason::Released)
    }

    fn contact_time_scale(&self) -> f64 {
        let v = self.scales.velocity;
        let mut shortest = f64::INFINITY;
        for row in &self.rows {
            if !row.movable {
                continue;
            }
            let meff = 1.0 / row.w_nn;
            let a1 = row.exponent + 1.0;
            // largest compression of a lone two-body contact: ½ m_eff v² = k w^(α+1)/(α+1)
            let dmax = (0.5 * meff * v * v * a1 / row.stiffness).powf(1.0 / a1);
            shortest = shortest.min(2.9 * dmax / v);
        }
        if shortest.is_finite() && shortest > 0.0 {
            shortest
        } else {
            1.0
        }
    }

    /// Flat state from the loaded problem; initial modes.
    fn timeline_load(&mut self) {
        let slots = self.velocity.len();
        let n = self.rows.len();
        let tl = &mut self.timeline;
        tl.slots = slots;
        tl.contacts = n;
        let len = 3 * slots + 3 * n;
        for v in [
            &mut tl.y,
            &mut tl.y_new,
            &mut tl.y_stage,
            &mut tl.error,
            &mut tl.k1,
            &mut tl.k2,
            &mut tl.k3,
            &mut tl.k4,
        ] {
            v.clear();
            v.resize(len, 0.0);
        }
        for v in [
            &mut tl.force_n,
            &mut tl.force_t,
            &mut tl.start_n,
            &mut tl.start_t,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
        for (s, v) in self.velocity.iter().enumerate() {
            tl.y[3 * s..3 * s + 3].copy_from_slice(v);
        }
        tl.normal.clear();
        tl.tangent.clear();
        let threshold = self.scales.threshold;
        for row in &self.rows {
            let rn = rate(row, row.normal_axis(), &tl.y);
            let rt = rate(row, row.tangent_axis(), &tl.y);
            tl.normal.push(if row.movable && rn < -threshold {
                Normal::Compression
            } else {
                Normal::Open
            });
            tl.tangent.push(friction_mode(rt, threshold));
        }
    }

    /// dy/dt at `y` with the current modes; forces go to `force_n`/`force_t`.
    fn timeline_rhs(&mut self, which: Stage) {
        let tl = &mut self.timeline;
        let (y, dy) = match which {
            Stage::K1 => (&tl.y, &mut tl.k1),
            Stage::K2 => (&tl.y_stage, &mut tl.k2),
            Stage::K3 => (&tl.y_stage, &mut tl.k3),
            Stage::K4 => (&tl.y_new, &mut tl.k4),
        };
        dy.iter_mut().for_each(|x| *x = 0.0);
        let (w_at, pn_at, pt_at) = (
            3 * tl.slots,
            3 * tl.slots + tl.contacts,
            3 * tl.slots + 2 * tl.contacts,
        );
        let mut sticking = false;
        for (i, row) in self.rows.iter().enumerate() {
            if !row.movable {
                tl.force_n[i] = 0.0;
                tl.force_t[i] = 0.0;
                continue;
            }
            let rn = rate(row, row.normal_axis(), y);
            let w = y[w_at + i];
            let (dw, f) = match tl.normal[i] {
                Normal::Open => (-rn, 0.0),
                Normal::Compression => (-rn, row.stiffness_force(w)),
                Normal::Expansion => (
                    -rn / (row.restitution * row.restitution),
                    row.stiffness_force(w),
                ),
            };
            dy[w_at + i] = dw;
            let ft = if f > 0.0 && has_friction(row) {
                match tl.tangent[i] {
                    Tangent::Slide(s) => -row.friction * s * f,
                    Tangent::Stick => {
                        sticking = true;
                        tl.force_t[i] // warm start, refined below
                    }
                }
            } else {
                0.0
            };
            tl.force_n[i] = f;
            tl.force_t[i] = ft;
            if f != 0.0 {
                push(
                    row,
                    row.normal_axis(),
                    f,
                    &self.inv_mass,
                    &self.inv_inertia,
                    dy,
                );
            }
            if ft != 0.0 {
                push(
                    row,
                    row.tangent_axis(),
                    ft,
                    &self.inv_mass,
                    &self.inv_inertia,
                    dy,
                );
            }
        }
        if sticking {
            // Sticking contacts: F_t such that the tangential acceleration is 0.
            let mut scale: f64 = 0.0;
            for (i, row) in self.rows.iter().enumerate() {
                scale = scale.max(tl.force_n[i] * row.w_tt.max(row.w_nn));
            }
            let settled = STICK_SETTLED * scale.max(1e-300);
            for _ in 0..STICK_SWEEPS {
                let mut largest: f64 = 0.0;
                for (i, row) in self.rows.iter().enumerate() {
                    if tl.tangent[i] != Tangent::Stick || tl.force_n[i] <= 0.0 || !has_friction(row)
                    {
                        continue;
                    }
                    let at = rate(row, row.tangent_axis(), dy);
                    let change = -at / row.w_tt;
                    tl.force_t[i] += change;
                    push(
                        row,
                        row.tangent_axis(),
                        change,
                        &self.inv_mass,
                        &self.inv_inertia,
                        dy,
                    );
                    largest = largest.max(at.abs());
                }
                if largest <= settled {
                    break;
                }
            }
        }
        // the world slot never moves
        let world = 3 * (tl.slots - 1);
        dy[world..world + 3].iter_mut().for_each(|x| *x = 0.0);
        let n = tl.contacts;
        dy[pn_at..pn_at + n].copy_from_slice(&tl.force_n);
        dy[pt_at..pt_at + n].copy_from_slice(&tl.force_t);
    }

    /// One Bogacki–Shampine step of length h from `y` into `y_new`, with the
    /// embedded error vector in `error`.
    fn timeline_step(&mut self, h: f64) {
        self.timeline_rhs(Stage::K1);
        let tl = &mut self.timeline;
        tl.start_n.copy_from_slice(&tl.force_n);
        tl.start_t.copy_from_slice(&tl.force_t);
        for j in 0..tl.y.len() {
            tl.y_stage[j] = tl.y[j] + h * A21 * tl.k1[j];
        }
        self.timeline_rhs(Stage::K2);
        let tl = &mut self.timeline;
        for j in 0..tl.y.len() {
            tl.y_stage[j] = tl.y[j] + h * A32 * tl.k2[j];
        }
        self.timeline_rhs(Stage::K3);
        let tl = &mut self.timeline;
        for j in 0..tl.y.len() {
            tl.y_new[j] = tl.y[j] + h * (B1 * tl.k1[j] + B2 * tl.k2[j] + B3 * tl.k3[j]);
        }
        self.timeline_rhs(Stage::K4);
        let tl = &mut self.timeline;
        for j in 0..tl.y.len() {
            tl.error[j] = h * (E1 * tl.k1[j] + E2 * tl.k2[j] + E3 * tl.k3[j] + E4 * tl.k4[j]);
        }
    }

    /// Error of the step in contact space: rates relative to the velocity
    /// scale, compressions relative to the length scale V·T.
    fn timeline_error(&self, speed: f64, length: f64) -> f64 {
        let tl = &self.timeline;
        let w_at = tl.w();
        let mut worst: f64 = 0.0;
        for (i, row) in self.rows.iter().enumerate() {
            if !row.movable {
                continue;
            }
            let en = rate(row, row.normal_axis(), &tl.error).abs() / speed;
            let et = rate(row, row.tangent_axis(), &tl.error).abs() / speed;
            let ew = tl.error[w_at + i].abs() / length;
            worst = worst.max(en).max(et).max(ew);
        }
        worst
    }

    /// The earliest mode change inside the trial step, if any.
    fn timeline_event(&self) -> Option<Event> {
        let tl = &self.timeline;
        let w_at = tl.w();
        let threshold = self.scales.threshold;
        let mut first: Option<Event> = None;
        let mut consider = |contact: usize, g0: f64, g1: f64| {
            if g1 < 0.0 && g0 >= g1 {
                let at = if g0 > 0.0 { g0 / (g0 - g1) } else { 0.0 };
                if first.is_none_or(|e| at < e.at) {
                    first = Some(Event { contact, at });
                }
            }
        };
        for (i, row) in self.rows.iter().enumerate() {
            if !row.movable {
                continue;
            }
            let (w0, w1) = (tl.y[w_at + i], tl.y_new[w_at + i]);
            let rn0 = rate(row, row.normal_axis(), &tl.y);
            let rn1 = rate(row, row.normal_axis(), &tl.y_new);
            match tl.normal[i] {
                Normal::Compression => consider(i, -rn0, -rn1),
                Normal::Expansion => consider(i, w0, w1),
                Normal::Open => {
                    // a gap closes while approaching
                    if rn1 < -threshold {
                        consider(i, -w0, -w1)
                    }
                }
            }
            if tl.normal[i] != Normal::Open && has_friction(row) && tl.force_n[i] > 0.0 {
                match tl.tangent[i] {
                    Tangent::Slide(s) => {
                        let rt0 = rate(row, row.tangent_axis(), &tl.y) * s;
                        let rt1 = rate(row, row.tangent_axis(), &tl.y_new) * s;
                        consider(i, rt0, rt1);
                    }
                    Tangent::Stick => {
                        let bound = row.stick_friction.max(row.friction);
                        let g0 = bound * tl.start_n[i] - tl.start_t[i].abs();
                        let g1 = bound * tl.force_n[i] - tl.force_t[i].abs();
                        consider(i, g0.max(0.0), g1);
                    }
                }
            }
        }
        first
    }

    fn timeline_accept(&mut self, t: &mut f64, h: f64, out: &mut ImpactOutcome) {
        *t += h;
        out.steps += 1;
        let tl = &mut self.timeline;
        std::mem::swap(&mut tl.y, &mut tl.y_new);
        let w_at = tl.w();
        for (i, row) in self.rows.iter().enumerate() {
            let w = tl.y[w_at + i];
            if w > 0.0 && tl.normal[i] != Normal::Open {
                let s = &mut self.state[i];
                s.peak_energy = s
                    .peak_energy
                    .max(row.stiffness_force(w) * w / (row.exponent + 1.0));
            }
        }
    }

    /// The mode change at the end of a step that landed on contact `i`'s event.
    fn timeline_switch(&mut self, i: usize) {
        let row = self.rows[i];
        let threshold = self.scales.threshold;
        let tl = &mut self.timeline;
        let w_at = tl.w();
        let rn = rate(&row, row.normal_axis(), &tl.y);
        let normal = tl.normal[i];
        match normal {
            Normal::Compression if rn >= -threshold => {
                if row.restitution > 0.0 {
                    tl.normal[i] = Normal::Expansion;
                } else {
                    // e = 0: the energy is lost when compression ends
                    tl.y[w_at + i] = 0.0;
                    tl.normal[i] = Normal::Open;
                }
            }
            Normal::Expansion if tl.y[w_at + i] <= 0.0 || rn < 0.0 => {
                tl.normal[i] = if rn < -threshold {
                    Normal::Compression
                } else {
                    Normal::Open
                };
            }
            Normal::Open if tl.y[w_at + i] >= 0.0 => {
                tl.normal[i] = Normal::Compression;
                let rt = rate(&row, row.tangent_axis(), &tl.y);
                tl.tangent[i] = friction_mode(rt, threshold);
            }
            _ => {}
        }
        if normal == tl.normal[i] {
            // the event was a friction one
            let rt = rate(&row, row.tangent_axis(), &tl.y);
            tl.tangent[i] = match tl.tangent[i] {
                Tangent::Slide(_) => {
                    tl.force_t[i] = 0.0;
                    Tangent::Stick
                }
                // breaks loose against the force that held it
                Tangent::Stick => {
                    let s = if rt.abs() > threshold {
                        rt.signum()
                    } else {
                        -tl.force_t[i].signum()
                    };
                    Tangent::Slide(s)
                }
            };
        }
    }

    fn timeline_done(&self, threshold: f64) -> bool {
        let tl = &self.timeline;
        self.rows.iter().enumerate().all(|(i, row)| {
            !row.movable
                || (tl.normal[i] == Normal::Open
                    && rate(row, row.normal_axis(), &tl.y) >= -threshold)
        })
    }

    /// With every contact open: the first gap to close and the time until it
    /// does; gaps advance by −δ̇·t. None when no gap closes.
    fn timeline_free_flight(&mut self, threshold: f64) -> Option<(usize, f64)> {
        let tl = &mut self.timeline;
        let w_at = tl.w();
        let mut first = None;
        let mut shortest = f64::INFINITY;
        for (i, row) in self.rows.iter().enumerate() {
            let rn = rate(row, row.normal_axis(), &tl.y);
            if row.movable && rn < -threshold {
                let t = (-tl.y[w_at + i]).max(0.0) / -rn;
                if t < shortest {
                    shortest = t;
                    first = Some(i);
                }
            }
        }
        let first = first?;
        for (i, row) in self.rows.iter().enumerate() {
            if row.movable {
                let rn = rate(row, row.normal_axis(), &tl.y);
                tl.y[w_at + i] -= rn * shortest;
            }
        }
        tl.y[w_at + first] = 0.0;
        Some((first, shortest))
    }

    /// Copies the time integration's result back into the solver's arrays.
    fn timeline_store(&mut self, t: f64) {
        let tl = &self.timeline;
        for (s, v) in self.velocity.iter_mut().enumerate() {
            *v = slot(&tl.y, s);
        }
        let (pn, pt) = (tl.pn(), tl.pt());
        for (i, s) in self.state.iter_mut().enumerate() {
            *s = ContactState {
                normal_impulse: tl.y[pn + i],
                tangent_impulse: tl.y[pt + i],
                peak_energy: s.peak_energy,
                ..ContactState::default()
            };
        }
        self.elapsed = t;
    }
}

#[derive(Clone, Copy)]
enum Stage {
    K1,
    K2,
    K3,
    K4,
}
