//! Newton's cradle in a window: native bevy_rapier above, topple below, five
//! steel balls on strings (revolute joints), the first raised 30°, both at
//! 1/60 s. The HUD shows each cradle's energy against its start: native
//! Rapier's restitution loses it within a few swings, topple's LZB impacts
//! (e = 1) keep it.
//!
//! ```text
//! cargo run --release --features bevy --example cradle
//! cargo run --release --features bevy --example cradle -- --screenshot cradle.png --frames 240
//! ```

mod common;

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::window::WindowResolution;
use bevy_rapier2d::prelude::*;
use topple::bevy::{rapier_plugin, ToppleMaterial, TopplePlugin};
use topple::coupling::PairMaterial;
use topple::impact::ContactMaterial;

const DT: f32 = 1.0 / 60.0;
const RADIUS: f32 = 0.02;
const STRING: f32 = 0.2;
const MASS: f32 = 0.26;
const BALLS: usize = 5;
/// The first ball starts raised by 30°.
const LIFT: f32 = std::f32::consts::FRAC_PI_6;
const G: f32 = 9.81;
/// Rest height of the balls of the native and the topple cradle (m).
const REST_Y: [f32; 2] = [0.02, -0.26];

#[derive(Component)]
struct Ball {
    topple: bool,
}

#[derive(Component)]
struct Hud;

/// A string from a pivot (m) to a ball, drawn as a thin rectangle.
#[derive(Component)]
struct StringTo {
    pivot: Vec2,
    ball: Entity,
}

/// A white disc on a transparent square, tinted by each ball's sprite.
fn disc_image() -> Image {
    use bevy::asset::RenderAssetUsages;
    use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
    const SIZE: u32 = 64;
    let mut data = Vec::with_capacity((SIZE * SIZE * 4) as usize);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (dx, dy) = (x as f32 + 0.5 - 32.0, y as f32 + 0.5 - 32.0);
            // coverage of the pixel by the disc of radius 31.5, one pixel of ramp
            let alpha = (31.5 - (dx * dx + dy * dy).sqrt() + 0.5).clamp(0.0, 1.0);
            data.extend_from_slice(&[255, 255, 255, (alpha * 255.0) as u8]);
        }
    }
    Image::new(
        Extent3d {
            width: SIZE,
            height: SIZE,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        data,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD,
    )
}

#[derive(Resource)]
struct Run {
    frame: u32,
    screenshot: Option<(PathBuf, u32)>,
    start_energy: [f32; 2],
}

fn main() -> AppExit {
    let mut screenshot = None;
    let mut args = std::env::args().skip(1);
    let (mut file, mut frames) = (None, 240u32);
    while let Some(flag) = args.next() {
        match (flag.as_str(), args.next()) {
            ("--screenshot", Some(v)) => file = Some(PathBuf::from(v)),
            ("--frames", Some(v)) => match v.parse() {
                Ok(n) => frames = n,
                Err(e) => {
                    eprintln!("error: --frames: {e}");
                    return AppExit::from_code(2);
                }
            },
            _ => {
                eprintln!("error: unknown flag {flag}: --screenshot FILE --frames N");
                return AppExit::from_code(2);
            }
        }
    }
    if let Some(f) = file {
        screenshot = Some((f, frames.max(1)));
    }
    App::new()
        .add_plugins(DefaultPlugins.set(WindowPlugin {
            primary_window: Some(Window {
                title: "topple: Newton's cradle, native Rapier (top) and topple (bottom)".into(),
                resolution: WindowResolution::new(1280, 720),
                ..default()
            }),
            ..default()
        }))
        .add_plugins((rapier_plugin(), TopplePlugin::default()))
        .insert_resource(TimestepMode::Fixed {
            dt: DT,
            substeps: 1,
        })
        .insert_resource(ClearColor(Color::srgb(0.08, 0.08, 0.1)))
        .insert_resource(Run {
            frame: 0,
            screenshot,
            start_energy: [0.0; 2],
        })
        .add_systems(Startup, setup)
        .add_systems(Update, (strings, hud, finish).chain())
        .run()
}

fn setup(mut commands: Commands, mut images: ResMut<Assets<Image>>) {
    let disc = images.add(disc_image());
    commands.spawn((
        Camera2d,
        Projection::Orthographic(OrthographicProjection {
            scale: 0.0008,
            ..OrthographicProjection::default_2d()
        }),
    ));
    let native = commands
        .spawn((
            RapierContextSimulation::default(),
            RapierConfiguration {
                gravity: Vec2::new(0.0, -G),
                ..RapierConfiguration::new(1.0)
            },
        ))
        .id();
    let steel = ToppleMaterial(PairMaterial {
        impact: ContactMaterial::hertz(1.0e10).with_restitution(1.0),
        smooth_friction: 0.0,
    });
    for (topple, y) in [(false, REST_Y[0]), (true, REST_Y[1])] {
        for i in 0..BALLS {
            let pivot = Vec2::new((i as f32 - 2.0) * 2.0 * RADIUS, y + STRING);
            let angle = if i == 0 { -LIFT } else { 0.0 };
            let centre = pivot + STRING * Vec2::new(angle.sin(), -angle.cos());
            let mut anchor = commands.spawn((
                RigidBody::Fixed,
                Transform::from_translation(pivot.extend(0.0)),
            ));
            if !topple {
                anchor.insert(RapierContextEntityLink(native));
            }
            let anchor = anchor.id();
            let joint = RevoluteJointBuilder::new()
                .local_anchor1(Vec2::ZERO)
                .local_anchor2(Vec2::new(0.0, STRING));
            let mut ball = commands.spawn((
                Ball { topple },
                RigidBody::Dynamic,
                Collider::ball(RADIUS),
                ColliderMassProperties::Mass(MASS),
                Transform::from_translation(centre.extend(0.0))
                    .with_rotation(Quat::from_rotation_z(angle)),
                Velocity::zero(),
                ImpulseJoint::new(anchor, joint),
                Sprite {
                    image: disc.clone(),
                    color: if topple {
                        Color::srgb(0.95, 0.55, 0.15)
                    } else {
                        Color::srgb(0.25, 0.55, 0.95)
                    },
                    custom_size: Some(Vec2::splat(2.0 * RADIUS)),
                    ..default()
                },
            ));
            let ball_id = ball.id();
            if topple {
                ball.insert(steel);
            } else {
                ball.insert((
                    RapierContextEntityLink(native),
                    Restitution::coefficient(1.0),
                    Friction::coefficient(0.0),
                ));
            }
            commands.spawn((
                StringTo {
                    pivot,
                    ball: ball_id,
                },
                Sprite::from_color(Color::srgb(0.6, 0.6, 0.6), Vec2::new(0.001, STRING)),
                Transform::from_translation(pivot.extend(-1.0)),
            ));
        }
    }
    commands.spawn((
        Hud,
        Text2d::new(""),
        TextFont {
            font_size: FontSize::Px(18.0),
            ..default()
        },
        Transform::from_xyz(0.0, 0.255, 1.0).with_scale(Vec3::splat(0.0008)),
    ));
}

/// Each string from its pivot to its ball's centre.
fn strings(
    mut strings: Query<(&StringTo, &mut Transform), Without<Ball>>,
    balls: Query<&Transform, With<Ball>>,
) {
    for (s, mut t) in &mut strings {
        if let Ok(ball) = balls.get(s.ball) {
            let d = ball.translation.truncate() - s.pivot;
            t.translation = (s.pivot + 0.5 * d).extend(-1.0);
            t.rotation = Quat::from_rotation_z(d.to_angle() + std::f32::consts::FRAC_PI_2);
        }
    }
}

/// Kinetic plus potential energy of each cradle (J; balls as discs).
fn energies(balls: &Query<(&Ball, &Transform, &Velocity)>) -> [f32; 2] {
    let mut e = [0.0; 2];
    for (ball, t, v) in balls {
        let inertia = 0.5 * MASS * RADIUS * RADIUS;
        e[ball.topple as usize] += 0.5 * MASS * v.linear.length_squared()
            + 0.5 * inertia * v.angular * v.angular
            + MASS * G * t.translation.y;
    }
    e
}

fn hud(
    mut run: ResMut<Run>,
    balls: Query<(&Ball, &Transform, &Velocity)>,
    mut text: Query<&mut Text2d, With<Hud>>,
) {
    run.frame += 1;
    let e = energies(&balls);
    if run.frame == 2 {
        run.start_energy = e;
    }
    let Ok(mut text) = text.single_mut() else {
        return;
    };
    // energy above the balls' rest height, relative to the start
    let rest = REST_Y.map(|y| BALLS as f32 * MASS * G * y);
    let lift = MASS * G * STRING * (1.0 - LIFT.cos());
    let share = |k: usize| 100.0 * (e[k] - rest[k]) / lift;
    text.0 = format!(
        "Newton's cradle, dt 1/60 s, e = 1   t = {:.1} s\nnative Rapier (top): energy {:.1} % of the start\ntopple (bottom): energy {:.1} % of the start",
        run.frame as f32 * DT,
        share(0),
        share(1)
    );
}

fn finish(mut commands: Commands, run: Res<Run>, mut exit: MessageWriter<AppExit>) {
    let Some((file, frames)) = run.screenshot.clone() else {
        return;
    };
    common::screenshot_then_exit(&mut commands, &mut exit, file, run.frame, frames);
}
