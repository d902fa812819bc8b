//! Scenes: a documented TOML format (boxes, balls, ground, materials, pair
//! rules, gravity, duration, solver settings, a domino-row generator), built
//! into a Rapier world and run with topple or with native Rapier, on either
//! Rapier build.
//!
//! | item | file | role |
//! | --- | --- | --- |
//! | [`Scene`] and its parts | `format.rs` | the TOML format (serde) |
//! | [`SceneError`] | `error.rs` | why a scene could not be loaded, built or run |
//! | [`expand_row`], [`row_params`] | `row.rs` | the `[row]` generator over [`crate::domino`]'s presets and ground models |
//! | [`SceneOutput`], [`row_scene`] | `setup.rs` | build-independent front: settings, materials, output |
//! | [`run_scene`], [`run_row`] | `run.rs` | dispatch to the `f64` or `f32` build (each behind its cargo feature) |
//! | [`check_scene`] | `check.rs` | a parsed scene's ranges, degenerate shapes, overlapping bodies |

mod check;
mod error;
mod format;
mod row;
mod run;
mod setup;

#[doc(no_inline)]
pub use crate::rapier::ImpactResponse;
pub use check::check_scene;
pub use error::{SceneError, SceneResult};
pub use format::{
    BodySpec, GroundSpec, MaterialSpec, PairLaw, PairSpec, RowOverrides, RowSection, Scene,
    ShapeKind, SolverSpec, WorkBudget,
};
pub use row::{expand_row, row_params, NO_SLIP_FRICTION};
pub use run::{run_row, run_scene};
#[cfg(feature = "scene-files")]
pub use setup::load_scene;
#[cfg(any(feature = "f32", feature = "f64"))]
pub(crate) use setup::pair_material;
pub use setup::{row_scene, topple_settings, BodyState, RunOptions, SceneOutput, TimedImpact};
