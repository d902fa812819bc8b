//! The smallest spacing with a wave: a scan of s/h upwards, then bisection of
//! the first step from "no wave" to "wave".

use super::{solve, Geometry, Model, Outcome, TheoryError};
use crate::input::InputError;
use serde::Serialize;

/// Two spacings around the smallest spacing with a wave: the model has no wave
/// at `without_wave` and a wave at `with_wave`, `without_wave < with_wave`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpacingBracket {
    /// s/h with no wave.
    pub without_wave: f64,
    /// s/h with a wave.
    pub with_wave: f64,
}

/// Smallest s/h with a wave for `model` and thickness ratio `d/h`, bracketed
/// to `tolerance` (in s/h): scans s/h = 0.001, 0.002, …, 0.999 for the first
/// wave, then bisects the step before it. An error if there is a wave already at
/// s/h = 0.001 or nowhere on the scan. Bisection also stops, with a wider
/// bracket, if a point is so close to the stall that its period cannot be
/// resolved to 10⁻⁶ (a `NotConverged` error from [`solve`](super::solve)).
///
/// ```
/// use topple::theory::{min_spacing, Model};
/// let b = min_spacing(&Model::Single { mu: 0.0, e: 0.0 }, 0.12, 1e-8).unwrap();
/// assert!(b.with_wave - b.without_wave <= 1e-8);
/// // gravity must gain from 0 to θ_c: θ_c > 2 atan(d/h)
/// assert!(b.with_wave > (2.0 * 0.12_f64.atan()).sin());
/// ```
pub fn min_spacing(
    model: &Model,
    thickness_ratio: f64,
    tolerance: f64,
) -> Result<SpacingBracket, TheoryError> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(TheoryError::InvalidParameter(InputError::new(
            "tolerance",
            tolerance,
            "finite and tolerance > 0",
        )));
    }
    let has_wave = |s: f64| -> Result<bool, TheoryError> {
        let out = solve(model, &Geometry::new(thickness_ratio, s)?)?;
        Ok(matches!(out, Outcome::Wave(_)))
    };
    let step = 1e-3;
    if has_wave(step)? {
        return Err(TheoryError::NoThreshold {
            model: model.name(),
            wave_at: Some(step),
        });
    }
    let mut lo = step;
    for i in 2..1000 {
        let s = step * i as f64;
        if has_wave(s)? {
            let mut hi = s;
            while hi - lo > tolerance {
                let mid = 0.5 * (lo + hi);
                match has_wave(mid) {
                    Ok(true) => hi = mid,
                    Ok(false) => lo = mid,
                    Err(TheoryError::NotConverged(_)) => break,
                    Err(e) => return Err(e),
                }
            }
            return Ok(SpacingBracket {
                without_wave: lo,
                with_wave: hi,
            });
        }
        lo = s;
    }
    Err(TheoryError::NoThreshold {
        model: model.name(),
        wave_at: None,
    })
}
