//! The paper's scheme: the LZB law stepped in the normal impulse of a primary
//! contact (paper Sec. 2.3 and 3.1), with the fixed step ΔP = 10⁻⁴ P₀ of the
//! paper ([`crate::impact::StepControl::Fixed`]) or the error-controlled impulse step topple
//! used before its time-domain solver ([`crate::impact::StepControl::AdaptiveImpulse`], kept
//! so that benchmarks can show both side by side).
//!
//! Data are flat: one [`Row`] of frozen geometry and one [`ContactState`] per
//! contact, one `[vx, vy, ω]` per body plus a last slot for the fixed world.
//! Each contact couples two bodies, so every pass below is O(contacts) and the
//! Delassus operator W = J M⁻¹ Jᵀ is never formed: W·dP is obtained by applying
//! dP to the body velocities and reading the contact rates back.
//!
//! One impulse step (docs/model.md §2–4), an improved-Euler step in the primary's
//! impulse: a half step with the start energies predicts the mid-step
//! energies, by whose ratios the full step is distributed:
//! 1. normal rates δ̇_i at the start of the step;
//! 2. the primary p: the contact with the largest stored energy E, or, when no
//!    contact holds energy, the one approaching fastest;
//! 3. increments: loaded contacts dP_i = h F_i(E_i)/F_p(E_p) (docs/model.md §1);
//!    closed contacts with E_i = 0 that approach join with the increment that
//!    stores E_i ≈ |δ̇_i| dP_i consistently with F_p (docs/model.md §3); the step is
//!    scaled so that no contact takes more than h;
//! 4. held contacts and Coulomb friction on the whole step, by projected
//!    Gauss–Seidel: a contact without slip stays stuck if that needs
//!    |dP_t| ≤ μ_s dP_n, else it slides the way it is pushed; a sliding
//!    contact takes |dP_t| = μ dP_n against its slip; a no-slip contact
//!    (μ = ∞) takes the tangential impulse that stops its slip, unbounded,
//!    while it takes normal impulse (so it may still lift off);
//! 5. landing: every impulse of the step scales with its length, so the
//!    velocities are linear in it; the step is shortened to end where a
//!    contact's compression ends, its energy runs out (quadratic), a resting
//!    contact starts to approach, a gap closes or a sliding contact's slip
//!    stops;
//! 6. energies with the mid-step rate: dE = −δ̇ dP in compression,
//!    dE = −δ̇ dP / e² in expansion; e = 0 releases at once; E ≥ 0.
//!
//! The fixed step takes h = ΔP = the paper's 10⁻⁴ P₀. The adaptive step
//! chooses h per step from an estimate of its local error: the velocity
//! change by which the increments distributed with the start energies
//! (explicit Euler) differ from those actually taken, plus the friction
//! impulse that a contact breaking loose inside the step may misplace. A lone
//! loaded contact has constant ratios and no error, so its steps are limited
//! only by the events they land on.
//!
//! A contact that has released its energy and separates opens a gap, tracked in
//! the impact's own time dt = dP_p / F_p; it takes part again only once the gap
//! has closed. This makes the e = 1 result equal to the compliant model
//! F = k δ^α integrated in time, separations and re-contacts included.

use super::contact::cross;
use super::{
    Body, BodyVelocity, Contact, ContactImpulse, ImpactError, ImpactOutcome, ImpactSettings,
    StopReason,
};

/// The two ways of stepping the impulse.
#[derive(Clone, Copy, Debug)]
pub(crate) enum ImpulseScheme {
    /// [`crate::impact::StepControl::Fixed`].
    Fixed { impulse_step: f64 },
    /// [`crate::impact::StepControl::AdaptiveImpulse`].
    Adaptive { tolerance: f64 },
}

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

/// A direction of impulse with its moment arms r×dir on the two bodies.
#[derive(Clone, Copy, Debug)]
struct Axis {
    dir: [f64; 2],
    arm_a: f64,
    arm_b: f64,
}

impl Row {
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

    /// Unbounded friction (μ = ∞, [`ContactMaterial::no_slip`]): the
    /// contact never slides while it takes normal impulse.
    ///
    /// [`ContactMaterial::no_slip`]: super::ContactMaterial::no_slip
    #[inline]
    fn no_slip(&self) -> bool {
        self.friction == f64::INFINITY
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
    /// P₀ (N·s), see [`crate::impact::StepControl::Fixed`].
    impulse: f64,
    /// Largest approach speed at the start (m/s).
    velocity: f64,
    /// Rates above −threshold count as not approaching (m/s).
    threshold: f64,
}

/// Gauss–Legendre nodes on [0, 1] and weights (4 points, exact for
/// polynomials of degree 7).
const GAUSS_4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_87, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

/// Landing fractions at or below this are not worth a step of their own.
const MIN_LANDING: f64 = 1e-9;

/// Friction sweeps per step at most, and the slip correction (relative to
/// the velocity scale) below which they stop.
const FRICTION_SWEEPS: usize = 16;
const FRICTION_SETTLED: f64 = 1e-13;

/// The two halves of an improved-Euler step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// Half step distributed by the start energies, not landed.
    Predictor,
    /// Full step distributed by the mid-step energies, landed.
    Corrector,
}

/// The primary contact of a step and its force.
#[derive(Clone, Copy, Debug)]
struct Primary {
    index: usize,
    /// F_p (N) used to distribute the step.
    force: f64,
    /// F_p (N) of the start energies (the explicit-Euler distribution).
    start_force: f64,
}

/// Result of one step attempt.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Step {
    /// Nothing is loaded and nothing closed approaches: the impact is over.
    Done,
    /// Advanced; `length` is the step actually taken in the units of h.
    Advanced { length: f64 },
}

/// The impulse-stepping integrator (see the module docs). Keeps its buffers
/// between impacts; the stepping loop never allocates.
///
/// P₀, the impulse scale of [`crate::impact::StepControl::Fixed`], is the larger of the
/// magnitude of the free bodies' total linear momentum (the paper's
/// definition) and the largest impulse that would stop one approaching contact
/// on its own (|δ̇_i| / W_ii); the second matters when the momentum is zero, as
/// for two bodies meeting head-on.
#[derive(Debug, Default)]
pub(crate) struct ImpulseStepper {
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
    /// F_i(E_i) (N) of the energies at the step's start, 0 where unloaded;
    /// set by the predictor, reused by the error estimate.
    start_force: Vec<f64>,
    /// Explicit-Euler increments of the error estimate (adaptive mode).
    euler_increment: Vec<f64>,
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
    /// Contacts whose gap closes without a step.
    closing: Vec<bool>,
    scales: Scales,
    /// Impact time elapsed so far (s), from the contact law.
    elapsed: f64,
    /// See [`ImpactSettings::e0_hold`].
    e0_hold: bool,
    /// Adaptive mode: state saved before a trial step, restored on rejection.
    saved_velocity: Vec<[f64; 3]>,
    saved_state: Vec<ContactState>,
    /// The impulse (N·s) below which a landing is not worth a step:
    /// [`MIN_LANDING`] times the paper's step 10⁻⁴ P₀ in adaptive mode, so
    /// that large adaptive steps do not skip events.
    landing_impulse: f64,
    /// Local error estimate of the last full step (adaptive mode), relative
    /// to the velocity scale.
    step_error: f64,
    /// Adaptive mode is running (the full steps estimate their error).
    adaptive: bool,
    /// The Gauss nodes warped for an end where E = 0 (see
    /// [`Self::impact_time`]), for the contacts of `warp.0`'s exponent.
    warp: (f64, [NodeWarp; 4]),
}

/// A Gauss node s warped by σ = s^k: (s^k, k s^(k−1)).
type NodeWarp = (f64, f64);

/// The Gauss nodes warped by σ = s^k (k = α + 1 of the contact law).
fn warped_nodes(k: f64) -> [NodeWarp; 4] {
    GAUSS_4.map(|(node, _)| (node.powf(k), k * node.powf(k - 1.0)))
}

impl ImpulseStepper {
    /// Resolves one validated impact into `out` with a fixed or an adaptive
    /// impulse step. Errors: the step limit or a non-finite state.
    pub(crate) fn solve_into(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        scheme: ImpulseScheme,
        settings: &ImpactSettings,
        out: &mut ImpactOutcome,
    ) -> Result<(), ImpactError> {
        self.load(bodies, contacts);
        self.elapsed = 0.0;
        self.e0_hold = settings.e0_hold;
        out.kinetic_energy_before = bodies.iter().map(Body::kinetic_energy).sum();
        out.steps = 0;
        out.rejected_steps = 0;

        let reason = if self.scales.velocity == 0.0 {
            StopReason::NoApproach
        } else {
            match scheme {
                ImpulseScheme::Fixed { impulse_step } => {
                    self.adaptive = false;
                    let h = impulse_step * self.scales.impulse;
                    self.landing_impulse = MIN_LANDING * h;
                    self.run_fixed(h, settings.max_steps, out)?
                }
                ImpulseScheme::Adaptive { tolerance } => {
                    self.adaptive = true;
                    self.landing_impulse = MIN_LANDING * 1e-4 * self.scales.impulse;
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
            let frame = c.frame(bodies);
            let (a, b, normal, tangent) = (frame.a, frame.b, frame.normal, frame.tangent);
            let (ra, rb) = (frame.arm_a, frame.arm_b);
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

        if let Some(row) = self.rows.first() {
            let k = 1.0 / (1.0 - row.power);
            if k != self.warp.0 {
                self.warp = (k, warped_nodes(k));
            }
        }
        let n = self.rows.len();
        let nb = self.velocity.len();
        self.trial.resize(nb, [0.0; 3]);
        self.rate.resize(n, 0.0);
        self.rate_change.resize(n, 0.0);
        self.increment.resize(n, 0.0);
        self.start_force.resize(n, 0.0);
        self.euler_increment.resize(n, 0.0);
        self.mid_velocity.resize(nb, [0.0; 3]);
        self.mid_state.resize(n, ContactState::default());
        self.mid_energy.resize(n, 0.0);
        self.tangent_step.resize(n, 0.0);
        self.held_step.resize(n, 0.0);
        self.stuck_at_start.clear();
        self.stuck_at_start.resize(n, false);
        self.released.clear();
        self.released.resize(n, false);
        self.closing.clear();
        self.closing.resize(n, false);
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
            match self.step(h) {
                Step::Done => return Ok(StopReason::Released),
                Step::Advanced { .. } => {
                    out.steps += 1;
                    if out.steps >= max_steps {
                        return Err(ImpactError::StepLimit { steps: out.steps });
                    }
                    if out.steps.is_multiple_of(4096) && !self.finite() {
                        return Err(ImpactError::NonFinite { steps: out.steps });
                    }
                }
            }
        }
    }

    /// Adaptive mode: the paper's scheme with the impulse step chosen per
    /// step. Each step's local error is estimated by the difference between
    /// the increments distributed with the start energies (explicit Euler)
    /// and with the mid-step energies (the improved Euler actually taken),
    /// and by the friction impulse of contacts that switch between stick and
    /// slip inside the step (the switch is not located within a step); a
    /// step whose estimate exceeds `tolerance` is taken again shorter.
    /// Between events a lone loaded contact has constant ratios and no
    /// error, so its steps grow until they land on the events.
    fn run_adaptive(
        &mut self,
        tolerance: f64,
        max_steps: usize,
        out: &mut ImpactOutcome,
    ) -> Result<StopReason, ImpactError> {
        let p0 = self.scales.impulse;
        // The Euler error is second order in h: its square root sets the
        // first step.
        let mut h = p0 * (0.1 * tolerance.sqrt()).clamp(1e-8, 1e-2);
        let h_min = p0 * 1e-15;
        self.saved_velocity.resize(self.velocity.len(), [0.0; 3]);
        self.saved_state
            .resize(self.state.len(), ContactState::default());
        let mut attempts = 0usize;
        loop {
            attempts += 1;
            if attempts > max_steps {
                return Err(ImpactError::StepLimit { steps: out.steps });
            }
            self.saved_velocity.copy_from_slice(&self.velocity);
            self.saved_state.copy_from_slice(&self.state);
            let elapsed = self.elapsed;
            let length = match self.step(h) {
                Step::Done => return Ok(StopReason::Released),
                Step::Advanced { length } => length,
            };
            // the step's error estimate over the tolerance: ≤ 1 is accepted
            let error = self.step_error / tolerance;
            if error > 1.0 && h > h_min {
                self.velocity.copy_from_slice(&self.saved_velocity);
                self.state.copy_from_slice(&self.saved_state);
                self.elapsed = elapsed;
                out.rejected_steps += 1;
                h = (h * (0.9 / error.sqrt()).clamp(0.1, 0.9)).max(h_min);
                continue;
            }
            out.steps += 1;
            if out.steps.is_multiple_of(4096) && !self.finite() {
                return Err(ImpactError::NonFinite { steps: out.steps });
            }
            let grow = if error > 0.0 {
                (0.9 / error.sqrt()).clamp(0.2, 5.0)
            } else {
                5.0
            };
            // A step cut short by a landing grows from what it took (at
            // least a tenth of h): long steps that keep landing early
            // resolve nothing (an e = 0 contact pushed again after its
            // compression ended reloads in cycles that long steps cut into
            // many tiny ones). No step beyond the impact's impulse scale.
            let base = if length < h { length.max(0.1 * h) } else { h };
            h = (base * grow).clamp(h_min, p0);
        }
    }

    fn finite(&self) -> bool {
        self.velocity.iter().flatten().all(|x| x.is_finite())
            && self.state.iter().all(|s| s.energy.is_finite())
    }

    /// One step of length `h` (N·s): the improved-Euler scheme in the impulse
    /// variable. A half Euler step predicts the stored energies at mid-step;
    /// the full step then distributes its impulse by the ratios F_i/F_p of those
    /// mid-step energies and lands on the first switch inside it. Second order
    /// in h, like the paper's improved Euler in time.
    fn step(&mut self, h: f64) -> Step {
        self.mid_velocity.copy_from_slice(&self.velocity);
        self.mid_state.copy_from_slice(&self.state);
        let elapsed = self.elapsed;
        if self.euler_step(0.5 * h, Stage::Predictor) == Step::Done {
            return Step::Done;
        }
        self.elapsed = elapsed;
        for (m, s) in self.mid_energy.iter_mut().zip(&self.state) {
            *m = s.energy;
        }
        self.velocity.copy_from_slice(&self.mid_velocity);
        self.state.copy_from_slice(&self.mid_state);
        self.euler_step(h, Stage::Corrector)
    }

    /// One explicit step of length at most `h` (N·s); see the module doc.
    /// The predictor distributes by the start energies and takes the whole
    /// step; the corrector distributes by the energies in `mid_energy` (where
    /// positive) and lands on the first switch.
    fn euler_step(&mut self, h: f64, stage: Stage) -> Step {
        let threshold = self.scales.threshold;
        // 1. rates; 2. primary.
        let Some(primary) = self.primary(h, stage) else {
            return Step::Done;
        };
        // 3. increments, scaled so that no contact takes more than h.
        let length = loop {
            let scale = self.distribute(h, primary, stage);
            if stage == Stage::Corrector && self.adaptive {
                self.step_error = self.ratio_error(h, scale, primary.start_force, threshold);
            }
            for inc in &mut self.increment {
                *inc *= scale;
            }
            // 4. the whole step's impulses on trial velocities: the normal
            // increments, then the held contacts and Coulomb friction.
            self.trial.copy_from_slice(&self.velocity);
            apply_increments(
                &self.rows,
                &self.increment,
                &self.inv_mass,
                &self.inv_inertia,
                &mut self.trial,
            );
            self.held_and_friction();
            if stage == Stage::Predictor {
                break 1.0;
            }
            // 5. landing on the first switch inside the step: every impulse
            // of the step scales with its length σ, so v(σ) is linear. A
            // switch within a negligible impulse happens at once — a contact
            // with too little energy left releases it (dissipated, without
            // impulse), a closing gap closes — and the step is distributed
            // again.
            let step_time = self.increment[primary.index] / primary.force;
            let (length, switched_now) = self.landing(h, step_time);
            if !switched_now {
                break length;
            }
            self.switch_marked();
        };
        self.commit(length);
        if stage == Stage::Corrector && self.adaptive {
            self.friction_error();
        }
        // 6. energies with the mid-step rate; 7. impact time and gaps (the
        // predictor keeps only its energies, so it skips them).
        let primary_energy_before = self.state[primary.index].energy;
        let primary_energy_raw = self.update_energies(primary.index, threshold);
        if stage == Stage::Corrector {
            let (dt, moment) =
                self.impact_time(primary.index, primary_energy_before, primary_energy_raw);
            self.elapsed += dt;
            self.update_gaps(dt, moment, threshold);
        }
        Step::Advanced { length: length * h }
    }

    /// Steps 1–2: the rates δ̇_i at the start of the step (an e = 0 contact
    /// whose compression has ended loses its energy, docs/model.md §2) and the
    /// primary contact: the one with the largest stored energy (in the
    /// corrector, the largest mid-step energy), or, when none holds energy,
    /// the one approaching fastest, whose force is then that of the energy
    /// |δ̇| h it stores over the step (docs/model.md §3). Flies freely to the first
    /// closing gap when only gaps approach; `None` when nothing approaches.
    fn primary(&mut self, h: f64, stage: Stage) -> Option<Primary> {
        let threshold = self.scales.threshold;
        let mut primary = usize::MAX;
        let mut largest_energy = 0.0;
        let mut fastest = usize::MAX;
        let mut fastest_rate = -threshold;
        for i in 0..self.rows.len() {
            let row = &self.rows[i];
            if !row.movable {
                continue;
            }
            let rate = Self::normal_rate(row, &self.velocity);
            self.rate[i] = rate;
            let s = &mut self.state[i];
            // e = 0: the energy is lost when compression ends (docs/model.md §2).
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
            fastest = self.free_flight()?;
            fastest_rate = self.rate[fastest];
        }
        let start_force = if primary != usize::MAX {
            self.rows[primary].force(largest_energy)
        } else {
            // the primary starts too: its force at the step's end (docs/model.md
            // §3), or, in the adaptive step, its mean over the step (see
            // `increment_of`)
            let row = &self.rows[fastest];
            let mean = if self.adaptive {
                1.0 / (row.exponent + 1.0)
            } else {
                1.0
            };
            mean * row.force(-fastest_rate * h)
        };
        if stage == Stage::Corrector {
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
        Some(if primary != usize::MAX {
            Primary {
                index: primary,
                force: self.rows[primary].force(largest_energy),
                start_force,
            }
        } else {
            Primary {
                index: fastest,
                force: start_force,
                start_force,
            }
        })
    }

    /// Step 3: every contact's normal increment for a primary step h, in
    /// `increment`; returns the factor (≤ 1) that keeps each below h.
    fn distribute(&mut self, h: f64, primary: Primary, stage: Stage) -> f64 {
        let threshold = self.scales.threshold;
        let mut largest = 0.0f64;
        for i in 0..self.rows.len() {
            let (row, s) = (&self.rows[i], &self.state[i]);
            let ratio_force = if stage == Stage::Corrector && self.mid_energy[i] > 0.0 {
                row.force(self.mid_energy[i])
            } else {
                row.force(s.energy)
            };
            if stage == Stage::Predictor {
                self.start_force[i] = ratio_force;
            }
            let inc = Self::increment_of(
                row,
                s,
                self.rate[i],
                ratio_force,
                h,
                primary.force,
                (threshold, self.adaptive),
            );
            self.increment[i] = inc;
            largest = largest.max(inc);
        }
        if largest > h {
            h / largest
        } else {
            1.0
        }
    }

    /// Step 4, on the trial velocities after the normal increments: held
    /// contacts and Coulomb friction by projected Gauss–Seidel sweeps over
    /// the step's held normal and tangential increments until the
    /// corrections are rounding. A held contact takes the non-negative
    /// impulse that keeps it from approaching. A contact that does not slip
    /// at the start of the step stays stuck while that needs
    /// |dP_t| ≤ μ_s dP_n, and otherwise slides the way it is pushed; a
    /// sliding contact takes |dP_t| = μ dP_n against its slip at the start
    /// (the step lands where that slip stops, see [`Self::landing`]).
    fn held_and_friction(&mut self) {
        let n = self.rows.len();
        let threshold = self.scales.threshold;
        let mut sweeping = false;
        // Only held, stuck and no-slip contacts read the trial velocities;
        // without them one sweep settles every impulse.
        let mut coupled = false;
        for i in 0..n {
            self.tangent_step[i] = 0.0;
            self.held_step[i] = 0.0;
            let row = &self.rows[i];
            let s = &self.state[i];
            let stuck = Self::tangent_rate(row, &self.velocity).abs() <= threshold;
            self.stuck_at_start[i] = stuck;
            let rubbing = self.increment[i] > 0.0 && Self::has_friction(row);
            sweeping |= row.movable && (s.held || rubbing);
            coupled |= row.movable && (s.held || (rubbing && (stuck || row.no_slip())));
        }
        if !sweeping {
            return;
        }
        let settled = FRICTION_SETTLED * self.scales.velocity;
        let masses = (&self.inv_mass[..], &self.inv_inertia[..]);
        for _sweep in 0..FRICTION_SWEEPS {
            let mut largest_change: f64 = 0.0;
            for i in 0..n {
                let row = &self.rows[i];
                if !row.movable {
                    continue;
                }
                if self.state[i].held {
                    let rate = Self::normal_rate(row, &self.trial);
                    let wanted = (self.held_step[i] - rate / row.w_nn).max(0.0);
                    let moved = settle(
                        row,
                        row.normal_axis(),
                        row.w_nn,
                        &mut self.held_step[i],
                        wanted,
                        masses,
                        &mut self.trial,
                    );
                    largest_change = largest_change.max(moved);
                }
                let inc = self.increment[i] + self.held_step[i];
                if inc <= 0.0 || !Self::has_friction(row) {
                    continue;
                }
                // A no-slip contact (μ = ∞) takes whatever tangential
                // impulse stops its slip, whether or not it slipped at the
                // start: the limit μ → ∞ of the sliding branch.
                let (value, sticking) = if self.stuck_at_start[i] || row.no_slip() {
                    let slip = Self::tangent_rate(row, &self.trial);
                    let wanted = self.tangent_step[i] - slip / row.w_tt;
                    if wanted.abs() <= row.stick_friction.max(row.friction) * inc {
                        (wanted, true)
                    } else {
                        (wanted.signum() * row.friction * inc, false)
                    }
                } else {
                    let slip = Self::tangent_rate(row, &self.velocity);
                    (-slip.signum() * row.friction * inc, false)
                };
                self.state[i].sticking = sticking;
                let moved = settle(
                    row,
                    row.tangent_axis(),
                    row.w_tt,
                    &mut self.tangent_step[i],
                    value,
                    masses,
                    &mut self.trial,
                );
                largest_change = largest_change.max(moved);
            }
            if largest_change <= settled || !coupled {
                break;
            }
        }
    }

    #[inline]
    fn has_friction(row: &Row) -> bool {
        row.w_tt > 0.0 && (row.friction > 0.0 || row.stick_friction > 0.0)
    }

    /// Step 5: the fraction σ ∈ (0, 1] of the step at which the first switch
    /// happens — a contact's compression ends, its energy runs out in
    /// expansion, a resting closed contact starts to approach, an open gap
    /// closes — with the rates linear in σ (`rate_change` receives the
    /// whole step's change). Also whether a contact releases its last bit of
    /// energy at once (marked in `released`).
    fn landing(&mut self, h: f64, step_time: f64) -> (f64, bool) {
        let threshold = self.scales.threshold;
        let min_landing = self.landing_impulse / h;
        let mut length = 1.0f64;
        let mut released_now = false;
        for i in 0..self.rows.len() {
            let row = &self.rows[i];
            if !row.movable {
                continue;
            }
            let rate = self.rate[i];
            let change = Self::normal_rate(row, &self.trial) - rate;
            self.rate_change[i] = change;
            let inc = self.increment[i] + self.held_step[i];
            let s = &self.state[i];
            let at = if inc > 0.0 && rate < -threshold && rate + change > 0.0 {
                // compression ends
                -rate / change
            } else if self.increment[i] > 0.0 && rate >= -threshold && s.energy > 0.0 {
                // expansion: release(σ) = σ inc (rate + σ change / 2) / e² reaches E
                let inc = self.increment[i];
                let e2 = row.restitution * row.restitution;
                let (qa, qb, qc) = (0.5 * inc * change, inc * rate, -e2 * s.energy);
                if qa + qb + qc > 0.0 {
                    let at = smallest_positive_root(qa, qb, qc);
                    if at <= min_landing {
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
                    let at = smallest_positive_root(qa, qb, qc);
                    if at <= min_landing {
                        released_now = true;
                        self.closing[i] = true;
                    }
                    at
                } else {
                    1.0
                }
            } else {
                1.0
            };
            if at > min_landing {
                length = length.min(at);
            }
            // a sliding contact's slip stops
            if inc > 0.0 && !self.stuck_at_start[i] && !row.no_slip() && Self::has_friction(row) {
                let slip0 = Self::tangent_rate(row, &self.velocity);
                let slip1 = Self::tangent_rate(row, &self.trial);
                if slip0 * slip1 < 0.0 {
                    let at = slip0 / (slip0 - slip1);
                    if at > min_landing {
                        length = length.min(at);
                    }
                }
            }
        }
        (length, released_now)
    }

    /// Contacts marked `released` lose their energy; gaps marked `closing`
    /// close.
    fn switch_marked(&mut self) {
        for i in 0..self.rows.len() {
            if self.released[i] {
                self.released[i] = false;
                self.state[i].energy = 0.0;
            }
            if self.closing[i] {
                self.closing[i] = false;
                self.state[i].gap = 0.0;
            }
        }
    }

    /// Takes the fraction `length` of the trial step: velocities, normal,
    /// held and tangential increments.
    fn commit(&mut self, length: f64) {
        for (v, t) in self.velocity.iter_mut().zip(&self.trial) {
            for k in 0..3 {
                v[k] += length * (t[k] - v[k]);
            }
        }
        let threshold = self.scales.threshold;
        for i in 0..self.rows.len() {
            self.increment[i] *= length;
            self.held_step[i] *= length;
            self.tangent_step[i] *= length;
            let row = &self.rows[i];
            let s = &mut self.state[i];
            s.tangent_impulse += self.tangent_step[i];
            s.normal_impulse += self.held_step[i];
            let _ = (row, threshold);
        }
    }

    /// Adaptive mode: a contact that sticks at the start of a step and
    /// slides in it may have broken loose anywhere inside the step (the
    /// switch is not located), so up to μ dP_n of friction impulse may be
    /// misplaced; that
    /// (as a velocity, relative to the velocity scale) joins the step's
    /// error estimate.
    fn friction_error(&mut self) {
        for i in 0..self.rows.len() {
            let row = &self.rows[i];
            let inc = self.increment[i] + self.held_step[i];
            if self.stuck_at_start[i]
                && !self.state[i].sticking
                && inc > 0.0
                && Self::has_friction(row)
            {
                let inc = self.increment[i] + self.held_step[i];
                let misplaced = row.stick_friction.max(row.friction) * inc * row.w_tt;
                self.step_error = self.step_error.max(misplaced / self.scales.velocity);
            }
        }
    }

    /// Step 6: stored energies with the mid-step rate, dE = −δ̇ dP in
    /// compression and −δ̇ dP / e² in expansion (e = 0 releases at once);
    /// `rate_change` receives the end rates. Returns the primary's energy
    /// before clamping at 0 (for the impact time).
    fn update_energies(&mut self, primary: usize, threshold: f64) -> f64 {
        let mut primary_energy_raw = self.state[primary].energy;
        for i in 0..self.rows.len() {
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
        primary_energy_raw
    }

    /// Impact time of the step, dt = ∫ dP_p / F_p(E_p), and its first
    /// moment ∫ σ dt over the step's fraction σ ∈ [0, 1] (s).
    ///
    /// The fixed step takes E_p linear in P_p over the step (exact at the
    /// singular start E_p = 0; its steps are short). The adaptive step's can
    /// be long: there E_p(σ) = E₀ − dP_p (δ̇₀ σ + Δ σ²/2)/η is quadratic (δ̇
    /// is linear in σ, η = 1 in compression, e² in expansion) and the
    /// integral is taken by Gauss–Legendre quadrature on each half of the
    /// step, with σ = s^k (k = 1/(1 − α/(α+1)) = α+1) near an end where
    /// E_p = 0, which makes the integrable singularity E^(−α/(α+1)) smooth.
    fn impact_time(&self, primary: usize, e0: f64, e1_raw: f64) -> (f64, f64) {
        let row = &self.rows[primary];
        let inc = self.increment[primary];
        if inc == 0.0 {
            return (0.0, 0.0);
        }
        let e1 = e1_raw.max(0.0);
        if !self.adaptive {
            let slope = (e1_raw - e0) / inc;
            let rise = 1.0 - row.power;
            let dt = if (slope * inc).abs() <= 1e-12 * e0.max(e1) {
                inc / row.force(e0.max(e1))
            } else {
                // until E_p reaches zero if it runs out inside the step
                (e1.powf(rise) - e0.powf(rise)) / (row.force_coeff * rise * slope)
            };
            return (dt, 0.5 * dt);
        }
        // E(σ) = e0 + a σ + b σ², through E(1) = e1_raw with the mid-step
        // rate's energy change split by the start and end rates
        let r0 = self.rate[primary];
        let r1 = self.rate_change[primary];
        let eta = if e1_raw >= e0 || row.restitution == 0.0 {
            1.0
        } else {
            row.restitution * row.restitution
        };
        let (a, b) = (-inc * r0 / eta, -inc * 0.5 * (r1 - r0) / eta);
        let energy = |sigma: f64| (e0 + sigma * (a + sigma * b)).max(0.0);
        let k = 1.0 / (1.0 - row.power);
        let warp = if k == self.warp.0 {
            self.warp.1
        } else {
            warped_nodes(k)
        };
        let (mut t0, mut t1) = (0.0, 0.0);
        for ((node, weight), (node_k, slope_k)) in GAUSS_4.into_iter().zip(warp) {
            // first half, σ = ½ s^k if E vanishes at 0, else σ = ½ s
            let (sigma, jac) = if e0 <= 0.0 {
                (0.5 * node_k, 0.5 * slope_k)
            } else {
                (0.5 * node, 0.5)
            };
            let f = row.force(energy(sigma));
            if f > 0.0 {
                t0 += weight * jac / f;
                t1 += weight * jac * sigma / f;
            }
            // second half, from the end
            let (sigma, jac) = if e1 <= 0.0 {
                (1.0 - 0.5 * node_k, 0.5 * slope_k)
            } else {
                (1.0 - 0.5 * node, 0.5)
            };
            let f = row.force(energy(sigma));
            if f > 0.0 {
                t0 += weight * jac / f;
                t1 += weight * jac * sigma / f;
            }
        }
        (inc * t0, inc * t1)
    }

    /// Step 7: the gaps of the contacts that carry no energy advance by
    /// ∫ δ̇ dt = δ̇₀ dt + Δ ∫ σ dt (δ̇ linear in σ, `moment` = ∫ σ dt); a held
    /// contact that nothing holds any more and that separates is released.
    fn update_gaps(&mut self, dt: f64, moment: f64, threshold: f64) {
        for i in 0..self.rows.len() {
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
                let change = self.rate_change[i] - self.rate[i];
                let moved = self.rate[i] * dt + change * moment;
                if self.adaptive && s.gap > 0.0 && s.gap + moved < 0.0 {
                    // The landing on this gap's closing, which takes the
                    // step's time as uniform in σ, came late: the fraction
                    // of the step the contact spent closed but without
                    // force joins the error estimate (adaptive mode).
                    let late = -(s.gap + moved) / moved.abs();
                    self.step_error = self.step_error.max(late);
                }
                s.gap += moved;
                // closed when what is left is rounding of the landing
                if s.gap <= 1e-9 * moved.abs() {
                    s.gap = 0.0;
                }
            }
        }
    }

    /// Normal increment of one contact for a step of primary impulse `h`
    /// (N·s) whose primary pushes with `primary_force` (N): loaded contacts
    /// in the ratio F_i(E_i)/F_p (docs/model.md §1, F_i = `ratio_force`);
    /// approaching closed contacts without energy start as in the contact
    /// law, E_i ≈ |δ̇_i| dP_i. The fixed step uses docs/model.md §3,
    /// dP_i = (h c_i / F_p)^(α+1) |δ̇_i|^α, which takes the force at the
    /// step's end; the adaptive step, whose first steps can be long, the
    /// exact start at constant δ̇_i over the step's time h / F_p (F = k w^α
    /// with w = |δ̇_i| t integrates to dP_i = (h c_i / ((α+1) F_p))^(α+1)
    /// |δ̇_i|^α). Both agree as h → 0.
    #[inline]
    fn increment_of(
        row: &Row,
        s: &ContactState,
        rate: f64,
        ratio_force: f64,
        h: f64,
        primary_force: f64,
        (threshold, time_exact): (f64, bool),
    ) -> f64 {
        if !row.movable {
            0.0
        } else if ratio_force > 0.0 {
            h * ratio_force / primary_force
        } else if s.gap == 0.0 && !s.held && rate < -threshold {
            let a1 = row.exponent + 1.0;
            let start = if time_exact { 1.0 / a1 } else { 1.0 };
            (start * h * row.force_coeff / primary_force).powf(a1) * (-rate).powf(row.exponent)
        } else {
            0.0
        }
    }

    /// Adaptive mode's error estimate of a full step, relative to the
    /// velocity scale: the largest velocity change W_ii |dP_i − dP_i^E| by
    /// which the improved-Euler increments `increment` (times `scale`) differ
    /// from the explicit-Euler ones, distributed with the start energies
    /// (primary force `start_force`). Second order in h.
    fn ratio_error(&mut self, h: f64, scale: f64, start_force: f64, threshold: f64) -> f64 {
        if start_force <= 0.0 {
            return 0.0;
        }
        let n = self.rows.len();
        let mut largest = 0.0f64;
        for i in 0..n {
            let (row, s) = (&self.rows[i], &self.state[i]);
            // a contact still loaded here holds its start energy (landings
            // only release), whose force the predictor kept
            let ratio_force = if s.energy > 0.0 {
                self.start_force[i]
            } else {
                0.0
            };
            let inc = Self::increment_of(
                row,
                s,
                self.rate[i],
                ratio_force,
                h,
                start_force,
                (threshold, true),
            );
            self.euler_increment[i] = inc;
            largest = largest.max(inc);
        }
        let start_scale = if largest > h { h / largest } else { 1.0 };
        let mut worst = 0.0f64;
        for i in 0..n {
            let euler = start_scale * self.euler_increment[i];
            let diff = (self.increment[i] * scale - euler).abs() * self.rows[i].w_nn;
            worst = worst.max(diff);
        }
        worst / self.scales.velocity
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

/// Applies every contact's normal increment to `v`.
fn apply_increments(
    rows: &[Row],
    increment: &[f64],
    inv_mass: &[f64],
    inv_inertia: &[f64],
    v: &mut [[f64; 3]],
) {
    for (row, &p) in rows.iter().zip(increment) {
        if p > 0.0 {
            ImpulseStepper::apply(row, row.normal_axis(), p, inv_mass, inv_inertia, v);
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
    ImpulseStepper::apply(row, axis, change, inv_mass, inv_inertia, v);
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
