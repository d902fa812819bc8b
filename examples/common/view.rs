//! Drawing the shared scenes ([`super::scenes::Piece`]) and the HUD of the
//! windowed scene examples: a pixel camera, sprites and meshes per shape,
//! a native context beside topple's, frame rate and topple's frame time.

#![allow(dead_code)] // each example takes what it needs

use bevy::prelude::*;
use bevy_rapier2d::prelude::*;
use topple::bevy::ToppleFrameStats;

use super::scenes::{Piece, PieceShape, Role, Target, PPM};
use topple::bevy::ImpactResponse;

pub const WIDTH: u32 = 1280;
pub const HEIGHT: u32 = 720;

/// Upright dominoes, toppled ones (per physics), boxes, balls, grounds.
pub const UPRIGHT: Color = Color::srgb(0.9, 0.9, 0.9);
pub const TOPPLED_TOPPLE: Color = Color::srgb(0.95, 0.55, 0.15);
pub const TOPPLED_NATIVE: Color = Color::srgb(0.25, 0.55, 0.95);
pub const GROUND: Color = Color::srgb(0.35, 0.35, 0.38);
pub const BALL: Color = Color::srgb(0.85, 0.3, 0.3);
pub const HUD_TEXT: Color = Color::srgb(0.95, 0.95, 0.95);
/// A domino is drawn upright within this angle (rad).
pub const UPRIGHT_ANGLE: f32 = 0.1;

/// The window of the scene examples.
pub fn window(title: &str) -> WindowPlugin {
    WindowPlugin {
        primary_window: Some(Window {
            title: title.into(),
            resolution: bevy::window::WindowResolution::new(WIDTH, HEIGHT),
            ..default()
        }),
        ..default()
    }
}

/// The two contexts the examples switch between: bevy_rapier's default one
/// (stepped by topple) and a second one stepped natively.
#[derive(Resource, Clone, Copy)]
pub struct Contexts {
    pub native: Entity,
}

impl Contexts {
    /// Where a scene of the given physics goes.
    pub fn target(&self, physics: ImpactResponse) -> Target {
        Target {
            physics,
            context: match physics {
                ImpactResponse::Topple => None,
                ImpactResponse::Native => Some(self.native),
            },
        }
    }
}

/// A camera in pixels and a native context in pixel units.
pub fn setup_view(mut commands: Commands) {
    commands.insert_resource(Meter::default());
    commands.spawn(Camera2d);
    let mut sim = RapierContextSimulation::default();
    sim.integration_parameters.length_unit = PPM;
    let native = commands.spawn((sim, RapierConfiguration::new(PPM))).id();
    commands.insert_resource(Contexts { native });
}

/// The examples' textures (`assets/textures`, made by its `make.py`),
/// built into the binary so that it runs from any directory.
#[derive(Resource)]
pub struct Textures {
    pub crate_face: Handle<Image>,
    pub domino: Handle<Image>,
    pub domino_flat: Handle<Image>,
}

fn texture(bytes: &[u8]) -> Image {
    use bevy::asset::RenderAssetUsages;
    use bevy::image::{CompressedImageFormats, ImageSampler, ImageType};
    Image::from_buffer(
        bytes,
        ImageType::Extension("png"),
        CompressedImageFormats::NONE,
        true,
        ImageSampler::linear(),
        RenderAssetUsages::RENDER_WORLD,
    )
    .expect("the examples' textures are PNGs")
}

pub fn load_textures(mut commands: Commands, mut images: ResMut<Assets<Image>>) {
    commands.insert_resource(Textures {
        crate_face: images.add(texture(include_bytes!("../../assets/textures/crate.png"))),
        domino: images.add(texture(include_bytes!("../../assets/textures/domino.png"))),
        domino_flat: images.add(texture(include_bytes!(
            "../../assets/textures/domino_flat.png"
        ))),
    });
}

/// Meshes and materials for the shapes, made once per piece.
pub fn decorate(
    mut commands: Commands,
    pieces: Query<(Entity, &Piece), Added<Piece>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<ColorMaterial>>,
    textures: Res<Textures>,
) {
    for (e, piece) in &pieces {
        let colour = match piece.role {
            Role::Ground => GROUND,
            Role::Domino => UPRIGHT,
            Role::Block => Color::WHITE,
            Role::Ball => BALL,
        };
        let mut entity = commands.entity(e);
        match &piece.shape {
            PieceShape::Rect(size) => {
                let sprite = if piece.role == Role::Block {
                    Sprite {
                        image: textures.crate_face.clone(),
                        custom_size: Some(*size),
                        ..default()
                    }
                } else if piece.role == Role::Domino && size.min_element() > 11.0 {
                    // large dominoes show their face, standing or lying flat
                    let image = if size.y >= size.x {
                        textures.domino.clone()
                    } else {
                        textures.domino_flat.clone()
                    };
                    Sprite {
                        image,
                        custom_size: Some(*size),
                        color: colour,
                        ..default()
                    }
                } else {
                    Sprite::from_color(colour, *size)
                };
                entity.insert(sprite);
            }
            PieceShape::Disc(r) => {
                entity.insert((
                    Mesh2d(meshes.add(Circle::new(*r))),
                    MeshMaterial2d(materials.add(colour)),
                ));
            }
            PieceShape::Capsule(half, r) => {
                entity.insert(Visibility::Visible).with_child((
                    Mesh2d(meshes.add(Capsule2d::new(*r, 2.0 * half))),
                    MeshMaterial2d(materials.add(Color::srgb(0.55, 0.75, 0.4))),
                    Transform::from_rotation(Quat::from_rotation_z(std::f32::consts::FRAC_PI_2)),
                ));
            }
            PieceShape::Polygon(points) => {
                let r = points.first().map_or(10.0, |p| p.length());
                entity.insert(Visibility::Visible).with_child((
                    Mesh2d(meshes.add(RegularPolygon::new(r, points.len() as u32))),
                    MeshMaterial2d(materials.add(Color::srgb(0.6, 0.5, 0.85))),
                    // bevy's polygon has a corner on +y, the collider on +x
                    Transform::from_rotation(Quat::from_rotation_z(-std::f32::consts::FRAC_PI_2)),
                ));
            }
            PieceShape::Line(points) => {
                entity.insert(Visibility::Visible);
                for pair in points.windows(2) {
                    let (a, b) = (pair[0], pair[1]);
                    let d = b - a;
                    entity.with_child((
                        Sprite::from_color(GROUND, Vec2::new(d.length() + 4.0, 4.0)),
                        Transform::from_translation((0.5 * (a + b)).extend(-1.0))
                            .with_rotation(Quat::from_rotation_z(d.to_angle())),
                    ));
                }
            }
        }
    }
}

/// Dominoes upright grey, toppled in the colour of their physics.
pub fn colour_dominoes(
    physics: ImpactResponse,
    mut dominoes: Query<(&Transform, &Piece, &mut Sprite)>,
) {
    let toppled = match physics {
        ImpactResponse::Topple => TOPPLED_TOPPLE,
        ImpactResponse::Native => TOPPLED_NATIVE,
    };
    for (t, piece, mut sprite) in &mut dominoes {
        if piece.role == Role::Domino {
            let angle = t.rotation.to_euler(EulerRot::ZYX).0;
            sprite.color = if angle.abs() < UPRIGHT_ANGLE {
                UPRIGHT
            } else {
                toppled
            };
        }
    }
}

/// The HUD: frames per second (smoothed over about half a second of real
/// time) and what the physics step cost, from [`ToppleFrameStats`].
#[derive(Resource, Default)]
pub struct Meter {
    fps: f32,
    step_ms: f32,
    topple_ms: f32,
    impacts_per_s: f32,
    pub frame: u32,
}

impl Meter {
    pub fn update(&mut self, real_dt: f32, stats: &ToppleFrameStats) {
        let a = (real_dt / 0.5).clamp(0.0, 1.0);
        let mix = |old: f32, new: f32| {
            if self.frame == 0 {
                new
            } else {
                old + a * (new - old)
            }
        };
        if real_dt > 0.0 {
            self.fps = mix(self.fps, 1.0 / real_dt);
        }
        self.step_ms = mix(self.step_ms, 1e3 * stats.step_seconds as f32);
        self.topple_ms = mix(self.topple_ms, 1e3 * stats.topple_seconds as f32);
        self.impacts_per_s = mix(self.impacts_per_s, stats.impacts as f32 * 60.0);
        self.frame += 1;
    }

    /// One HUD line.
    pub fn line(&self, stats: &ToppleFrameStats) -> String {
        format!(
            "{:5.1} fps   physics step {:5.2} ms (topple's own {:5.2} ms)   impacts {:4.0}/s   fallbacks {}   left to Rapier {}",
            self.fps,
            self.step_ms,
            self.topple_ms,
            self.impacts_per_s,
            stats.totals.held_impacts + stats.totals.plastic_fallbacks,
            stats.totals.native_impacts,
        )
    }
}

#[derive(Component)]
pub struct Hud;

/// The HUD text at the window's top left (world pixels, camera at 0).
pub fn spawn_hud(commands: &mut Commands) {
    commands.spawn((
        Hud,
        Text2d::new(""),
        TextFont {
            font_size: FontSize::Px(16.0),
            ..default()
        },
        TextColor(HUD_TEXT),
        bevy::sprite::Anchor::TOP_LEFT,
        Transform::from_xyz(-0.5 * WIDTH as f32 + 12.0, 0.5 * HEIGHT as f32 - 10.0, 5.0),
    ));
}
