//! The paper's scheme: the LZB law stepped in the normal impulse of a primary
//! contact (paper Sec. 2.3 and 3.1), with the fixed step ΔP = 10⁻⁴ P₀ of the
//! paper ([`crate::impact::StepControl::Fixed`]) or the error-controlled impulse step topple
//! used before its time-domain solver ([`crate::impact::StepControl::AdaptiveImpulse`], kept
//! so that benchmarks can show both side by side).
//!
//! Data are flat (data.rs): per contact one row of frozen geometry and
//! material, one state that evolves and one scratch of the current step; per
//! body one slot and one `[vx, vy, ω]`. Each contact couples two bodies, so every pass below is
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
//! `ImpulseStepper`'s impl, and none imports from this one:
//!
//! | file | stage |
//! | --- | --- |
//! | `data.rs` | the layout: the stepper's buffers, per-contact row, state and scratch, body slots; contact kinematics |
//! | `load.rs` | body slots, contact rows, the scales P₀ and the approach threshold, the initial state |
//! | `law.rs` | the contact law F(E), the primary contact and the distributing law: each contact's increment for a primary step (steps 1–3) |
//! | `step.rs` | one improved-Euler step: predictor, corrector, the explicit step they share, commit |
//! | `friction.rs` | held points and Coulomb friction with stick and slip, by projected Gauss–Seidel (step 4) |
//! | `landing.rs` | the first switch inside a step and the switches due at once (step 5); free flight to a closing gap |
//! | `energy.rs` | stored energies, the impact time by Gauss quadrature, the gaps (steps 6–7) |
//! | `control.rs` | the entry, the fixed and the adaptive step control, the adaptive step's error estimates |
//! | `finish.rs` | the outcome: velocities, impulses, kinetic energies |

mod control;
mod data;
mod energy;
mod finish;
mod friction;
mod landing;
mod law;
mod load;
mod step;

pub(crate) use control::ImpulseScheme;
pub(crate) use data::ImpulseStepper;
