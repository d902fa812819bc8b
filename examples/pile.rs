//! Boxes and balls poured onto a ramp and a floor, in a window, in
//! bevy_rapier's pixel units, with topple's impacts or native bevy_rapier
//! (key N switches and pours again, R pours again). The HUD shows frames
//! per second and what the physics step cost; every impact beyond the
//! step's work budget is finished by topple's fallback (counted).
//!
//! ```text
//! cargo run --release --features bevy --example pile
//! cargo run --release --features bevy --example pile -- --bodies 300 --native
//! cargo run --release --features bevy --example pile -- --screenshot pile.png --frames 240
//! ```
//!
//! Flags: `--bodies N` (how many to pour, 1 to 2,000, default 200; one every
//! four frames), `--native`, `--screenshot FILE --frames N` (save the window
//! after N frames to FILE, then exit).

mod common;

use std::path::PathBuf;

use bevy::prelude::*;
use bevy_rapier2d::prelude::*;
use common::scenes::{label, other, pour_body, pour_ground, Lcg, Piece, DT, PPM};
use common::view::{self, Contexts, Hud, Meter};
use topple::bevy::ImpactResponse;
use topple::bevy::{rapier_plugin, ToppleFrameStats, TopplePlugin};

#[derive(Resource)]
struct Pour {
    physics: ImpactResponse,
    bodies: usize,
    poured: usize,
    started: bool,
    rng: Lcg,
    screenshot: Option<(PathBuf, u32)>,
    frame: u32,
}

fn parse_args() -> Result<Pour, String> {
    let mut pour = Pour {
        physics: ImpactResponse::Topple,
        bodies: 200,
        poured: 0,
        started: false,
        rng: Lcg(3),
        screenshot: None,
        frame: 0,
    };
    let (mut file, mut frames) = (None, 240u32);
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--bodies" => pour.bodies = value()?.parse().map_err(|e| format!("--bodies: {e}"))?,
            "--native" => pour.physics = ImpactResponse::Native,
            "--screenshot" => file = Some(PathBuf::from(value()?)),
            "--frames" => frames = value()?.parse().map_err(|e| format!("--frames: {e}"))?,
            other => {
                return Err(format!(
                    "unknown flag {other}: --bodies N --native --screenshot FILE --frames N"
                ))
            }
        }
    }
    if !(1..=2000).contains(&pour.bodies) {
        return Err(format!(
            "--bodies = {}: allowed 1 ≤ --bodies ≤ 2000",
            pour.bodies
        ));
    }
    pour.screenshot = file.map(|f| (f, frames.max(1)));
    Ok(pour)
}

fn main() -> AppExit {
    let pour = match parse_args() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return AppExit::from_code(2);
        }
    };
    App::new()
        .add_plugins(DefaultPlugins.set(view::window(
            "topple: a pile poured onto a ramp (N: native / topple, R: pour again)",
        )))
        .add_plugins((
            rapier_plugin().with_length_unit(PPM),
            TopplePlugin::default(),
        ))
        .insert_resource(TimestepMode::Fixed {
            dt: DT,
            substeps: 1,
        })
        .insert_resource(ClearColor(Color::srgb(0.08, 0.08, 0.1)))
        .insert_resource(pour)
        .add_systems(Startup, (view::setup_view, view::load_textures, setup))
        .add_systems(
            Update,
            (keys, pour_more, view::decorate, hud, screenshot).chain(),
        )
        .run()
}

fn setup(mut commands: Commands) {
    view::spawn_hud(&mut commands);
}

/// N switches between topple and native bevy_rapier, R pours again.
fn keys(
    mut commands: Commands,
    input: Res<ButtonInput<KeyCode>>,
    mut pour: ResMut<Pour>,
    pieces: Query<Entity, With<Piece>>,
) {
    let switch = input.just_pressed(KeyCode::KeyN);
    if !(switch || input.just_pressed(KeyCode::KeyR)) {
        return;
    }
    if switch {
        pour.physics = other(pour.physics);
    }
    for e in &pieces {
        commands.entity(e).despawn();
    }
    pour.started = false;
    pour.poured = 0;
    pour.rng = Lcg(3);
}

/// The ground at the start, then one body every four frames.
fn pour_more(mut commands: Commands, mut pour: ResMut<Pour>, contexts: Res<Contexts>) {
    let target = contexts.target(pour.physics);
    if !pour.started {
        pour_ground(&mut commands, target);
        pour.started = true;
        pour.frame = 0;
    }
    if pour.frame.is_multiple_of(4) && pour.poured < pour.bodies {
        let k = pour.poured;
        let pour = &mut *pour;
        pour_body(&mut commands, target, k, &mut pour.rng);
        pour.poured += 1;
    }
}

fn hud(
    time: Res<Time<bevy::time::Real>>,
    pour: Res<Pour>,
    stats: Res<ToppleFrameStats>,
    mut meter: ResMut<Meter>,
    mut text: Query<&mut Text2d, With<Hud>>,
) {
    meter.update(time.delta_secs(), &stats);
    let Ok(mut text) = text.single_mut() else {
        return;
    };
    text.0 = format!(
        "boxes and balls poured onto a ramp, {}: {}/{} poured   [N] {} [R] pour again\n{}",
        label(pour.physics),
        pour.poured,
        pour.bodies,
        label(other(pour.physics)),
        meter.line(&stats),
    );
}

fn screenshot(mut commands: Commands, mut pour: ResMut<Pour>, mut exit: MessageWriter<AppExit>) {
    pour.frame += 1;
    let Some((file, frames)) = pour.screenshot.clone() else {
        return;
    };
    common::screenshot_then_exit(&mut commands, &mut exit, file, pour.frame, frames);
}
