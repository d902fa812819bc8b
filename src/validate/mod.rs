//! Input checks at the entry points (CLI flags, scene files, impact JSON):
//! every bad value is refused before any work starts, with one line naming
//! the field, the value and the allowed range. The limits are documented in
//! `docs/input-limits.md`. A scene's checks, which need the scene format,
//! live beside it: [`crate::rapier::scene::check_scene`].
//!
//! | item | file | what it checks |
//! | --- | --- | --- |
//! | [`InputError`], [`check_range`], [`check_count`] | `mod.rs` | the error and the range checks every other file uses |
//! | [`row()`], [`RunBudget`], [`Naming`] | `row.rs` | a domino row, the engine's time step, tolerance and budget |
//! | [`memory_estimate`], [`check_memory`] | `memory.rs` | what a row of n blocks needs against what the machine has |
//! | [`parse_toml`], [`SyntaxError`] | `syntax.rs` | one-line parse errors of TOML and JSON input |
//! | `Placed`, `overlap`, `box_overlap` | `overlap.rs` | overlap depth of balls and boxes (the scene check, the stress sweep) |
//! | [`impact()`], [`impact_stepping`] | `impact.rs` | the magnitudes of an impact given as JSON; the reference engine's impulse stepping flags |
//!
//! ```
//! use topple::validate::check_range;
//! let e = check_range("--dt", f64::NAN, 1e-7, 3e-3).unwrap_err();
//! assert_eq!(e.to_string(), "--dt = NaN: allowed 1e-7 ≤ --dt ≤ 0.003");
//! assert!(check_range("--dt", 1e-4, 1e-7, 3e-3).is_ok());
//! ```

mod impact;
mod memory;
pub(crate) mod overlap;
pub mod row;
mod syntax;

pub use impact::{impact, impact_stepping};
pub use memory::{available_memory, check_memory, memory_estimate, EngineKind};
#[cfg(all(feature = "f32", feature = "f64"))]
pub(crate) use overlap::box_overlap;
pub use row::{row, Naming, RunBudget};
#[cfg(feature = "scene-files")]
pub use syntax::parse_toml;
pub use syntax::SyntaxError;

/// A value outside its allowed range: the field, the value as given and the
/// range, printed on one line. The CLI exits with status 2 on it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field} = {value}: allowed {allowed}")]
pub struct InputError {
    /// The flag or key (`--dt`, `row.spacing`, `bodies[2].radius`).
    pub field: String,
    /// The value as given.
    pub value: String,
    /// The allowed range or form.
    pub allowed: String,
}

impl InputError {
    /// An error for `field` holding `value`, allowed `allowed`.
    pub fn new(field: impl Into<String>, value: impl ToString, allowed: impl Into<String>) -> Self {
        InputError {
            field: field.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }
}

/// Shortest readable form of a limit: `1e-7`, `0.05`, `3`.
pub(crate) fn fmt_limit(x: f64) -> String {
    if x == 0.0 || (1e-3..1e4).contains(&x.abs()) {
        let s = format!("{x}");
        if s.len() <= 8 {
            return s;
        }
        return format!("{x:.4}");
    }
    let s = format!("{x:e}");
    match s.split_once('e') {
        Some((m, e)) if m.len() > 6 => format!("{:.3}e{e}", m.parse::<f64>().unwrap_or(x)),
        _ => s,
    }
}

/// A value as the user would write it: `0.3`, `1e200`, `NaN`, `-inf`.
pub(crate) fn fmt_value(x: f64) -> String {
    if x.is_finite() && x != 0.0 && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `lo ≤ value ≤ hi` and finite.
pub fn check_range(field: &str, value: f64, lo: f64, hi: f64) -> Result<f64, InputError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(value)
    } else {
        Err(InputError::new(
            field,
            fmt_value(value),
            format!("{} ≤ {field} ≤ {}", fmt_limit(lo), fmt_limit(hi)),
        ))
    }
}

/// `lo < value ≤ hi` and finite.
pub fn check_open_low(field: &str, value: f64, lo: f64, hi: f64) -> Result<f64, InputError> {
    if value.is_finite() && value > lo && value <= hi {
        Ok(value)
    } else {
        Err(InputError::new(
            field,
            fmt_value(value),
            format!("{} < {field} ≤ {}", fmt_limit(lo), fmt_limit(hi)),
        ))
    }
}

/// `lo ≤ value ≤ hi` for a count.
pub fn check_count(field: &str, value: usize, lo: usize, hi: usize) -> Result<usize, InputError> {
    if (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(InputError::new(
            field,
            value,
            format!("{lo} ≤ {field} ≤ {hi}"),
        ))
    }
}
