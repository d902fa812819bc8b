//! The paper's scheme: the LZB law stepped in the normal impulse of a primary
//! contact (paper Sec. 2.3 and 3.1), with the fixed step ΔP = 10⁻⁴ P₀ of the
//! paper ([`crate::impact::StepControl::Fixed`]) or the error-controlled impulse step topple
//! used before its time-domain solver ([`crate::impact::StepControl::AdaptiveImpulse`], kept
//! so that benchmarks can show both side by side).
//!
//! Data are flat: per contact one [`Row`] of frozen geometry and material,
//! one [`ContactState`] that evolves (saved and restored whole by the
//! predictor and by a rejected step) and one [`Scratch`] of the current step;
//! per body one [`BodySlot`] and one `[vx, vy, ω]`, plus a last slot for the
//! fixed world. Each contact couples two bodies, so every pass below is
//! O(contacts) and the Delassus operator W = J M⁻¹ Jᵀ is never formed: W·dP
//! is obtained by applying dP to the body velocities and reading the contact
//! rates back.
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
//!
//! The method is the file list, one stage each; every file extends
//! [`ImpulseStepper`]'s impl:
//!
//! | file | stage |
//! | --- | --- |
//! | `load.rs` | body slots, contact rows, scales, the initial state; contact rates and applying an impulse |
//! | `law.rs` | the contact law F(E) and the distributing law: each contact's increment for a primary step (steps 2–3) |
//! | `step.rs` | one improved-Euler step: predictor, corrector, the explicit step they share, commit |
//! | `friction.rs` | held points and Coulomb friction with stick and slip, by projected Gauss–Seidel (step 4) |
//! | `landing.rs` | the first switch inside a step and the switches due at once (step 5); free flight to a closing gap |
//! | `energy.rs` | stored energies, the impact time by Gauss quadrature, the gaps (steps 6–7) |
//! | `control.rs` | the fixed and the adaptive step control and the adaptive step's error estimates |
//! | `finish.rs` | the outcome: velocities, impulses, kinetic energies |

mod control;
mod energy;
mod finish;
mod friction;
mod landing;
mod law;
mod load;
mod step;

use super::{Body, Contact, ImpactError, ImpactOutcome, ImpactSettings, StopReason};
use energy::NodeWarp;
use load::{BodySlot, ContactState, Row, Scales};

/// The two ways of stepping the impulse.
#[derive(Clone, Copy, Debug)]
pub(crate) enum ImpulseScheme {
    /// [`crate::impact::StepControl::Fixed`].
    Fixed { impulse_step: f64 },
    /// [`crate::impact::StepControl::AdaptiveImpulse`].
    Adaptive { tolerance: f64 },
}

/// Landing fractions at or below this are not worth a step of their own.
const MIN_LANDING: f64 = 1e-9;

/// One contact's working data for the current step (Box2D's contact-solver
/// layout: every stage loads what it needs of a point into locals, solves,
/// and stores back). Reset at the start of each impact.
#[derive(Clone, Copy, Debug, Default)]
struct Scratch {
    /// δ̇ at the start of the step (m/s).
    rate: f64,
    /// δ̇ change over the full (unlanded) step; after the energies, the
    /// rate at the step's end (m/s).
    rate_change: f64,
    /// Normal increment of the step (N·s).
    increment: f64,
    /// F_i(E_i) (N) of the energies at the step's start, 0 where unloaded;
    /// set by the predictor, reused by the error estimate.
    start_force: f64,
    /// Explicit-Euler increment of the error estimate (adaptive mode, N·s).
    euler_increment: f64,
    /// Energy at mid-step, predicted by the half step (J).
    mid_energy: f64,
    /// Tangential and held normal increments of the step (N·s).
    tangent_step: f64,
    held_step: f64,
    /// Without slip at the step's start.
    stuck_at_start: bool,
    /// Releases its last bit of energy without a step.
    released: bool,
    /// Its gap closes without a step.
    closing: bool,
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
    body_slots: Vec<BodySlot>,
    /// Body velocities [vx, vy, ω]; the last slot is the world.
    velocity: Vec<[f64; 3]>,
    /// Trial velocities (landing prediction).
    trial: Vec<[f64; 3]>,
    state: Vec<ContactState>,
    scratch: Vec<Scratch>,
    /// Improved Euler: state saved before the half step.
    mid_velocity: Vec<[f64; 3]>,
    mid_state: Vec<ContactState>,
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
        self.finish(bodies, reason, out);
        Ok(())
    }
}
