//! The stepping loop of the LZB resolver.
//!
//! Data are flat: one [`Row`] of frozen geometry and one [`ContactState`] per
//! contact, one `[vx, vy, ω]` per body plus a last slot for the fixed world.
//! Each contact couples two bodies, so every pass below is O(contacts) and the
//! Delassus operator W = J M⁻¹ Jᵀ is never formed: W·dP is obtained by applying
//! dP to the body velocities and reading the contact rates back.
//!
//! One impulse step (errata §2–4):
//! 1. normal rates δ̇_i at the start of the step;
//! 2. the primary p: the contact with the largest stored energy E, or, when no
//!    contact holds energy, the one approaching fastest;
//! 3. increments: loaded contacts dP_i = h F_i(E_i)/F_p(E_p) (errata §1);
//!    closed contacts with E_i = 0 that approach join with
//!    dP_i = (h c_i / F_p)^(α_i+1) |δ̇_i|^α_i, the increment that stores
//!    E_i ≈ |δ̇_i| dP_i consistently with F_p (errata §3); the step is scaled so
//!    that no contact takes more than h;
//! 4. landing: the step is shortened so that it ends where a contact's
//!    compression ends, a contact's energy runs out, or a resting contact starts
//!    to approach (δ̇ is linear in the step length, the released energy
//!    quadratic);
//! 5. Coulomb friction, one Gauss–Seidel pass: a sticking contact stays stuck
//!    if that needs |dP_t| ≤ μ_s dP_n; otherwise it slides with |dP_t| = μ dP_n,
//!    and a sliding contact whose slip would reverse sticks instead;
//! 6. energies with the mid-step rate: dE = −δ̇ dP in compression,
//!    dE = −δ̇ dP / e² in expansion; e = 0 releases at once; E ≥ 0.
//!
//! A contact that has released its energy and separates opens a gap, tracked in
//! the impact's own time dt = dP_p / F_p; it takes part again only once the gap
//! has closed. This makes the e = 1 result equal to the compliant model
//! F = k δ^α integrated in time, separations and re-contacts included.

use super::{
    validate, Body, BodyVelocity, Contact, ContactImpulse, ImpactError, ImpactOutcome,
    ImpactSettings, StepControl, StopReason,
};

/// Frozen geometry and material of one contact.
#[derive(Clone, Copy, Debug, Default)]
struct Row {
    /// Body slots (the world is the last slot).
    a: usize,
    b: usize,
    normal: [f64; 2],
    tangent: [f64; 2],
    /// r×n and r×t for each body (r from the centre of mass to the point).
    a_rn: f64,
    a_rt: f64,
    b_rn: f64,
    b_rt: f64,
    /// Diagonal entries of the Delassus operator along n and t (1/kg).
    w_nn: f64,
    w_tt: f64,
    /// c = (α+1)^(α/(α+1)) k^(1/(α+1)), so F(E) = c E^(α/(α+1)).
    force_coeff: f64,
    /// α/(α+1).
    power: f64,
    exponent: f64,
    restitution: f64,
    friction: f64,
    stick_friction: f64,
    /// False when neither body can move: such a contact takes no part.
    movable: bool,
}

impl Row {
    #[inline]
    fn force(&self, stored_energy: f64) -> f64 {
        if stored_energy <= 0.0 {
            0.0
        } else {
            self.force_coeff * stored_energy.powf(self.power)
        }
    }
}

/// Evolving state of one contact.
#[derive(Clone, Copy, Debug, Default)]
struct ContactState {
    /// Stored potential energy E (J).
    energy: f64,
    normal_impulse: f64,
    tangent_impulse: f64,
    peak_energy: f64,
    /// Separation opened after release (m); the contact is closed while 0.
    gap: f64,
    /// Stick (true) or slip (false) for the friction law.
    sticking: bool,
}

/// Scales of one impact, fixed at its start.
#[derive(Clone, Copy, Debug, Default)]
struct Scales {
    /// P₀ (N·s), see [`StepControl::Fixed`].
    impulse: f64,
    /// Largest approach speed at the start (m/s).
    velocity: f64,
    /// Kinetic energy at the start (J).
    energy: f64,
    /// Rates above −threshold count as not approaching (m/s).
    threshold: f64,
}

/// Landing fractions at or below this are not worth a step of their own.
const MIN_LANDING: f64 = 1e-9;

/// Relative differences below this are rounding, not truncation error.
const ROUNDING: f64 = 1e-13;

/// Result of one step attempt.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Step {
    /// Nothing is loaded and nothing closed approaches: the impact is over.
    Done,
    /// Advanced; `length` is the step actually taken in the units of h.
    Advanced { length: f64 },
}

/// Reusable LZB impact solver.
///
/// Keeps its buffers between calls, so resolving many impacts allocates only
/// when a problem is larger than any before it. The stepping loop itself never
/// allocates.
///
/// P₀, the impulse scale of [`StepControl`], is the larger of the magnitude of
/// the free bodies' total linear momentum (the paper's definition) and the
/// largest impulse that would stop one approaching contact on its own
/// (|δ̇_i| / W_ii); the second matters when the momentum is zero, as for two
/// bodies meeting head-on.
///
/// ```
/// use topple::impact::{Body, Contact, ContactMaterial, ImpactSettings, ImpactSolver};
/// let mut solver = ImpactSolver::new();
/// // Newton's cradle of three balls (m = 1 kg, I irrelevant), e = 1
/// let bodies = [
///     Body::new(1.0, 1.0).with_velocity([1.0, 0.0]),
///     Body::new(1.0, 1.0).with_position([0.2, 0.0]),
///     Body::new(1.0, 1.0).with_position([0.4, 0.0]),
/// ];
/// let hertz = ContactMaterial::hertz(1e9);
/// let contacts = [
///     Contact::new([Some(0), Some(1)], [0.1, 0.0], [1.0, 0.0], hertz),
///     Contact::new([Some(1), Some(2)], [0.3, 0.0], [1.0, 0.0], hertz),
/// ];
/// let out = solver.solve(&bodies, &contacts, &ImpactSettings::adaptive(1e-6)).unwrap();
/// let total: f64 = out.bodies.iter().map(|b| b.velocity[0]).sum();
/// assert!((total - 1.0).abs() < 1e-9); // momentum
/// assert!(out.kinetic_energy_after <= out.kinetic_energy_before * (1.0 + 1e-9));
/// ```
#[derive(Debug, Default)]
pub struct ImpactSolver {
    rows: Vec<Row>,
    inv_mass: Vec<f64>,
    inv_inertia: Vec<f64>,
    /// Body velocities [vx, vy, ω]; the last slot is the world.
    velocity: Vec<[f64; 3]>,
    /// Trial velocities (landing prediction).
    trial: Vec<[f64; 3]>,
    state: Vec<ContactState>,
    /// δ̇ at the start of the step.
    rate: Vec<f64>,
    /// δ̇ change over the full (unlanded) step.
    rate_change: Vec<f64>,
    /// Normal increments of the step.
    increment: Vec<f64>,
    /// Improved Euler: state saved before the half step, mid-step energies.
    mid_velocity: Vec<[f64; 3]>,
    mid_state: Vec<ContactState>,
    mid_energy: Vec<f64>,
    /// Contacts whose last bit of energy is released without a step.
    released: Vec<bool>,
    scales: Scales,
    /// Impact time elapsed so far (s), from the contact law.
    elapsed: f64,
    // Adaptive mode: state at the start of the step and after the full step.
    saved_velocity: Vec<[f64; 3]>,
    saved_state: Vec<ContactState>,
    full_velocity: Vec<[f64; 3]>,
    full_state: Vec<ContactState>,
}

#[inline]
fn cross(r: [f64; 2], v: [f64; 2]) -> f64 {
    r[0] * v[1] - r[1] * v[0]
}

impl ImpactSolver {
    /// A solver with empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Resolves one impact and returns a new [`ImpactOutcome`].
    pub fn solve(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        settings: &ImpactSettings,
    ) -> Result<ImpactOutcome, ImpactError> {
        let mut out = ImpactOutcome::default();
        self.solve_into(bodies, contacts, settings, &mut out)?;
        Ok(out)
    }

    /// Resolves one impact into `out`, reusing its vectors.
    ///
    /// Errors: invalid input (checked before any stepping), the step limit, or
    /// a non-finite state. Fixed bodies keep their input velocity (they may be
    /// kinematic); a contact between two fixed bodies takes no part.
    pub fn solve_into(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        settings: &ImpactSettings,
        out: &mut ImpactOutcome,
    ) -> Result<(), ImpactError> {
        validate::check(bodies, contacts, settings)?;
        self.load(bodies, contacts);
        self.elapsed = 0.0;
        out.kinetic_energy_before = bodies.iter().map(Body::kinetic_energy).sum();
        out.steps = 0;
        out.rejected_steps = 0;

        let reason = if self.scales.velocity == 0.0 {
            StopReason::NoApproach
        } else {
            match settings.step_control {
                StepControl::Fixed { impulse_step } => {
                    self.run_fixed(impulse_step * self.scales.impulse, settings.max_steps, out)?
                }
                StepControl::Adaptive { tolerance } => {
                    self.run_adaptive(tolerance, settings.max_steps, out)?
                }
            }
        };

        out.stop_reason = Some(reason);
        out.duration = self.elapsed;
        out.bodies.clear();
        out.bodies
            .extend(self.velocity[..bodies.len()].iter().map(|v| BodyVelocity {
                velocity: [v[0], v[1]],
                angular_velocity: v[2],
            }));
        out.contacts.clear();
        out.contacts
            .extend(self.state.iter().map(|s| ContactImpulse {
                normal_impulse: s.normal_impulse,
                tangent_impulse: s.tangent_impulse,
                peak_energy: s.peak_energy,
            }));
        out.kinetic_energy_after = bodies
            .iter()
            .zip(&out.bodies)
            .filter(|(b, _)| !b.fixed)
            .map(|(b, v)| {
                let [vx, vy] = v.velocity;
                0.5 * b.mass * (vx * vx + vy * vy)
                    + 0.5 * b.inertia * v.angular_velocity * v.angular_velocity
            })
            .sum();
        Ok(())
    }

    /// Builds rows, velocities and scales; sizes every buffer.
    fn load(&mut self, bodies: &[Body], contacts: &[Contact]) {
        let world = bodies.len();
        self.inv_mass.clear();
        self.inv_inertia.clear();
        self.velocity.clear();
        for b in bodies {
            let (im, ii) = if b.fixed {
                (0.0, 0.0)
            } else {
                (1.0 / b.mass, 1.0 / b.inertia)
            };
            self.inv_mass.push(im);
            self.inv_inertia.push(ii);
            self.velocity
                .push([b.velocity[0], b.velocity[1], b.angular_velocity]);
        }
        self.inv_mass.push(0.0);
        self.inv_inertia.push(0.0);
        self.velocity.push([0.0; 3]);

        self.rows.clear();
        for c in contacts {
            let a = c.bodies[0].unwrap_or(world);
            let b = c.bodies[1].unwrap_or(world);
            let len = c.normal[0].hypot(c.normal[1]);
            let normal = [c.normal[0] / len, c.normal[1] / len];
            let tangent = [-normal[1], normal[0]];
            let arm = |slot: usize| {
                if slot == world {
                    [0.0, 0.0]
                } else {
                    let p = bodies[slot].position;
                    [c.point[0] - p[0], c.point[1] - p[1]]
                }
            };
            let (ra, rb) = (arm(a), arm(b));
            let (a_rn, a_rt, b_rn, b_rt) = (
                cross(ra, normal),
                cross(ra, tangent),
                cross(rb, normal),
                cross(rb, tangent),
            );
            let w = |rn_a: f64, rn_b: f64| {
                self.inv_mass[a]
                    + rn_a * rn_a * self.inv_inertia[a]
                    + self.inv_mass[b]
                    + rn_b * rn_b * self.inv_inertia[b]
            };
            let m = &c.material;
            let a1 = m.exponent + 1.0;
            let w_nn = w(a_rn, b_rn);
            self.rows.push(Row {
                a,
                b,
                normal,
                tangent,
                a_rn,
                a_rt,
                b_rn,
                b_rt,
                w_nn,
                w_tt: w(a_rt, b_rt),
                force_coeff: a1.powf(m.exponent / a1) * m.stiffness.powf(1.0 / a1),
                power: m.exponent / a1,
                exponent: m.exponent,
                restitution: m.restitution,
                friction: m.friction,
                stick_friction: m.stick_friction,
                movable: w_nn > 0.0,
            });
        }

        let n = self.rows.len();
        let nb = self.velocity.len();
        self.trial.resize(nb, [0.0; 3]);
        self.saved_velocity.resize(nb, [0.0; 3]);
        self.full_velocity.resize(nb, [0.0; 3]);
        self.rate.resize(n, 0.0);
        self.rate_change.resize(n, 0.0);
        self.increment.resize(n, 0.0);
        self.mid_velocity.resize(nb, [0.0; 3]);
        self.mid_state.resize(n, ContactState::default());
        self.mid_energy.resize(n, 0.0);
        self.released.clear();
        self.released.resize(n, false);
        self.state.clear();
        self.state.resize(n, ContactState::default());
        self.saved_state.resize(n, ContactState::default());
        self.full_state.resize(n, ContactState::default());

        // Scales: P₀, the velocity scale and the approach threshold.
        let mut momentum = [0.0, 0.0];
        let mut energy = 0.0;
        for b in bodies.iter().filter(|b| !b.fixed) {
            momentum[0] += b.mass * b.velocity[0];
            momentum[1] += b.mass * b.velocity[1];
            energy += b.kinetic_energy();
        }
        let mut speed: f64 = 0.0;
        let mut stopping_impulse: f64 = 0.0;
        for (i, row) in self.rows.iter().enumerate() {
            if !row.movable {
                continue;
            }
            let rate = Self::normal_rate(row, &self.velocity);
            if rate < 0.0 && self.state[i].gap == 0.0 {
                speed = speed.max(-rate);
                stopping_impulse = stopping_impulse.max(-rate / row.w_nn);
            }
        }
        let softest = self.rows.iter().map(|r| r.w_nn).fold(0.0, f64::max);
        self.scales = Scales {
            impulse: momentum[0].hypot(momentum[1]).max(stopping_impulse),
            velocity: speed,
            // The kinetic energy, or the energy of the fastest approach on the
            // most mobile contact when the bodies' own energy is smaller.
            energy: energy.max(0.5 * speed * speed / softest.max(1e-300)),
            // Relative rounding noise left after landing on a switch.
            threshold: 1e-9 * speed,
        };
        // Contacts that start without slip are sticking.
        for (i, row) in self.rows.iter().enumerate() {
            if row.movable {
                let rt = Self::tangent_rate(row, &self.velocity);
                self.state[i].sticking = rt.abs() <= self.scales.threshold;
            }
        }
    }

    /// δ̇ = n·(v_b + ω_b × r_b − v_a − ω_a × r_a) (m/s).
    #[inline]
    fn normal_rate(row: &Row, v: &[[f64; 3]]) -> f64 {
        let (va, vb) = (v[row.a], v[row.b]);
        row.normal[0] * (vb[0] - va[0]) + row.normal[1] * (vb[1] - va[1]) + vb[2] * row.b_rn
            - va[2] * row.a_rn
    }

    /// Tangential relative velocity along t (m/s).
    #[inline]
    fn tangent_rate(row: &Row, v: &[[f64; 3]]) -> f64 {
        let (va, vb) = (v[row.a], v[row.b]);
        row.tangent[0] * (vb[0] - va[0]) + row.tangent[1] * (vb[1] - va[1]) + vb[2] * row.b_rt
            - va[2] * row.a_rt
    }

    /// Applies impulse `p` along `dir` (arms `rn_a`, `rn_b`) to the row's bodies.
    #[inline]
    fn apply(
        row: &Row,
        dir: [f64; 2],
        arm_a: f64,
        arm_b: f64,
        p: f64,
        inv_mass: &[f64],
        inv_inertia: &[f64],
        v: &mut [[f64; 3]],
    ) {
        let (ma, ia) = (inv_mass[row.a] * p, inv_inertia[row.a] * p);
        let va = &mut v[row.a];
        va[0] -= ma * dir[0];
        va[1] -= ma * dir[1];
        va[2] -= ia * arm_a;
        let (mb, ib) = (inv_mass[row.b] * p, inv_inertia[row.b] * p);
        let vb = &mut v[row.b];
        vb[0] += mb * dir[0];
        vb[1] += mb * dir[1];
        vb[2] += ib * arm_b;
    }

    /// The paper's scheme: steps of primary impulse `h` until the impact ends.
    fn run_fixed(
        &mut self,
        h: f64,
        max_steps: usize,
        out: &mut ImpactOutcome,
    ) -> Result<StopReason, ImpactError> {
        loop {
            match self.step(h, true) {
                Step::Done => return Ok(StopReason::Released),
                Step::Advanced { .. } => {
                    out.steps += 1;
                    if out.steps >= max_steps {
                        return Err(ImpactError::StepLimit { steps: out.steps });
                    }
                    if out.steps % 4096 == 0 && !self.finite() {
                        return Err(ImpactError::NonFinite { steps: out.steps });
                    }
                }
            }
        }
    }

    fn finite(&self) -> bool {
        self.velocity.iter().flatten().all(|x| x.is_finite())
            && self.state.iter().all(|s| s.energy.is_finite())
    }

    /// One step of length `h` (N·s): the improved-Euler scheme in the impulse
    /// variable. A half Euler step predicts the stored energies at mid-step;
    /// the full step then distributes its impulse by the ratios F_i/F_p of those
    /// mid-step energies. Second order in h, like the paper's improved Euler in
    /// time.
    fn step(&mut self, h: f64, land: bool) -> Step {
        self.mid_velocity.copy_from_slice(&self.velocity);
        self.mid_state.copy_from_slice(&self.state);
        let elapsed = self.elapsed;
        if self.euler_step(0.5 * h, false, false) == Step::Done {
            return Step::Done;
        }
        self.elapsed = elapsed;
        for (m, s) in self.mid_energy.iter_mut().zip(&self.state) {
            *m = s.energy;
        }
        self.velocity.copy_from_slice(&self.mid_velocity);
        self.state.copy_from_slice(&self.mid_state);
        self.euler_step(h, land, true)
    }

    /// One explicit step of length at most `h` (N·s); see the module doc. With
    /// `from_mid`, the ratios use the energies in `mid_energy` where positive.
    fn euler_step(&mut self, h: f64, land: bool, from_mid: bool) -> Step {
        let threshold = self.scales.threshold;
        let n = self.rows.len();

        // 1. rates; 2. primary.
        let mut primary = usize::MAX;
        let mut largest_energy = 0.0;
        let mut fastest = usize::MAX;
        let mut fastest_rate = -threshold;
        for i in 0..n {
            let row = &self.rows[i];
            if !row.movable {
                continue;
            }
            let rate = Self::normal_rate(row, &self.velocity);
            self.rate[i] = rate;
            let s = &mut self.state[i];
            // e = 0: the energy is lost as soon as expansion starts.
            if s.energy > 0.0 && rate >= -threshold && row.restitution == 0.0 {
                s.energy = 0.0;
            }
            if s.energy > largest_energy {
                largest_energy = s.energy;
                primary = i;
            }
            if s.energy == 0.0 && s.gap == 0.0 && rate < fastest_rate {
                fastest_rate = rate;
                fastest = i;
            }
        }
        if primary == usize::MAX && fastest == usize::MAX {
            // Only open gaps approach: fly freely until the first one closes.
            match self.free_flight() {
                Some(closing) => {
                    fastest = closing;
                    fastest_rate = self.rate[closing];
                }
                None => return Step::Done,
            }
        }
        if from_mid {
            let mut largest_mid = 0.0;
            for (i, &e) in self.mid_energy.iter().enumerate() {
                if e > largest_mid && self.rows[i].movable {
                    largest_mid = e;
                    primary = i;
                }
            }
            if largest_mid > 0.0 {
                largest_energy = largest_mid;
            }
        }
        let (primary, primary_force) = if primary != usize::MAX {
            (primary, self.rows[primary].force(largest_energy))
        } else {
            // Nothing loaded: start from the fastest approach (errata §3).
            let row = &self.rows[fastest];
            (fastest, row.force(-fastest_rate * h))
        };

        // 3. increments.
        let mut largest = 0.0f64;
        for i in 0..n {
            let row = &self.rows[i];
            let s = &self.state[i];
            let rate = self.rate[i];
            let ratio_energy = if from_mid && self.mid_energy[i] > 0.0 {
                self.mid_energy[i]
            } else {
                s.energy
            };
            let inc = if !row.movable {
                0.0
            } else if ratio_energy > 0.0 {
                h * row.force(ratio_energy) / primary_force
            } else if s.gap == 0.0 && rate < -threshold {
                (h * row.force_coeff / primary_force).powf(row.exponent + 1.0)
                    * (-rate).powf(row.exponent)
            } else {
                0.0
            };
            self.increment[i] = inc;
            largest = largest.max(inc);
        }
        let scale = if largest > h { h / largest } else { 1.0 };

        // 4. landing on the first switch inside the step.
        let step_time = self.increment[primary] * scale / primary_force;
        let mut length = 1.0f64;
        let mut released_now = false;
        if land {
            self.trial.copy_from_slice(&self.velocity);
            for i in 0..n {
                let inc = self.increment[i] * scale;
                if inc > 0.0 {
                    let row = &self.rows[i];
                    Self::apply(
                        row,
                        row.normal,
                        row.a_rn,
                        row.b_rn,
                        inc,
                        &self.inv_mass,
                        &self.inv_inertia,
                        &mut self.trial,
                    );
                }
            }
            for i in 0..n {
                let row = &self.rows[i];
                if !row.movable {
                    continue;
                }
                let rate = self.rate[i];
                let change = Self::normal_rate(row, &self.trial) - rate;
                self.rate_change[i] = change;
                let inc = self.increment[i] * scale;
                let s = &self.state[i];
                let at = if inc > 0.0 && rate < -threshold && rate + change > 0.0 {
                    // compression ends
                    -rate / change
                } else if inc > 0.0 && rate >= -threshold && s.energy > 0.0 {
                    // expansion: release(σ) = σ inc (rate + σ change / 2) / e² reaches E
                    let e2 = row.restitution * row.restitution;
                    let (qa, qb, qc) = (0.5 * inc * change, inc * rate, -e2 * s.energy);
                    if qa + qb + qc > 0.0 {
                        let at = smallest_positive_root(qa, qb, qc);
                        if at <= MIN_LANDING {
                            // Too little energy left to be worth a step: it is
                            // released (dissipated) at once, without impulse.
                            released_now = true;
                            self.released[i] = true;
                        }
                        at
                    } else {
                        1.0
                    }
                } else if inc == 0.0
                    && s.energy == 0.0
                    && s.gap == 0.0
                    && rate + change < -threshold
                {
                    // a resting closed contact starts to approach: land just
                    // past the threshold so that it joins in the next step
                    ((rate + 2.0 * threshold) / -change).max(0.0)
                } else if inc == 0.0 && s.energy == 0.0 && s.gap > 0.0 {
                    // an open gap closes: gap(σ) = g + dt (δ̇ σ + Δ σ²/2), with
                    // the step's time estimated at the primary's ratio energy
                    let (qa, qb, qc) = (-0.5 * change * step_time, -rate * step_time, -s.gap);
                    if qa + qb + qc > 0.0 {
                        smallest_positive_root(qa, qb, qc)
                    } else {
                        1.0
                    }
                } else {
                    1.0
                };
                if at > MIN_LANDING {
                    length = length.min(at);
                }
            }
            // v(σ) is linear in σ.
            for (v, t) in self.velocity.iter_mut().zip(&self.trial) {
                for k in 0..3 {
                    v[k] += length * (t[k] - v[k]);
                }
            }
            if released_now {
                for i in 0..n {
                    if self.released[i] {
                        self.released[i] = false;
                        let row = &self.rows[i];
                        Self::apply(
                            row,
                            row.normal,
                            row.a_rn,
                            row.b_rn,
                            -self.increment[i] * scale * length,
                            &self.inv_mass,
                            &self.inv_inertia,
                            &mut self.velocity,
                        );
                        self.increment[i] = 0.0;
                        self.state[i].energy = 0.0;
                    }
                }
            }
        } else {
            for i in 0..n {
                let inc = self.increment[i] * scale;
                if inc > 0.0 {
                    let row = &self.rows[i];
                    Self::apply(
                        row,
                        row.normal,
                        row.a_rn,
                        row.b_rn,
                        inc,
                        &self.inv_mass,
                        &self.inv_inertia,
                        &mut self.velocity,
                    );
                }
            }
        }
        let factor = scale * length;
        for inc in &mut self.increment[..n] {
            *inc *= factor;
        }

        // 5. Coulomb friction, one Gauss–Seidel pass.
        for i in 0..n {
            let inc = self.increment[i];
            let row = &self.rows[i];
            if inc <= 0.0 || row.w_tt <= 0.0 || (row.friction == 0.0 && row.stick_friction == 0.0) {
                continue;
            }
            let slip = Self::tangent_rate(row, &self.velocity);
            let needed = -slip / row.w_tt;
            let s = &mut self.state[i];
            let dpt = if s.sticking && needed.abs() <= row.stick_friction * inc {
                needed
            } else if needed.abs() <= row.friction * inc {
                s.sticking = true;
                needed
            } else {
                s.sticking = false;
                needed.signum() * row.friction * inc
            };
            s.tangent_impulse += dpt;
            Self::apply(
                row,
                row.tangent,
                row.a_rt,
                row.b_rt,
                dpt,
                &self.inv_mass,
                &self.inv_inertia,
                &mut self.velocity,
            );
        }

        // 6. energies with the mid-step rate (the end rates go to `rate_change`).
        let primary_energy_before = self.state[primary].energy;
        let mut primary_energy_raw = primary_energy_before;
        for i in 0..n {
            let row = &self.rows[i];
            if !row.movable {
                continue;
            }
            let end = Self::normal_rate(row, &self.velocity);
            self.rate_change[i] = end;
            let inc = self.increment[i];
            if inc > 0.0 {
                let mid = 0.5 * (self.rate[i] + end);
                let s = &mut self.state[i];
                s.normal_impulse += inc;
                if mid < 0.0 {
                    s.energy -= mid * inc;
                } else if row.restitution > 0.0 {
                    s.energy -= mid * inc / (row.restitution * row.restitution);
                } else {
                    s.energy = 0.0;
                }
                if i == primary {
                    primary_energy_raw = s.energy;
                }
                s.energy = s.energy.max(0.0);
                s.peak_energy = s.peak_energy.max(s.energy);
            }
        }

        // Impact time of the step, dt = ∫ dP_p / F_p(E_p), with E_p linear in
        // P_p over the step (exact at the singular start E_p = 0).
        let dt = {
            let row = &self.rows[primary];
            let inc = self.increment[primary];
            let e0 = primary_energy_before;
            let slope = (primary_energy_raw - e0) / inc;
            let e1 = primary_energy_raw.max(0.0);
            let rise = 1.0 - row.power;
            if inc == 0.0 {
                0.0
            } else if (slope * inc).abs() <= 1e-12 * e0.max(e1) {
                inc / row.force(e0.max(e1))
            } else {
                // until E_p reaches zero if it runs out inside the step
                (e1.powf(rise) - e0.powf(rise)) / (row.force_coeff * rise * slope)
            }
        };
        self.elapsed += dt;

        // Gaps of the contacts that carry no energy.
        for i in 0..n {
            let s = &mut self.state[i];
            if self.rows[i].movable && self.increment[i] == 0.0 && s.energy == 0.0 && dt.is_finite()
            {
                let mid = 0.5 * (self.rate[i] + self.rate_change[i]);
                s.gap = s.gap + mid * dt;
                // closed when what is left is rounding of the landing
                if s.gap <= 1e-9 * (mid.abs() * dt) {
                    s.gap = 0.0;
                }
            }
        }
        Step::Advanced { length: length * h }
    }

    /// When nothing is loaded and no closed contact approaches, but open gaps
    /// do: advances every gap by δ̇·t for the free-flight time t until the first
    /// one closes (velocities do not change) and returns that contact. The gaps
    /// are microscopic (positions are frozen), so this is the same impact.
    fn free_flight(&mut self) -> Option<usize> {
        let threshold = self.scales.threshold;
        let mut first = None;
        let mut shortest = f64::INFINITY;
        for (i, s) in self.state.iter().enumerate() {
            let rate = self.rate[i];
            if self.rows[i].movable && s.gap > 0.0 && rate < -threshold {
                let t = s.gap / -rate;
                if t < shortest {
                    shortest = t;
                    first = Some(i);
                }
            }
        }
        let first = first?;
        for (i, s) in self.state.iter_mut().enumerate() {
            if self.rows[i].movable && s.energy == 0.0 {
                s.gap = (s.gap + self.rate[i] * shortest).max(0.0);
            }
        }
        self.state[first].gap = 0.0;
        self.elapsed += shortest;
        Some(first)
    }

    /// Step doubling with Richardson extrapolation: the fixed step is first
    /// order in h, so two half steps against one full step estimate the local
    /// error, and 2·(halves) − (full) is second order.
    fn run_adaptive(
        &mut self,
        tolerance: f64,
        max_steps: usize,
        out: &mut ImpactOutcome,
    ) -> Result<StopReason, ImpactError> {
        let p0 = self.scales.impulse;
        let mut h = p0 * tolerance.sqrt().min(1e-2);
        let h_min = p0 * 1e-14;
        let mut attempts = 0usize;
        loop {
            attempts += 1;
            if attempts >= max_steps {
                return Err(ImpactError::StepLimit { steps: out.steps });
            }
            self.saved_velocity.copy_from_slice(&self.velocity);
            self.saved_state.copy_from_slice(&self.state);
            let elapsed = self.elapsed;
            // The step length is the largest increment any contact takes.
            let taken = match self.step(h, true) {
                Step::Done => return Ok(StopReason::Released),
                Step::Advanced { length } => length,
            };
            std::mem::swap(&mut self.full_velocity, &mut self.velocity);
            std::mem::swap(&mut self.full_state, &mut self.state);
            self.velocity.copy_from_slice(&self.saved_velocity);
            self.state.copy_from_slice(&self.saved_state);
            self.elapsed = elapsed;
            // Two half steps without landing: the full step already stops short
            // of the next switch.
            let half = 0.5 * taken;
            let mut finished = false;
            for _ in 0..2 {
                if self.step(half, false) == Step::Done {
                    finished = true;
                    break;
                }
            }
            // Differences at the level of rounding are no error; the allowed
            // error per step never falls below that level either.
            let error = (self.difference() - ROUNDING).max(0.0);
            // Error per unit step: the global error stays near `tolerance`
            // times the total impulse over P₀.
            let allowed = (tolerance * taken / p0).max(ROUNDING);
            if error <= allowed || h <= h_min {
                // Halves that ended the impact are kept as they are.
                if !finished {
                    self.extrapolate();
                }
                out.steps += 1;
                if out.steps % 4096 == 0 && !self.finite() {
                    return Err(ImpactError::NonFinite { steps: out.steps });
                }
                // local error ∝ h³ against an allowance ∝ h
                let grow = if error > 0.0 {
                    0.9 * (allowed / error).sqrt()
                } else {
                    4.0
                };
                h = (taken * grow.clamp(0.2, 4.0)).max(h_min);
            } else {
                out.rejected_steps += 1;
                self.velocity.copy_from_slice(&self.saved_velocity);
                self.state.copy_from_slice(&self.saved_state);
                self.elapsed = elapsed;
                let shrink = 0.9 * (allowed / error).sqrt();
                h = (taken * shrink.clamp(0.1, 0.9)).max(h_min);
            }
        }
    }

    /// Local error estimate between the full step (`full_*`) and the two half
    /// steps (current): contact rates relative to the velocity scale, stored
    /// energies relative to the energy scale.
    fn difference(&self) -> f64 {
        let mut error: f64 = 0.0;
        for (i, row) in self.rows.iter().enumerate() {
            if !row.movable {
                continue;
            }
            let dn = Self::normal_rate(row, &self.velocity)
                - Self::normal_rate(row, &self.full_velocity);
            let dt = Self::tangent_rate(row, &self.velocity)
                - Self::tangent_rate(row, &self.full_velocity);
            let de = self.state[i].energy - self.full_state[i].energy;
            // A gap error shifts a re-contact by dg / V: compare with the time
            // the impact has lasted.
            let dg = self.state[i].gap - self.full_state[i].gap;
            error = error
                .max(dn.abs() / self.scales.velocity)
                .max(dt.abs() / self.scales.velocity)
                .max(de.abs() / self.scales.energy)
                .max(dg.abs() / (self.scales.velocity * self.elapsed.max(1e-300)));
        }
        // Richardson: the halves' error is (y_half − y_full) / (2² − 1).
        error / 3.0
    }

    /// Richardson for the second-order step: y ← (4·y_half − y_full)/3 for
    /// velocities, energies, impulses and open gaps.
    fn extrapolate(&mut self) {
        let mix = |half: f64, full: f64| (4.0 * half - full) / 3.0;
        for (v, f) in self.velocity.iter_mut().zip(&self.full_velocity) {
            for k in 0..3 {
                v[k] = mix(v[k], f[k]);
            }
        }
        for (s, f) in self.state.iter_mut().zip(&self.full_state) {
            if s.energy > 0.0 && f.energy > 0.0 {
                s.energy = mix(s.energy, f.energy).max(0.0);
            } else {
                s.energy = 0.0;
            }
            if s.gap > 0.0 && f.gap > 0.0 {
                s.gap = mix(s.gap, f.gap).max(0.0);
            }
            s.normal_impulse = mix(s.normal_impulse, f.normal_impulse).max(0.0);
            s.tangent_impulse = mix(s.tangent_impulse, f.tangent_impulse);
            s.peak_energy = s.peak_energy.max(s.energy);
        }
    }
}

/// Smallest root in (0, 1] of a σ² + b σ + c with c < 0 < a + b + c.
fn smallest_positive_root(a: f64, b: f64, c: f64) -> f64 {
    if a.abs() < 1e-14 * b.abs().max(1e-300) {
        return (-c / b).clamp(0.0, 1.0);
    }
    let disc = (b * b - 4.0 * a * c).max(0.0).sqrt();
    // Numerically stable pair of roots.
    let q = -0.5 * (b + b.signum() * disc);
    let (r1, r2) = (q / a, c / q);
    [r1, r2]
        .into_iter()
        .filter(|r| *r > 0.0 && *r <= 1.0)
        .fold(1.0, f64::min)
}
