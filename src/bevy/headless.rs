//! A headless app that runs one domino row at a fixed step, deterministic
//! frame by frame: for tests, benchmarks and the `headless_row` example.

use std::time::Duration;

use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bevy_rapier2d::plugin::RapierContextInitialization;
use bevy_rapier2d::prelude::*;

use super::plugin::{rapier_plugin, TopplePlugin};
use super::row::DominoRow;
use crate::input::InputError;

/// An app without window or renderer (MinimalPlugins, transforms,
/// bevy_rapier and topple) stepping the row's context at a fixed `dt` (s),
/// one physics step per `app.update()`, with the row spawned. A
/// [`ImpactResponse::Native`](crate::rapier::ImpactResponse::Native) row runs in a context stepped by bevy_rapier's own
/// code. Returns the app and the row entity (its [`super::DominoRowState`]).
///
/// ```
/// use topple::bevy::{headless_row_app, step_frames, DominoRow, DominoRowState};
/// use topple::domino::{Preset, RowSpec};
/// let p = Preset::T.params().ideal();
/// let row = DominoRow::new(RowSpec::new(p, 0.45 * p.block.height, 4, 1.0));
/// let (mut app, id) = headless_row_app(&row, 1.0 / 60.0).unwrap();
/// step_frames(&mut app, 60);
/// let state = app.world().get::<DominoRowState>(id).unwrap();
/// assert_eq!(state.hit_times().len(), 4); // the wave reached block 4
/// ```
pub fn headless_row_app(row: &DominoRow, dt: f64) -> Result<(App, Entity), InputError> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(InputError::new("dt", dt, "0 < dt, finite (s)"));
    }
    row.spec.validate()?;
    let init = RapierContextInitialization::InitializeDefaultRapierContext {
        integration_parameters: row.integration_parameters(dt),
        rapier_configuration: row.rapier_configuration(),
    };
    let who = row.physics;
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin))
        .add_plugins((
            rapier_plugin().with_custom_initialization(init),
            TopplePlugin::default()
                .with_settings(row.topple_settings(dt))
                .with_default_context(who),
        ))
        .insert_resource(TimestepMode::Fixed {
            dt: dt as f32,
            substeps: 1,
        })
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
            dt,
        )));
    app.finish();
    app.cleanup();
    // the context exists after the first update (PreStartup)
    app.update();
    let row = DominoRow {
        context: None,
        ..row.clone()
    };
    let id = {
        let world = app.world_mut();
        let mut commands = world.commands();
        let id = row.spawn(&mut commands)?;
        world.flush();
        id
    };
    Ok((app, id))
}

/// Runs `frames` updates of an app.
pub fn step_frames(app: &mut App, frames: usize) {
    for _ in 0..frames {
        app.update();
    }
}
