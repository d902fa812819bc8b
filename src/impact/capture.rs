//! A record of the impacts resolved on this thread, for benchmarks: switched
//! on per thread, every call of [`crate::impact::ImpactSolver::solve_into`]
//! with valid input keeps a copy of its bodies, contacts and settings, so
//! that the impacts of a whole scene can be solved again with other settings
//! (`cargo bench --bench impact` reads impacts recorded this way from
//! benches/data/).
//!
//! Off (the default), a call costs one thread-local read.
//!
//! ```
//! use topple::impact::{capture, Body, Contact, ContactMaterial, ImpactSettings, ImpactSolver};
//! let bodies = [Body::new(1.0, 0.01).with_velocity([1.0, 0.0])];
//! let wall = [Contact::new([Some(0), None], [0.1, 0.0], [1.0, 0.0], ContactMaterial::hertz(1e8))];
//! capture::start();
//! ImpactSolver::new().solve(&bodies, &wall, &ImpactSettings::default()).unwrap();
//! let seen = capture::finish();
//! assert_eq!(seen.len(), 1);
//! assert_eq!(seen[0].contacts.len(), 1);
//! ```

use std::cell::RefCell;

use serde::{Deserialize, Serialize};

use super::{Body, Contact, ImpactSettings};

/// One impact as the resolver received it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CapturedImpact {
    /// The bodies, velocities before the impact.
    pub bodies: Vec<Body>,
    /// The contact points.
    pub contacts: Vec<Contact>,
    /// The settings it was solved with.
    pub settings: ImpactSettings,
}

thread_local! {
    static CAPTURE: RefCell<Option<Vec<CapturedImpact>>> = const { RefCell::new(None) };
}

/// Starts recording the impacts of this thread (drops what was recorded).
pub fn start() {
    CAPTURE.with(|c| *c.borrow_mut() = Some(Vec::new()));
}

/// Stops recording and returns the impacts recorded since [`start`].
pub fn finish() -> Vec<CapturedImpact> {
    CAPTURE.with(|c| c.borrow_mut().take().unwrap_or_default())
}

/// Whether this thread is recording impacts (between [`start`] and
/// [`finish`]). The Rapier pass then solves its impacts one instant at a
/// time on this thread, so that every one of them is recorded.
pub fn is_on() -> bool {
    CAPTURE.with(|c| c.borrow().is_some())
}

/// Records an impact if this thread is recording.
pub(crate) fn record(bodies: &[Body], contacts: &[Contact], settings: &ImpactSettings) {
    CAPTURE.with(|c| {
        if let Some(list) = c.borrow_mut().as_mut() {
            list.push(CapturedImpact {
                bodies: bodies.to_vec(),
                contacts: contacts.to_vec(),
                settings: *settings,
            });
        }
    });
}
