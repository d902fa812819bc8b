//! Two domino rows side by side in a window: native bevy_rapier above, topple
//! below, same blocks, spacing and push, both stepped at 1/60 s. The HUD shows
//! each row's measured wave speed v̂_na and the cooperative model's.
//!
//! ```text
//! cargo run --release --features bevy --example dominoes
//! cargo run --release --features bevy --example dominoes -- --screenshot shot.png --frames 90
//! ```
//!
//! Keys: R restart, Up/Down spacing ±0.05 h, 1/2/3 preset X/T/P, I ideal
//! material on/off. With `--screenshot FILE --frames N` it saves the window
//! after N frames to FILE, the rows' state (upright and toppled blocks,
//! where they are on screen) to FILE.json, and exits.
//!
//! Colours: a block standing within 0.1 rad of upright is light grey; a
//! toppled one is orange in the topple row and blue in the native row (the
//! screenshot check, `.ci/check_screenshot.py`, looks for these colours).

mod common;

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::window::WindowResolution;
use bevy_rapier2d::plugin::RapierContextInitialization;
use bevy_rapier2d::prelude::*;
use topple::bevy::{rapier_plugin, DominoRow, DominoRowState, ImpactResponse, TopplePlugin};
use topple::domino::{Preset, RowSpec};
use topple::theory::{solve, Geometry, Model};

const DT: f64 = 1.0 / 60.0;
const WIDTH: u32 = 1280;
const HEIGHT: u32 = 720;
/// Metres per pixel of the camera.
const SCALE: f32 = 0.0016;
/// A block is drawn upright within this angle (rad).
const UPRIGHT: f32 = 0.1;
const GREY: Color = Color::srgb(0.9, 0.9, 0.9);
const ORANGE: Color = Color::srgb(0.95, 0.55, 0.15);
const BLUE: Color = Color::srgb(0.25, 0.55, 0.95);
const GROUND: Color = Color::srgb(0.35, 0.35, 0.35);
/// Height of the native row's ground above the topple row's (m).
const ROW_GAP: f32 = 0.3;

#[derive(Resource, Clone)]
struct Demo {
    preset: Preset,
    ideal: bool,
    spacing_ratio: f64,
    n: usize,
    native_context: Option<Entity>,
    rows: Vec<Entity>,
    screenshot: Option<(PathBuf, u32)>,
    frame: u32,
}

impl Demo {
    fn spec(&self) -> RowSpec {
        let mut p = self.preset.params();
        if self.ideal {
            p = p.ideal();
        }
        RowSpec::new(p, self.spacing_ratio * p.block.height, self.n, 1.0)
    }

    /// Where the rows start (m): centred in the window.
    fn origin(&self) -> Vec2 {
        let s = self.spec();
        Vec2::new(-0.5 * (s.pitch() * (s.n - 1) as f64) as f32, -0.2)
    }

    fn cooperative(&self) -> Option<f64> {
        let s = self.spec();
        let b = s.params.block;
        let g = Geometry::new(b.thickness / b.height, s.spacing_ratio()).ok()?;
        solve(&Model::Cooperative, &g).ok()?.natural_speed()
    }
}

fn parse_args() -> Result<Demo, String> {
    let mut demo = Demo {
        preset: Preset::T,
        ideal: true,
        spacing_ratio: 0.45,
        n: 40,
        native_context: None,
        rows: Vec::new(),
        screenshot: None,
        frame: 0,
    };
    let (mut file, mut frames) = (None, 120u32);
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--screenshot" => file = Some(PathBuf::from(value()?)),
            "--frames" => frames = value()?.parse().map_err(|e| format!("--frames: {e}"))?,
            "--preset" => demo.preset = value()?.parse()?,
            "--table1" => demo.ideal = false,
            "--n" => demo.n = value()?.parse().map_err(|e| format!("--n: {e}"))?,
            other => {
                return Err(format!(
                "unknown flag {other}: --screenshot FILE --frames N --preset x|t|p --table1 --n N"
            ))
            }
        }
    }
    if !(2..=200).contains(&demo.n) {
        return Err(format!("--n = {}: allowed 2 ≤ --n ≤ 200", demo.n));
    }
    demo.screenshot = file.map(|f| (f, frames.max(1)));
    Ok(demo)
}

fn main() -> AppExit {
    let demo = match parse_args() {
        Ok(d) => d,
        Err(e) => {
            eprintln!("error: {e}");
            return AppExit::from_code(2);
        }
    };
    let row = DominoRow::new(demo.spec());
    let init = RapierContextInitialization::InitializeDefaultRapierContext {
        integration_parameters: row.integration_parameters(DT),
        rapier_configuration: row.rapier_configuration(),
    };
    App::new()
        .add_plugins(DefaultPlugins.set(WindowPlugin {
            primary_window: Some(Window {
                title: "topple: native Rapier (top) and topple (bottom)".into(),
                resolution: WindowResolution::new(WIDTH, HEIGHT),
                ..default()
            }),
            ..default()
        }))
        .add_plugins((
            rapier_plugin().with_custom_initialization(init),
            TopplePlugin::default().with_settings(row.topple_settings(DT)),
        ))
        .insert_resource(TimestepMode::Fixed {
            dt: DT as f32,
            substeps: 1,
        })
        .insert_resource(ClearColor(Color::srgb(0.08, 0.08, 0.1)))
        .insert_resource(demo)
        .add_systems(Startup, setup)
        .add_systems(
            Update,
            (keys, spawn_rows, decorate, colour_blocks, hud, screenshot).chain(),
        )
        .run()
}

#[derive(Component)]
struct Hud;

fn setup(mut commands: Commands, mut demo: ResMut<Demo>) {
    commands.spawn((
        Camera2d,
        Projection::Orthographic(OrthographicProjection {
            scale: SCALE,
            ..OrthographicProjection::default_2d()
        }),
        Transform::from_xyz(0.0, 0.0, 10.0),
    ));
    let row = DominoRow::new(demo.spec());
    let mut sim = RapierContextSimulation::default();
    sim.integration_parameters = row.integration_parameters(DT);
    let ctx = commands.spawn((sim, row.rapier_configuration())).id();
    demo.native_context = Some(ctx);
    commands.spawn((
        Hud,
        Text2d::new(""),
        TextFont {
            font_size: FontSize::Px(18.0),
            ..default()
        },
        TextColor(GREY),
        Transform::from_xyz(0.0, 0.26 * HEIGHT as f32 * SCALE, 1.0).with_scale(Vec3::splat(SCALE)),
    ));
}

/// Spawns both rows when there are none (at start and after a restart).
fn spawn_rows(mut commands: Commands, mut demo: ResMut<Demo>) {
    if !demo.rows.is_empty() {
        return;
    }
    let origin = demo.origin();
    let native = DominoRow {
        origin: origin + Vec2::new(0.0, ROW_GAP),
        physics: ImpactResponse::Native,
        context: demo.native_context,
        ..DominoRow::new(demo.spec())
    };
    let topple = DominoRow {
        origin,
        ..DominoRow::new(demo.spec())
    };
    for row in [native, topple] {
        match row.spawn(&mut commands) {
            Ok(id) => demo.rows.push(id),
            Err(e) => error!("row refused: {e}"),
        }
    }
}

/// Sprites for the blocks and grounds of new rows.
fn decorate(mut commands: Commands, rows: Query<&DominoRowState, Added<DominoRowState>>) {
    for row in &rows {
        let b = row.spec.params.block;
        for &e in &row.blocks {
            commands.entity(e).insert(Sprite::from_color(
                GREY,
                Vec2::new(b.thickness as f32, b.height as f32),
            ));
        }
        let length = (row.spec.pitch() * row.spec.n as f64 + 2.0 * b.height) as f32;
        // a strip on the ground's top face (the collider is 2 m thick)
        commands
            .entity(row.ground)
            .insert(Visibility::Visible)
            .with_child((
                Sprite::from_color(GROUND, Vec2::new(length, 0.004)),
                Transform::from_xyz(0.0, 1.0 - 0.002, -1.0),
            ));
    }
}

/// Upright blocks grey, toppled ones in their row's colour.
fn colour_blocks(rows: Query<&DominoRowState>, mut blocks: Query<(&Transform, &mut Sprite)>) {
    for row in &rows {
        let toppled = match row.physics {
            ImpactResponse::Topple => ORANGE,
            ImpactResponse::Native => BLUE,
        };
        for &e in &row.blocks {
            if let Ok((t, mut sprite)) = blocks.get_mut(e) {
                let angle = t.rotation.to_euler(EulerRot::ZYX).0;
                sprite.color = if angle.abs() < UPRIGHT { GREY } else { toppled };
            }
        }
    }
}

fn hud(demo: Res<Demo>, rows: Query<&DominoRowState>, mut text: Query<&mut Text2d, With<Hud>>) {
    let Ok(mut text) = text.single_mut() else {
        return;
    };
    let mut lines = vec![format!(
        "Domino {:?}{}  s/h {:.2}  n {}  dt 1/60 s   cooperative model v_na = {}",
        demo.preset,
        if demo.ideal { " (ideal)" } else { " (Table 1)" },
        demo.spacing_ratio,
        demo.n,
        demo.cooperative().map_or("-".into(), |v| format!("{v:.3}"))
    )];
    for &id in &demo.rows {
        if let Ok(row) = rows.get(id) {
            let r = row.report();
            lines.push(format!(
                "{:>12}: blocks hit {:>3}/{}   v_na = {}",
                match row.physics {
                    ImpactResponse::Native => "native (top)",
                    ImpactResponse::Topple => "topple",
                },
                row.hit_times().len(),
                row.spec.n,
                r.natural_speed.map_or("-".into(), |v| format!("{v:.3}"))
            ));
        }
    }
    lines.push("R restart  Up/Down spacing  1/2/3 preset X/T/P  I ideal".into());
    text.0 = lines.join("\n");
}

/// Keys: restart, spacing, preset, material.
fn keys(
    mut commands: Commands,
    input: Res<ButtonInput<KeyCode>>,
    mut demo: ResMut<Demo>,
    rows: Query<&DominoRowState>,
    mut contexts: Query<&mut RapierContextSimulation>,
) {
    let before = (demo.preset, demo.ideal, demo.spacing_ratio);
    if input.just_pressed(KeyCode::ArrowUp) {
        demo.spacing_ratio = (demo.spacing_ratio + 0.05).min(0.6);
    }
    if input.just_pressed(KeyCode::ArrowDown) {
        demo.spacing_ratio = (demo.spacing_ratio - 0.05).max(0.1);
    }
    for (key, preset) in [
        (KeyCode::Digit1, Preset::X),
        (KeyCode::Digit2, Preset::T),
        (KeyCode::Digit3, Preset::P),
    ] {
        if input.just_pressed(key) {
            demo.preset = preset;
        }
    }
    if input.just_pressed(KeyCode::KeyI) {
        demo.ideal = !demo.ideal;
    }
    let changed = before != (demo.preset, demo.ideal, demo.spacing_ratio);
    if !(changed || input.just_pressed(KeyCode::KeyR)) {
        return;
    }
    for id in std::mem::take(&mut demo.rows) {
        if let Ok(row) = rows.get(id) {
            for &e in row.blocks.iter().chain([&row.ground]) {
                commands.entity(e).despawn();
            }
        }
        commands.entity(id).despawn();
    }
    let params = DominoRow::new(demo.spec()).integration_parameters(DT);
    for mut sim in &mut contexts {
        sim.integration_parameters = params;
    }
}

/// `--screenshot`: after N frames, the window to FILE and the rows' state to
/// FILE.json; exits when the image is written.
fn screenshot(
    mut commands: Commands,
    mut demo: ResMut<Demo>,
    rows: Query<&DominoRowState>,
    blocks: Query<&Transform>,
    mut exit: MessageWriter<AppExit>,
) {
    demo.frame += 1;
    let Some((file, frames)) = demo.screenshot.clone() else {
        return;
    };
    if demo.frame == frames {
        let state = rows_json(&demo, &rows, &blocks);
        let json = file.with_extension("png.json");
        if let Err(e) = std::fs::write(&json, state.to_string()) {
            error!("cannot write {}: {e}", json.display());
            exit.write(AppExit::from_code(1));
            return;
        }
    }
    common::screenshot_then_exit(&mut commands, &mut exit, file, demo.frame, frames);
}

/// The rows as the screenshot shows them: per row the upright and toppled
/// blocks, and the pixel row through the upright blocks at 85 % of their
/// height with the pixel columns the row spans.
fn rows_json(
    demo: &Demo,
    rows: &Query<&DominoRowState>,
    blocks: &Query<&Transform>,
) -> serde_json::Value {
    let to_px = |p: Vec2| {
        (
            p.x / SCALE + 0.5 * WIDTH as f32,
            0.5 * HEIGHT as f32 - p.y / SCALE,
        )
    };
    let mut out = Vec::new();
    for &id in &demo.rows {
        let Ok(row) = rows.get(id) else { continue };
        let angles: Vec<f32> = row
            .blocks
            .iter()
            .filter_map(|&e| blocks.get(e).ok())
            .map(|t| t.rotation.to_euler(EulerRot::ZYX).0)
            .collect();
        let upright = angles.iter().filter(|a| a.abs() < UPRIGHT).count();
        let origin = match row.physics {
            ImpactResponse::Native => demo.origin() + Vec2::new(0.0, ROW_GAP),
            ImpactResponse::Topple => demo.origin(),
        };
        let h = row.spec.params.block.height as f32;
        let (x0, y) = to_px(origin + Vec2::new(-h, 0.85 * h));
        let (x1, _) =
            to_px(origin + Vec2::new((row.spec.pitch() * row.spec.n as f64) as f32 + h, 0.0));
        let (_, top) = to_px(origin + Vec2::new(0.0, 1.2 * h));
        let (_, bottom) = to_px(origin + Vec2::new(0.0, -0.001));
        out.push(serde_json::json!({
            "row": match row.physics { ImpactResponse::Native => "native", ImpactResponse::Topple => "topple" },
            "n": row.spec.n,
            "upright": upright,
            "toppled": angles.len() - upright,
            "scan_y": y.round(),
            "x_min": x0.max(0.0).round(),
            "x_max": x1.min(WIDTH as f32 - 1.0).round(),
            "band_top": top.max(0.0).round(),
            "band_bottom": bottom.min(HEIGHT as f32 - 1.0).round(),
            "toppled_rgb": match row.physics {
                ImpactResponse::Native => [64, 140, 242],
                ImpactResponse::Topple => [242, 140, 38],
            },
        }));
    }
    serde_json::json!({ "width": WIDTH, "height": HEIGHT, "upright_rgb": [230, 230, 230], "rows": out })
}
