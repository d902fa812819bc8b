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

pub(crate) use crate::input::fmt_value;
pub use crate::input::{check_count, check_open_low, check_range, InputError};
pub use impact::{impact, impact_stepping};
pub use memory::{available_memory, check_memory, memory_estimate, EngineKind};
#[cfg(all(feature = "f32", feature = "f64"))]
pub(crate) use overlap::box_overlap;
pub use row::{row, Naming, RunBudget};
#[cfg(feature = "scene-files")]
pub use syntax::parse_toml;
pub use syntax::SyntaxError;
