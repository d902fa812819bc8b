//! The stepping loop (placeholder: being written in this commit series).

use super::{validate, Body, Contact, ImpactError, ImpactOutcome, ImpactSettings};

/// Reusable LZB impact solver.
#[derive(Debug, Default)]
pub struct ImpactSolver {}

impl ImpactSolver {
    /// A solver with empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Resolves one impact.
    pub fn solve(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        settings: &ImpactSettings,
    ) -> Result<ImpactOutcome, ImpactError> {
        validate::check(bodies, contacts, settings)?;
        Err(ImpactError::InvalidSettings("not implemented yet".into()))
    }
}
