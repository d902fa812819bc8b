//! topple on `rapier2d` (f32, the build `bevy_rapier2d` uses; re-exported as
//! [`crate::rapier2d`]). The same source as [`super::f64`], compiled for f32:
//!
//! Rapier works in f32, the LZB resolver and the coupling layer stay f64
//! inside (see the module docs of [`super`] for the tolerances).

// One source compiled for two precisions: a cast or conversion that is a
// no-op in one build is needed in the other.
#![allow(clippy::unnecessary_cast, clippy::useless_conversion)]

use ::rapier2d as backend;

#[path = "adapter/cadence.rs"]
mod cadence;
#[path = "adapter/chain.rs"]
pub mod chain;
#[path = "adapter/hooks.rs"]
mod hooks;
#[path = "adapter/motion.rs"]
mod motion;
#[path = "adapter/pass/mod.rs"]
mod pass;
#[path = "adapter/scale.rs"]
mod scale;
#[path = "adapter/scene_build.rs"]
mod scene_build;
#[path = "adapter/scene_run.rs"]
mod scene_run;
#[path = "adapter/support.rs"]
mod support;
#[path = "adapter/world.rs"]
mod world;

pub use backend::math::Real;
pub use hooks::{ChainedHooks, ToppleHooks};
pub use pass::{ImpactContact, ImpactEvent};
pub use scene_build::{build, integration_parameters, RowInfo, SceneWorld};
pub use scene_run::{impact_input_json, run_scene, signed_gap, HitTracker};
pub use support::{Notice, LOCKED_INERTIA};
pub use world::{StepParts, ToppleRapier};

/// This build's precision.
pub const PRECISION: crate::rapier::Precision = crate::rapier::Precision::F32;
