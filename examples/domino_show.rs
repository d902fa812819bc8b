//! A domino show in a window, in bevy_rapier's pixel units, with topple's
//! impacts or native bevy_rapier (key N switches, R restarts): several rows
//! toppling at once, dominoes growing 1.5× along a row into a tower of
//! dominoes stacked flat, which the last and largest knocks into a pile, and
//! a row down a flight of steps. The HUD shows frames per second and what
//! the physics step cost.
//!
//! ```text
//! cargo run --release --features bevy --example domino_show
//! cargo run --release --features bevy --example domino_show -- --fronts 6 --native
//! cargo run --release --features bevy --example domino_show -- --screenshot show.png --frames 90
//! ```
//!
//! Flags: `--fronts N` (parallel rows, 1 to 16, default 6; 13 fit the
//! 720-pixel window, more run on below it), `--native`
//! (start with native bevy_rapier), `--screenshot FILE --frames N` (save the
//! window after N frames to FILE and the rows' state to FILE.json, then
//! exit). Colours: a domino within 0.1 rad of upright is light grey, a
//! toppled one orange with topple and blue with native bevy_rapier.

mod common;

use std::path::PathBuf;

use bevy::prelude::*;
use bevy_rapier2d::prelude::*;
use common::scenes::{label, other, Piece, Role, DT, PPM};
use common::show::{domino_show, ShowLayout, FRONT_H};
use common::view::{self, Contexts, Hud, Meter, HEIGHT, UPRIGHT_ANGLE, WIDTH};
use topple::bevy::ImpactResponse;
use topple::bevy::{rapier_plugin, ToppleFrameStats, TopplePlugin};

#[derive(Resource)]
struct Show {
    physics: ImpactResponse,
    fronts: usize,
    layout: Option<ShowLayout>,
    screenshot: Option<(PathBuf, u32)>,
    frame: u32,
}

fn parse_args() -> Result<Show, String> {
    let mut show = Show {
        physics: ImpactResponse::Topple,
        fronts: 6,
        layout: None,
        screenshot: None,
        frame: 0,
    };
    let (mut file, mut frames) = (None, 90u32);
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--fronts" => show.fronts = value()?.parse().map_err(|e| format!("--fronts: {e}"))?,
            "--native" => show.physics = ImpactResponse::Native,
            "--screenshot" => file = Some(PathBuf::from(value()?)),
            "--frames" => frames = value()?.parse().map_err(|e| format!("--frames: {e}"))?,
            other => {
                return Err(format!(
                    "unknown flag {other}: --fronts N --native --screenshot FILE --frames N"
                ))
            }
        }
    }
    if !(1..=16).contains(&show.fronts) {
        return Err(format!(
            "--fronts = {}: allowed 1 ≤ --fronts ≤ 16",
            show.fronts
        ));
    }
    show.screenshot = file.map(|f| (f, frames.max(1)));
    Ok(show)
}

fn main() -> AppExit {
    let show = match parse_args() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return AppExit::from_code(2);
        }
    };
    App::new()
        .add_plugins(DefaultPlugins.set(view::window(
            "topple: domino show (N: native / topple, R: restart)",
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
        .insert_resource(show)
        .add_systems(Startup, (view::setup_view, view::load_textures, setup))
        .add_systems(
            Update,
            (keys, spawn, view::decorate, colour, hud, screenshot).chain(),
        )
        .run()
}

fn setup(mut commands: Commands) {
    view::spawn_hud(&mut commands);
}

/// N switches between topple and native bevy_rapier, R restarts.
fn keys(
    mut commands: Commands,
    input: Res<ButtonInput<KeyCode>>,
    mut show: ResMut<Show>,
    pieces: Query<Entity, With<Piece>>,
) {
    let switch = input.just_pressed(KeyCode::KeyN);
    if !(switch || input.just_pressed(KeyCode::KeyR)) {
        return;
    }
    if switch {
        show.physics = other(show.physics);
    }
    for e in &pieces {
        commands.entity(e).despawn();
    }
    show.layout = None;
}

/// Spawns the show when there is none (at start, after N or R).
fn spawn(mut commands: Commands, mut show: ResMut<Show>, contexts: Res<Contexts>) {
    if show.layout.is_some() {
        return;
    }
    let target = contexts.target(show.physics);
    show.layout = Some(domino_show(&mut commands, target, show.fronts));
}

fn colour(show: Res<Show>, dominoes: Query<(&Transform, &Piece, &mut Sprite)>) {
    view::colour_dominoes(show.physics, dominoes);
}

fn toppled(layout: &[Entity], transforms: &Query<&Transform>) -> usize {
    layout
        .iter()
        .filter_map(|&e| transforms.get(e).ok())
        .filter(|t| t.rotation.to_euler(EulerRot::ZYX).0.abs() >= UPRIGHT_ANGLE)
        .count()
}

fn hud(
    time: Res<Time<bevy::time::Real>>,
    show: Res<Show>,
    stats: Res<ToppleFrameStats>,
    mut meter: ResMut<Meter>,
    transforms: Query<&Transform>,
    mut text: Query<&mut Text2d, With<Hud>>,
) {
    meter.update(time.delta_secs(), &stats);
    let (Ok(mut text), Some(layout)) = (text.single_mut(), show.layout.as_ref()) else {
        return;
    };
    let fronts: Vec<Entity> = layout
        .rows
        .iter()
        .flat_map(|r| r.dominoes.clone())
        .collect();
    text.0 = format!(
        "domino show, {}: {} fronts, dominoes growing 1.5x into a tower, a row down steps   [N] {} [R] restart\n{}\ndown: fronts {}/{}   growing {}/{}   tower {}/{}   steps {}/{}",
        label(show.physics),
        show.fronts,
        label(other(show.physics)),
        meter.line(&stats),
        toppled(&fronts, &transforms),
        fronts.len(),
        toppled(&layout.growing, &transforms),
        layout.growing.len(),
        toppled(&layout.tower, &transforms),
        layout.tower.len(),
        toppled(&layout.steps, &transforms),
        layout.steps.len(),
    );
}

/// `--screenshot`: after N frames, the window to FILE and the fronts' state
/// to FILE.json; exits when the image is written.
fn screenshot(
    mut commands: Commands,
    mut show: ResMut<Show>,
    transforms: Query<&Transform>,
    pieces: Query<&Piece>,
    mut exit: MessageWriter<AppExit>,
) {
    show.frame += 1;
    let Some((file, frames)) = show.screenshot.clone() else {
        return;
    };
    if show.frame == frames {
        let state = fronts_json(&show, &transforms, &pieces);
        let json = file.with_extension("png.json");
        if let Err(e) = std::fs::write(&json, state.to_string()) {
            error!("cannot write {}: {e}", json.display());
            exit.write(AppExit::from_code(1));
            return;
        }
    }
    common::screenshot_then_exit(&mut commands, &mut exit, file, show.frame, frames);
}

/// The fronts as the screenshot shows them, in the schema of
/// `.ci/check_screenshot.py`: per row its upright and toppled dominoes, the
/// pixel row through the upright ones at 85 % of their height and the pixel
/// columns the row spans.
fn fronts_json(
    show: &Show,
    transforms: &Query<&Transform>,
    pieces: &Query<&Piece>,
) -> serde_json::Value {
    let to_px = |p: Vec2| (p.x + 0.5 * WIDTH as f32, 0.5 * HEIGHT as f32 - p.y);
    let mut rows = Vec::new();
    for row in show.layout.iter().flat_map(|l| &l.rows) {
        let angles: Vec<f32> = row
            .dominoes
            .iter()
            .filter(|&&e| pieces.get(e).is_ok_and(|p| p.role == Role::Domino))
            .filter_map(|&e| transforms.get(e).ok())
            .map(|t| t.rotation.to_euler(EulerRot::ZYX).0)
            .collect();
        let upright = angles.iter().filter(|a| a.abs() < UPRIGHT_ANGLE).count();
        let (x0, y) = to_px(Vec2::new(row.x0 - 4.0, row.shelf_y + 0.85 * FRONT_H));
        let (x1, _) = to_px(Vec2::new(row.x1 + 2.0 * FRONT_H, row.shelf_y));
        let (_, top) = to_px(Vec2::new(0.0, row.shelf_y + 1.2 * FRONT_H));
        let (_, bottom) = to_px(Vec2::new(0.0, row.shelf_y + 1.0));
        if top < 0.0 || bottom > HEIGHT as f32 {
            continue; // off the window
        }
        rows.push(serde_json::json!({
            "row": label(show.physics),
            "n": row.dominoes.len(),
            "upright": upright,
            "toppled": angles.len() - upright,
            "scan_y": y.round(),
            "x_min": x0.max(0.0).round(),
            "x_max": x1.min(WIDTH as f32 - 1.0).round(),
            "band_top": top.max(0.0).round(),
            "band_bottom": bottom.min(HEIGHT as f32 - 1.0).round(),
            "toppled_rgb": match show.physics {
                ImpactResponse::Topple => [242, 140, 38],
                ImpactResponse::Native => [64, 140, 242],
            },
        }));
    }
    serde_json::json!({ "width": WIDTH, "height": HEIGHT, "upright_rgb": [230, 230, 230], "rows": rows })
}
