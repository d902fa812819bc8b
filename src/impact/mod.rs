//! The LZB multiple-impact resolver: bodies and contacts in, post-impact
//! velocities out. Pure math; knows nothing of dominoes, Rapier or Bevy.
//!
//! | item | role |
//! | --- | --- |
//! | [`Body`], [`Contact`], [`ContactMaterial`] | the input: planar rigid bodies and their contact points |
//! | [`ImpactSettings`], [`StepControl`] | the paper's fixed impulse step, or adaptive stepping with an error tolerance |
//! | [`ImpactSolver`] | reusable solver (keeps its buffers between impacts) |
//! | [`ImpactOutcome`] | velocities, impulses, peak energies, kinetic energy before/after, steps |
//! | [`audit`] | an independent per-thread check of every accepted impact (the stress sweep) |
//!
//! The model (paper Sec. 2.3 with the corrections of docs/model.md §1–4):
//! positions are frozen and non-impulsive forces ignored during the impact; the
//! state is advanced in the normal impulse of a *primary* contact; every loaded
//! contact takes the increment dP_i = dP_p · F_i(E_i)/F_p(E_p) with
//! F(E) = (α+1)^(α/(α+1)) k^(1/(α+1)) E^(α/(α+1)); the stored energy grows by
//! −δ̇ dP_i in compression and falls by δ̇ dP_i / e² in expansion (mid-step δ̇);
//! friction follows Coulomb's law in differential form with stick and slip.
//!
//! ```
//! use topple::impact::{Body, Contact, ContactMaterial, ImpactSettings, ImpactSolver};
//! // a ball of 1 kg hits a wall at 2 m/s with e = 0.5
//! let bodies = [Body::new(1.0, 0.01).with_velocity([2.0, 0.0])];
//! let contacts = [Contact::new([Some(0), None], [0.1, 0.0], [1.0, 0.0],
//!                              ContactMaterial::hertz(1e8).with_restitution(0.5))];
//! let out = ImpactSolver::new().solve(&bodies, &contacts, &ImpactSettings::default()).unwrap();
//! assert!((out.bodies[0].velocity[0] + 1.0).abs() < 1e-3);
//! ```

pub mod audit;
mod body;
pub mod capture;
pub(crate) mod contact;
pub(crate) mod dormand_prince;
mod error;
mod impulse;
mod outcome;
mod settings;
mod solver;
mod validate;

pub use body::{Body, BodyVelocity};
pub use contact::{Contact, ContactMaterial};
pub use error::ImpactError;
pub use outcome::{ContactImpulse, ImpactOutcome, StopReason};
pub use settings::{ImpactSettings, StepControl};
pub use solver::ImpactSolver;

/// Resolves one impact with a fresh solver (see [`ImpactSolver::solve`]).
pub fn resolve(
    bodies: &[Body],
    contacts: &[Contact],
    settings: &ImpactSettings,
) -> Result<ImpactOutcome, ImpactError> {
    ImpactSolver::new().solve(bodies, contacts, settings)
}
