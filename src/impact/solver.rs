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

mod timeline;

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
    stiffness: f64,
    restitution: f64,
    friction: f64,
    stick_friction: f64,
    /// False when neither body can move: such a contact takes no part.
    movable: bool,
}

/// A direction of impulse with its moment arms r×dir on the two bodies.
#[derive(Clone, Copy, Debug)]
struct Axis {
    dir: [f64; 2],
    arm_a: f64,
    arm_b: f64,
}

impl Row {
    /// F = k w^α from the energy-equivalent compression w (m); 0 for w ≤ 0.
    #[inline]
    fn stiffness_force(&self, w: f64) -> f64 {
        if w <= 0.0 {
            0.0
        } else {
            self.stiffness * w.powf(self.exponent)
        }
    }

    #[inline]
    fn normal_axis(&self) -> Axis {
        Axis {
            dir: self.normal,
            arm_a: self.a_rn,
            arm_b: self.b_rn,
        }
    }

    #[inline]
    fn tangent_axis(&self) -> Axis {
        Axis {
            dir: self.tangent,
            arm_a: self.a_rt,
            arm_b: self.b_rt,
        }
    }

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
    /// e = 0 contact whose compression has ended without separating: held
    /// closed by a non-negative impulse (the sliding-mode limit of e = 0).
    held: bool,
}

/// Scales of one impact, fixed at its start.
#[derive(Clone, Copy, Debug, Default)]
struct Scales {
    /// P₀ (N·s), see [`StepControl::Fixed`].
    impulse: f64,
    /// Largest approach speed at the start (m/s).
    velocity: f64,
    /// Rates above −threshold count as not approaching (m/s).
    threshold: f64,
}

/// Landing fractions at or below this are not worth a step of their own.
const MIN_LANDING: f64 = 1e-9;

/// Friction sweeps per step at most, and the slip correction (relative to
/// the velocity scale) below which they stop.
const FRICTION_SWEEPS: usize = 16;
const FRICTION_SETTLED: f64 = 1e-13;

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
    /// Tangential and held normal increments of the step, stick state at its start.
    tangent_step: Vec<f64>,
    held_step: Vec<f64>,
    stuck_at_start: Vec<bool>,
    /// Contacts whose last bit of energy is released without a step.
    released: Vec<bool>,
    scales: Scales,
    /// Impact time elapsed so far (s), from the contact law.
    elapsed: f64,
    /// See [`ImpactSettings::e0_hold`].
    e0_hold: bool,
    /// Adaptive mode's buffers.
    timeline: timeline::Timeline,
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
        self.e0_hold = settings.e0_hold;
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
                    self.run_timeline(tolerance, settings.max_steps, out)?
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
                stiffness: m.stiffness,
                restitution: m.restitution,
                friction: m.friction,
                stick_friction: m.stick_friction,
                movable: w_nn > 0.0,
            });
        }

        let n = self.rows.len();
        let nb = self.velocity.len();
        self.trial.resize(nb, [0.0; 3]);
        self.rate.resize(n, 0.0);
        self.rate_change.resize(n, 0.0);
        self.increment.resize(n, 0.0);
        self.mid_velocity.resize(nb, [0.0; 3]);
        self.mid_state.resize(n, ContactState::default());
        self.mid_energy.resize(n, 0.0);
        self.tangent_step.resize(n, 0.0);
        self.held_step.resize(n, 0.0);
        self.stuck_at_start.clear();
        self.stuck_at_start.resize(n, false);
        self.released.clear();
        self.released.resize(n, false);
        self.state.clear();
        self.state.resize(n, ContactState::default());

        // Scales: P₀, the velocity scale and the approach threshold.
        let mut momentum = [0.0, 0.0];
        for b in bodies.iter().filter(|b| !b.fixed) {
            momentum[0] += b.mass * b.velocity[0];
            momentum[1] += b.mass * b.velocity[1];
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
        self.scales = Scales {
            impulse: momentum[0].hypot(momentum[1]).max(stopping_impulse),
            velocity: speed,
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

    /// Applies impulse `p` along `axis` to the row's bodies.
    #[inline]
    fn apply(
        row: &Row,
        axis: Axis,
        p: f64,
        inv_mass: &[f64],
        inv_inertia: &[f64],
        v: &mut [[f64; 3]],
    ) {
        let Axis { dir, arm_a, arm_b } = axis;
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
            // e = 0: the energy is lost when compression ends (errata §2).
            // With `e0_hold`, a contact that does not separate then is held
            // closed (a plastic unilateral constraint, see ImpactSettings).
            if row.restitution == 0.0 && s.energy > 0.0 && rate >= -threshold {
                s.energy = 0.0;
                s.held = self.e0_hold && rate <= threshold;
            }
            if s.held && rate < -threshold {
                // approaching again with nothing holding it: a new impact
                s.held = false;
            }
            if s.energy > largest_energy {
                largest_energy = s.energy;
                primary = i;
            }
            if s.energy == 0.0 && s.gap == 0.0 && !s.held && rate < fastest_rate {
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
            } else if s.gap == 0.0 && !s.held && rate < -threshold {
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
            apply_increments(
                &self.rows,
                &self.increment,
                scale,
                &self.inv_mass,
                &self.inv_inertia,
                &mut self.trial,
            );
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
                    && !s.held
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
                            row.normal_axis(),
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
            apply_increments(
                &self.rows,
                &self.increment,
                scale,
                &self.inv_mass,
                &self.inv_inertia,
                &mut self.velocity,
            );
        }
        let factor = scale * length;
        for inc in &mut self.increment[..n] {
            *inc *= factor;
        }

        // 5. Held contacts and Coulomb friction: projected Gauss–Seidel sweeps
        // over this step's held normal and tangential increments until the
        // corrections are rounding. A held contact takes the non-negative
        // impulse that keeps it from approaching. A contact sticking at the
        // start of the step stays stuck while that needs |dP_t| ≤ μ_s dP_n, a
        // sliding one sticks when |dP_t| ≤ μ dP_n stops its slip; otherwise
        // |dP_t| = μ dP_n against the slip.
        let mut sweeping = false;
        for i in 0..n {
            self.tangent_step[i] = 0.0;
            self.held_step[i] = 0.0;
            let row = &self.rows[i];
            let s = &self.state[i];
            self.stuck_at_start[i] = s.sticking;
            sweeping |= row.movable
                && (s.held
                    || (self.increment[i] > 0.0
                        && row.w_tt > 0.0
                        && (row.friction > 0.0 || row.stick_friction > 0.0)));
        }
        if sweeping {
            let settled = FRICTION_SETTLED * self.scales.velocity;
            for _sweep in 0..FRICTION_SWEEPS {
                let mut largest_change: f64 = 0.0;
                for i in 0..n {
                    let row = &self.rows[i];
                    if !row.movable {
                        continue;
                    }
                    if self.state[i].held {
                        let rate = Self::normal_rate(row, &self.velocity);
                        let wanted = (self.held_step[i] - rate / row.w_nn).max(0.0);
                        let moved = settle(
                            row,
                            row.normal_axis(),
                            row.w_nn,
                            &mut self.held_step[i],
                            wanted,
                            (&self.inv_mass, &self.inv_inertia),
                            &mut self.velocity,
                        );
                        largest_change = largest_change.max(moved);
                    }
                    let inc = self.increment[i] + self.held_step[i];
                    if inc <= 0.0
                        || row.w_tt <= 0.0
                        || (row.friction == 0.0 && row.stick_friction == 0.0)
                    {
                        continue;
                    }
                    let slip = Self::tangent_rate(row, &self.velocity);
                    let wanted = self.tangent_step[i] - slip / row.w_tt;
                    let stick_limit = if self.stuck_at_start[i] {
                        row.stick_friction.max(row.friction)
                    } else {
                        row.friction
                    } * inc;
                    let (value, sticking) = if wanted.abs() <= stick_limit {
                        (wanted, true)
                    } else {
                        (wanted.signum() * row.friction * inc, false)
                    };
                    self.state[i].sticking = sticking;
                    let moved = settle(
                        row,
                        row.tangent_axis(),
                        row.w_tt,
                        &mut self.tangent_step[i],
                        value,
                        (&self.inv_mass, &self.inv_inertia),
                        &mut self.velocity,
                    );
                    largest_change = largest_change.max(moved);
                }
                if largest_change <= settled {
                    break;
                }
            }
            for i in 0..n {
                let s = &mut self.state[i];
                s.tangent_impulse += self.tangent_step[i];
                s.normal_impulse += self.held_step[i];
            }
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
            let inc = self.increment[i];
            if inc > 0.0 {
                let mid = 0.5 * (self.rate[i] + end);
                let s = &mut self.state[i];
                // In expansion the impulse's work comes out of the stored
                // energy, e² E at most. Friction coupled into the normal can
                // open a contact after the landing test: cut the increment
                // just enough that the mid-step rate is what the energy pays
                // for (zero for e = 0); the contact leaves the step opening.
                // The contact has then spent its energy (what is left of it is
                // dissipated, never created).
                let payable = row.restitution * row.restitution * s.energy;
                if mid > threshold && mid * inc > payable {
                    let target = payable / inc;
                    let cut = (2.0 * (mid - target) / row.w_nn).clamp(0.0, inc);
                    Self::apply(
                        row,
                        row.normal_axis(),
                        -cut,
                        &self.inv_mass,
                        &self.inv_inertia,
                        &mut self.velocity,
                    );
                    self.increment[i] = inc - cut;
                    s.normal_impulse += inc - cut;
                    s.energy = 0.0;
                    if i == primary {
                        primary_energy_raw = 0.0;
                    }
                    self.rate_change[i] = Self::normal_rate(row, &self.velocity);
                    continue;
                }
                s.normal_impulse += inc;
                if mid <= threshold {
                    // compression (or the neutral rounding band)
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
            self.rate_change[i] = Self::normal_rate(row, &self.velocity);
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
            if s.held && self.held_step[i] == 0.0 && self.rate_change[i] > threshold {
                // nothing holds it any more and it separates
                s.held = false;
            }
            if self.rows[i].movable
                && !s.held
                && self.increment[i] == 0.0
                && s.energy == 0.0
                && dt.is_finite()
            {
                let mid = 0.5 * (self.rate[i] + self.rate_change[i]);
                s.gap += mid * dt;
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
}

/// Applies every contact's normal increment, times `scale`, to `v`.
fn apply_increments(
    rows: &[Row],
    increment: &[f64],
    scale: f64,
    inv_mass: &[f64],
    inv_inertia: &[f64],
    v: &mut [[f64; 3]],
) {
    for (row, inc) in rows.iter().zip(increment) {
        let p = inc * scale;
        if p > 0.0 {
            ImpactSolver::apply(row, row.normal_axis(), p, inv_mass, inv_inertia, v);
        }
    }
}

/// Sets a step's accumulated impulse along `axis` to `wanted`, applies the
/// difference to the bodies and returns the velocity correction it made
/// (|change| · W along the axis, m/s).
fn settle(
    row: &Row,
    axis: Axis,
    w: f64,
    accumulated: &mut f64,
    wanted: f64,
    (inv_mass, inv_inertia): (&[f64], &[f64]),
    v: &mut [[f64; 3]],
) -> f64 {
    let change = wanted - *accumulated;
    if change == 0.0 {
        return 0.0;
    }
    *accumulated = wanted;
    ImpactSolver::apply(row, axis, change, inv_mass, inv_inertia, v);
    change.abs() * w
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
