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
//! | impact threshold | max(`min_approach_speed` · L, 2 \|g\| Δt): 2 \|g\| Δt is the approach a resting contact picks up in one step, so a stack at rest has no impacts |
//! | rebound threshold | max(`min_approach_speed` · L, \|g\| Δt/n) for a step cut into n > 1 sub-steps (the impact threshold for n = 1): the threshold of a pair Rapier has not held in this step or the last ([`rebound_threshold`]) |
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
    let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
    let l = f64::from(params.length_unit);
    let l = if l.is_finite() && l > 0.0 { l } else { 1.0 };
    let g = finite(f64::from(gravity.length()));
    let dt = finite(f64::from(params.dt)).max(0.0);
    let floor = 64.0 * f64::from(Real::EPSILON) * l.max(1.0);
    ToppleSettings {
        min_approach_speed: (s.min_approach_speed * l).max(2.0 * g * dt),
        patch: PatchRule {
            closed_tolerance: (s.patch.closed_tolerance * l).max(floor),
            flat_tolerance: (s.patch.flat_tolerance * l).max(floor),
            min_patch_length: s.patch.min_patch_length * l,
            ..s.patch
        },
        ..*s
    }
}

/// The impact threshold (world units/s) of a managed pair that Rapier's
/// contact solver has not held in this step or the last, for a step cut
/// into `substeps` = n > 1 Rapier steps: max(`min_approach_speed` · L,
/// |g| Δt/n), the approach gravity gives a contact in one of those Rapier
/// steps. A pair Rapier holds keeps the step's threshold 2 |g| Δt, twice
/// that approach over the whole step: its slower approaches are the
/// chatter of Rapier's soft contact. A pair it has not held is not resting
/// on it, so the margin of two is not needed there, and every rebound it
/// would leave to Rapier is stopped dead (docs/bevy.md, "Rebounds and
/// chatter"; docs/game-rate.md, "The rebound threshold at one Rapier
/// step's approach": at 2 |g| Δt/n Domino X at s/h 0.3 read 4 % slow at
/// 1/60 s, at |g| Δt/n 2.9 %). A step taken whole (n = 1) keeps the step's
/// threshold for every pair, as before the rule: there the lower
/// threshold was measured to move the Table 1 rows at 1/240 s and 1 ms
/// either way.
pub(crate) fn rebound_threshold(
    s: &ToppleSettings,
    gravity: Vector,
    params: &IntegrationParameters,
    substeps: usize,
) -> f64 {
    let scaled = effective(s, gravity, params);
    let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
    let l = f64::from(params.length_unit);
    let l = if l.is_finite() && l > 0.0 { l } else { 1.0 };
    let g = finite(f64::from(gravity.length()));
    if substeps <= 1 {
        return scaled.min_approach_speed;
    }
    let h = finite(f64::from(params.dt)).max(0.0) / substeps as f64;
    (s.min_approach_speed * l)
        .max(g * h)
        .min(scaled.min_approach_speed)
}
