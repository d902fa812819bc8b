//! [`TopplePlugin`]: where topple's systems run in bevy_rapier's schedule.

use bevy::ecs::schedule::{InternedScheduleLabel, ScheduleLabel};
use bevy::platform::collections::HashSet;
use bevy::prelude::*;
use bevy_rapier2d::prelude::*;

use super::events::{ToppleImpact, ToppleNotice};
use super::row::track_rows;
use super::step::{attach_to_contexts, manage_colliders, step_contexts};
use super::world::{ToppleConfig, ToppleFrameStats};
use crate::coupling::ToppleSettings;
use crate::rapier::ImpactResponse;

/// The system sets topple adds to the physics schedule (see the table in
/// [`crate::bevy`]).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ToppleSystems {
    /// Gives new Rapier contexts their clock and the default one its
    /// [`crate::bevy::ToppleWorld`].
    Attach,
    /// Registers the colliders of entities with a
    /// [`crate::bevy::ToppleMaterial`] and applies [`ToppleConfig`].
    Manage,
    /// Steps every context (in bevy_rapier's `PhysicsSet::StepSimulation`).
    Step,
    /// Updates the [`crate::bevy::DominoRowState`] measures.
    Measure,
}

/// bevy_rapier's plugin without its own step, which [`TopplePlugin`]
/// replaces: the sync and writeback systems only. Use it in place of
/// `RapierPhysicsPlugin::<NoUserData>::default()` (then set the length unit,
/// schedule or initialization as usual).
///
/// ```
/// let rapier = topple::bevy::rapier_plugin().in_fixed_schedule();
/// # let _ = rapier;
/// ```
pub fn rapier_plugin() -> RapierPhysicsPlugin<NoUserData> {
    RapierPhysicsPlugin::<NoUserData>::default().with_physics_sets_systems(HashSet::from_iter([
        PhysicsSet::SyncBackend,
        PhysicsSet::Writeback,
    ]))
}

/// LZB impacts for bevy_rapier2d: add it next to [`rapier_plugin`] (in the
/// same schedule). It steps every Rapier context in bevy_rapier's
/// `PhysicsSet::StepSimulation`: the contexts with a
/// [`crate::bevy::ToppleWorld`] (the default context gets one) with topple's
/// impacts at their instant, the others exactly as bevy_rapier would.
///
/// ```no_run
/// use bevy::prelude::*;
/// use topple::bevy::{rapier_plugin, TopplePlugin};
/// App::new()
///     .add_plugins((MinimalPlugins, TransformPlugin))
///     .add_plugins((rapier_plugin(), TopplePlugin::default()))
///     .run();
/// ```
#[derive(Debug, Clone)]
pub struct TopplePlugin {
    schedule: InternedScheduleLabel,
    settings: ToppleSettings,
    default_context: ImpactResponse,
}

impl Default for TopplePlugin {
    fn default() -> Self {
        TopplePlugin {
            schedule: PostUpdate.intern(),
            settings: ToppleSettings::default(),
            default_context: ImpactResponse::Topple,
        }
    }
}

impl TopplePlugin {
    /// With these settings (also reachable later through [`ToppleConfig`]).
    pub fn with_settings(mut self, settings: ToppleSettings) -> Self {
        self.settings = settings;
        self
    }

    /// Who steps the default context (topple by default).
    pub fn with_default_context(mut self, who: ImpactResponse) -> Self {
        self.default_context = who;
        self
    }

    /// In `FixedUpdate`, for a `RapierPhysicsPlugin` put there with
    /// `in_fixed_schedule()`.
    pub fn in_fixed_schedule(self) -> Self {
        self.in_schedule(FixedUpdate)
    }

    /// In the schedule bevy_rapier's systems run in.
    pub fn in_schedule(mut self, schedule: impl ScheduleLabel) -> Self {
        self.schedule = schedule.intern();
        self
    }
}

impl Plugin for TopplePlugin {
    fn build(&self, app: &mut App) {
        if !app.world().contains_resource::<ToppleConfig>() {
            app.insert_resource(ToppleConfig {
                settings: self.settings,
                pair_rules: Vec::new(),
            });
        }
        app.insert_resource(self.default_context)
            .init_resource::<ToppleFrameStats>()
            .add_message::<ToppleImpact>()
            .add_message::<ToppleNotice>()
            .configure_sets(
                self.schedule,
                (
                    ToppleSystems::Attach,
                    ToppleSystems::Manage,
                    ToppleSystems::Step,
                    ToppleSystems::Measure,
                )
                    .chain()
                    .after(PhysicsSet::SyncBackend)
                    .before(PhysicsSet::Writeback),
            )
            .configure_sets(
                self.schedule,
                ToppleSystems::Step.in_set(PhysicsSet::StepSimulation),
            )
            .add_systems(
                self.schedule,
                (
                    attach_to_contexts.in_set(ToppleSystems::Attach),
                    manage_colliders.in_set(ToppleSystems::Manage),
                    step_contexts.in_set(ToppleSystems::Step),
                    track_rows.in_set(ToppleSystems::Measure),
                ),
            );
    }
}
