//! The structured input error every layer returns for a bad value: the
//! field, the value as given and the allowed range, printed on one line
//! (`--dt = NaN: allowed 1e-7 ≤ --dt ≤ 0.003`). It sits above every other
//! layer so that the domino presets, the theory, the resolver's settings, the
//! reference engine and the scene format all carry the same type; the entry
//! points' checks that build on it are in [`crate::validate`].
//!
//! ```
//! use topple::input::{check_range, InputError};
//! let e: InputError = check_range("spacing", -0.01, 0.0, 0.046).unwrap_err();
//! assert_eq!(e.field, "spacing");
//! assert_eq!(e.value, "-0.01");
//! assert_eq!(e.to_string(), "spacing = -0.01: allowed 0 ≤ spacing ≤ 0.046");
//! ```

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

/// The one-line message, for callers that report errors as text.
impl From<InputError> for String {
    fn from(e: InputError) -> String {
        e.to_string()
    }
}
