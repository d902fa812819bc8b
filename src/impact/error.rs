//! Errors of the impact resolver.

/// Why an impact could not be resolved. Every input problem is reported before
/// any stepping starts.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// A body's data is unusable (non-finite, or mass/inertia ≤ 0 on a free body).
    #[error("body {index}: {reason}")]
    InvalidBody {
        /// Index of the body.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// A contact's data is unusable.
    #[error("contact {index}: {reason}")]
    InvalidContact {
        /// Index of the contact.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// The settings are unusable (step or tolerance not in (0, 1], zero step
    /// limit): the field, its value and the allowed range.
    #[error("settings: {0}")]
    InvalidSettings(crate::input::InputError),
    /// The impact did not end within `max_steps` steps, or stopped making
    /// progress (gaps closing without any point loading).
    #[error("impact did not end within {steps} steps (raise max_steps or the impulse step)")]
    StepLimit {
        /// Steps taken.
        steps: usize,
    },
    /// The state became non-finite (should not happen on valid input).
    #[error("impact state became non-finite after {steps} steps")]
    NonFinite {
        /// Steps taken.
        steps: usize,
    },
}
