//! Scenes: a documented TOML format (boxes, balls, ground, materials, pair
//! rules, gravity, duration, solver settings, a domino-row generator), built
//! into a Rapier world and run with topple or with native Rapier.

mod build;
mod format;
mod row;
mod run;

pub use build::{build, topple_settings, Engine, RowInfo, SceneWorld};
pub use format::{
    BodySpec, GroundSpec, MaterialSpec, PairLaw, PairSpec, RowOverrides, RowSpec, Scene, ShapeKind,
    SolverSpec,
};
pub use row::{expand_row, preset, Preset, RowMeasures};
pub use run::{
    impact_input_json, load_scene, run_scene, signed_gap, BodyState, HitTracker, RunOptions,
    SceneOutput, TimedImpact,
};
