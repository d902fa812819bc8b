//! The Bevy plugin (feature `bevy`): topple's impacts in a bevy_rapier2d app.
//!
//! bevy_rapier2d steps its Rapier contexts in one system that loops over its
//! sub-steps itself, so nothing can act between them from outside. topple
//! therefore takes the step over: [`rapier_plugin`] is bevy_rapier's plugin
//! without its step system, and [`TopplePlugin`] puts its own step in the
//! same place. Contexts with a [`ToppleWorld`] (the default context gets one)
//! are stepped through topple's Rapier adapter, which resolves each impact at
//! the instant its pair closes, splits Rapier's step there and sub-steps a
//! 1/60 s frame into 1/240 s pieces ([`crate::rapier`]); every other context
//! is stepped by bevy_rapier's own code, unchanged. Only colliders whose
//! entity has a [`ToppleMaterial`] take part in LZB impacts; the rest is
//! plain Rapier.
//!
//! | plugin | system set | schedule (default `PostUpdate`) | what it does |
//! | --- | --- | --- | --- |
//! | [`rapier_plugin`] | `PhysicsSet::SyncBackend` | bevy_rapier's | Bevy components into Rapier (unchanged) |
//! | [`TopplePlugin`] | [`ToppleSystems::Attach`] | after `SyncBackend` | clocks on new contexts, a [`ToppleWorld`] on the default one |
//! | [`TopplePlugin`] | [`ToppleSystems::Manage`] | after `Attach` | colliders with a [`ToppleMaterial`] handed to topple, [`ToppleConfig`] applied |
//! | [`TopplePlugin`] | [`ToppleSystems::Step`] | inside `PhysicsSet::StepSimulation` | every context stepped; [`ToppleImpact`] messages, [`ToppleFrameStats`] |
//! | [`TopplePlugin`] | [`ToppleSystems::Measure`] | after `Step`, before `Writeback` | [`DominoRowState`] hit times and v̂ |
//! | [`rapier_plugin`] | `PhysicsSet::Writeback` | bevy_rapier's | Rapier poses and velocities back into Bevy (unchanged) |
//!
//! All timestep modes of bevy_rapier work (`Fixed` with its sub-steps,
//! `Variable`, `Interpolated`), and so does `.in_fixed_schedule()` on both
//! plugins. What differs from bevy_rapier: contact-force events are not sent
//! for topple's contexts (collision events are), and user physics hooks
//! (`RapierPhysicsPlugin<MyHooks>`) are not called in topple's contexts.
//!
//! | item | role |
//! | --- | --- |
//! | [`TopplePlugin`], [`rapier_plugin`], [`ToppleSystems`] | the plugins and system sets |
//! | [`ToppleMaterial`] | per collider: opt in with an impact material |
//! | [`ToppleConfig`] | resource: settings and pair rules |
//! | [`ToppleFrameStats`] | resource: impacts, LZB steps, fallbacks and time of the last frame |
//! | [`ToppleImpact`], [`ImpactPoint`] | message per resolved impact group |
//! | [`ToppleNotice`] | message (and a warning) per collider whose impacts are left to Rapier |
//! | [`ToppleWorld`], [`PhysicsClock`] | per context: topple's adapter, simulated time |
//! | [`DominoRow`], [`DominoRowState`], [`ImpactResponse`] | spawn a Table 1 row; its wave measures |
//! | [`SceneSpawn`], [`SpawnedScene`] | spawn a scene file of `topple scene` (scaled into the app's units) |
//!
//! ```no_run
//! use bevy::prelude::*;
//! use topple::bevy::{rapier_plugin, DominoRow, TopplePlugin};
//! use topple::domino::{Preset, RowSpec};
//!
//! fn setup(mut commands: Commands) {
//!     let p = Preset::T.params();
//!     let row = DominoRow::new(RowSpec::new(p, 0.45 * p.block.height, 40, 1.0));
//!     row.spawn(&mut commands).expect("a valid row");
//! }
//!
//! App::new()
//!     .add_plugins((MinimalPlugins, TransformPlugin))
//!     .add_plugins((rapier_plugin(), TopplePlugin::default()))
//!     .add_systems(Startup, setup)
//!     .run();
//! ```

mod events;
mod headless;
mod plugin;
mod row;
mod scene;
mod step;
mod world;

#[doc(no_inline)]
pub use crate::rapier::ImpactResponse;
pub use events::{ImpactPoint, ToppleImpact, ToppleNotice};
pub use headless::{headless_row_app, step_frames};
pub use plugin::{rapier_plugin, TopplePlugin, ToppleSystems};
pub use row::{DominoRow, DominoRowState};
pub use scene::{SceneSpawn, SpawnedScene};
pub use world::{PhysicsClock, ToppleConfig, ToppleFrameStats, ToppleMaterial, ToppleWorld};
