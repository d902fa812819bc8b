//! The settings of a step in the world's own units.
//!
//! [`ToppleSettings`] gives its lengths and speeds per length unit, the way
//! Rapier gives its tolerances (`IntegrationParameters::length_unit`: a
//! typical body size, bevy_rapier's pixels per metre): a world measured in
//! pixels with a length unit of 100 gets the same tolerances, scaled, as the
//! same world in metres with a length unit of 1, and so the same motion,
//! scaled. Each step the adapter derives from the world's length unit L, its
//! gravity g (world units/s²) and the step's length Δt (s):
//!
//! | setting | used in the step |
//! | --- | --- |
//! | impact threshold | max(`min_approach_speed` · L, 2 \|g\| Δt): 2 \|g\| Δt is twice the approach a resting contact picks up in one Rapier step, so a stack at rest has no impacts; Δt is the step, or the sub-step while a step is cut into sub-steps |
//! | closed tolerance | max(`patch.closed_tolerance` · L, 64 ε · max(L, 1)) |
//! | flat tolerance | max(`patch.flat_tolerance` · L, 64 ε · max(L, 1)) |
//! | shortest patch | `patch.min_patch_length` · L |
//!
//! ε is the machine epsilon of the build's scalar type: parry places bodies
//! no more finely than a few ε of their coordinates, so no gap below 64 ε
//! per metre (taking a length unit above 1 as units per metre) is resolved.
//! Times (`max_substep`) are in seconds; the LZB resolver's tolerance and
//! the budgets are dimensionless.

use super::backend::math::{Real, Vector};
use super::backend::prelude::IntegrationParameters;
use crate::coupling::{PatchRule, ToppleSettings};

/// The settings `s` in the units of a world with this gravity and these
/// parameters (see the module table).
pub(crate) fn effective(
    s: &ToppleSettings,
    gravity: Vector,
    params: &IntegrationParameters,
) -> ToppleSettings {
    let l = length_unit(params);
    let floor = 64.0 * f64::from(Real::EPSILON) * l.max(1.0);
    ToppleSettings {
        min_approach_speed: threshold(s, gravity, params, f64::from(params.dt)),
        patch: PatchRule {
            closed_tolerance: (s.patch.closed_tolerance * l).max(floor),
            flat_tolerance: (s.patch.flat_tolerance * l).max(floor),
            min_patch_length: s.patch.min_patch_length * l,
            ..s.patch
        },
        ..*s
    }
}

/// The impact threshold (world units/s) of one Rapier step of `h` (s) in
/// such a world: max(`min_approach_speed` · L, 2 |g| h). A resting contact
/// picks up |g| h of approach in a Rapier step of h, so with the threshold
/// twice that a stack at rest has no impacts; a frame cut into sub-steps
/// has the sub-step's threshold (`ToppleRapier::step_parts`).
pub(crate) fn threshold(
    s: &ToppleSettings,
    gravity: Vector,
    params: &IntegrationParameters,
    h: f64,
) -> f64 {
    let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
    let g = finite(f64::from(gravity.length()));
    (s.min_approach_speed * length_unit(params)).max(2.0 * g * finite(h).max(0.0))
}

/// The world's length unit, 1 if it is not a positive number.
fn length_unit(params: &IntegrationParameters) -> f64 {
    let l = f64::from(params.length_unit);
    if l.is_finite() && l > 0.0 {
        l
    } else {
        1.0
    }
}
