//! The Bevy plugin in headless apps (feature `bevy`).
//!
//! One test binary per layer (so each links the crate once); each file below
//! was a test binary of its own and keeps its tests and tolerances.

mod cradle;
#[path = "../../examples/common/scenes.rs"]
mod example_scenes;
mod parallel;
mod row;
mod scenes;
