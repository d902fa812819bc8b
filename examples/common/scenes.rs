//! Scenes a Bevy game builds, shared by the examples (`domino_show`, `pile`)
//! and the frame benchmark (`benches/bevy_frames.rs`): bevy_rapier's pixel
//! units (100 pixels per metre, gravity 981 px/s²), a material on every
//! collider, either topple's ([`ToppleMaterial`]) or native bevy_rapier's
//! (`Friction` and `Restitution`, the same coefficients).
//!
//! Every scene function spawns physics only; each spawned body carries a
//! [`Piece`] telling an example how to draw it.

#![allow(dead_code)] // each user takes the scenes it needs

use std::time::Duration;

use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bevy_rapier2d::prelude::*;
use topple::bevy::{rapier_plugin, ImpactResponse, ToppleConfig, ToppleMaterial, TopplePlugin};
use topple::coupling::PairMaterial;
use topple::impact::ContactMaterial;

/// Pixels per metre of the scenes (bevy_rapier's usual pixel units).
pub const PPM: f32 = 100.0;
/// Gravity (px/s²).
pub const G: f32 = 9.81 * PPM;
/// The physics step (s).
pub const DT: f32 = 1.0 / 60.0;

/// The HUD's name of who resolves a scene's impacts: topple's LZB impacts,
/// or bevy_rapier alone.
pub fn label(physics: ImpactResponse) -> &'static str {
    match physics {
        ImpactResponse::Topple => "topple",
        ImpactResponse::Native => "native",
    }
}

/// The other one (what the switching key selects).
pub fn other(physics: ImpactResponse) -> ImpactResponse {
    match physics {
        ImpactResponse::Topple => ImpactResponse::Native,
        ImpactResponse::Native => ImpactResponse::Topple,
    }
}

/// Where a scene goes: its physics and Rapier context (`None`: the default
/// context).
#[derive(Clone, Copy, Debug, Default)]
pub struct Target {
    pub physics: ImpactResponse,
    pub context: Option<Entity>,
}

/// How an example draws a body: its shape and role.
#[derive(Component, Clone, Debug)]
pub struct Piece {
    pub shape: PieceShape,
    pub role: Role,
}

#[derive(Clone, Debug)]
pub enum PieceShape {
    Rect(Vec2),
    Disc(f32),
    /// A capsule along x: half length of the segment, radius.
    Capsule(f32, f32),
    /// A convex polygon's vertices (px, body frame).
    Polygon(Vec<Vec2>),
    /// A polyline's vertices (px, body frame), drawn as thin rectangles.
    Line(Vec<Vec2>),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Ground,
    Block,
    Domino,
    Ball,
}

/// A material: restitution e, friction μ (μ_s = 1.2 μ), impact stiffness k.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mat {
    pub restitution: f64,
    pub friction: f64,
    pub stiffness: f64,
}

impl Mat {
    /// Wooden blocks and balls: e = 0.3, μ = 0.5.
    pub const WOOD: Mat = Mat {
        restitution: 0.3,
        friction: 0.5,
        stiffness: 1e8,
    };
    /// The ground: e = 0.3, μ = 0.6, stiffer.
    pub const GROUND: Mat = Mat {
        restitution: 0.3,
        friction: 0.6,
        stiffness: 5e8,
    };
    /// Show dominoes (Tufnol of Table 1: e = 0.62, μ = 0.15).
    pub const DOMINO: Mat = Mat {
        restitution: 0.62,
        friction: 0.15,
        stiffness: 2.3e8,
    };

    /// The dominoes' tables and steps (Table 1's block–ground e = 0.5, with
    /// a grippier μ = 0.5 than Table 1's 0.2: on 0.2 the large dominoes of
    /// the growing row slide instead of toppling).
    pub const TABLE: Mat = Mat {
        restitution: 0.5,
        friction: 0.5,
        stiffness: 6.9e8,
    };

    pub fn topple(self) -> PairMaterial {
        PairMaterial::from_table(
            ContactMaterial::hertz(self.stiffness),
            self.friction,
            1.2 * self.friction,
            self.restitution,
            1.0,
        )
    }
}

/// The material component of a collider: topple's, or bevy_rapier's own
/// coefficients (averaged between two colliders, Rapier's default rule).
pub fn material(e: &mut EntityCommands, target: Target, m: Mat) {
    match target.physics {
        ImpactResponse::Topple => {
            e.insert(ToppleMaterial(m.topple()));
        }
        ImpactResponse::Native => {
            e.insert((
                Friction::coefficient(m.friction as f32),
                Restitution::coefficient(m.restitution as f32),
            ));
        }
    }
    if let Some(ctx) = target.context {
        e.insert(RapierContextEntityLink(ctx));
    }
}

/// A headless app in pixel units stepping one context at 1/60 s per
/// `update()`, deterministic, with the default context stepped by topple or
/// by bevy_rapier, and topple's default settings.
pub fn headless_app(physics: ImpactResponse) -> App {
    let who = physics;
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin))
        .add_plugins((
            rapier_plugin().with_length_unit(PPM),
            TopplePlugin::default().with_default_context(who),
        ))
        .insert_resource(TimestepMode::Fixed {
            dt: DT,
            substeps: 1,
        })
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f32(
            DT,
        )));
    app.finish();
    app.cleanup();
    app.update(); // the context exists after the first update
    app
}

/// Spawns with the app's commands and applies them.
pub fn spawn_in(app: &mut App, f: impl FnOnce(&mut Commands)) {
    let world = app.world_mut();
    let mut commands = world.commands();
    f(&mut commands);
    world.flush();
}

/// A fixed ground: its top face at `y` (px), from `x0` to `x1`.
pub fn ground(commands: &mut Commands, target: Target, x0: f32, x1: f32, y: f32, m: Mat) -> Entity {
    let half = Vec2::new(0.5 * (x1 - x0), 10.0);
    let mut e = commands.spawn((
        RigidBody::Fixed,
        Collider::cuboid(half.x, half.y),
        Transform::from_xyz(0.5 * (x0 + x1), y - half.y, 0.0),
        Piece {
            shape: PieceShape::Rect(2.0 * half),
            role: Role::Ground,
        },
    ));
    material(&mut e, target, m);
    e.id()
}

/// A dynamic box (px) at rest, optionally asleep.
pub fn block(
    commands: &mut Commands,
    target: Target,
    size: Vec2,
    at: Vec2,
    angle: f32,
    role: Role,
    m: Mat,
) -> Entity {
    let mut e = commands.spawn((
        RigidBody::Dynamic,
        Collider::cuboid(0.5 * size.x, 0.5 * size.y),
        Transform::from_translation(at.extend(0.0)).with_rotation(Quat::from_rotation_z(angle)),
        Velocity::zero(),
        Piece {
            shape: PieceShape::Rect(size),
            role,
        },
    ));
    material(&mut e, target, m);
    e.id()
}

/// A domino of height `h` and thickness `d` (px) standing with its bottom
/// centre at `foot`; with `push = Some(k)` it turns about its front bottom
/// edge at θ̇ = k √(g/h) (the paper's push of k), clockwise, towards +x.
pub fn standing_domino(
    commands: &mut Commands,
    target: Target,
    h: f32,
    d: f32,
    foot: Vec2,
    push: Option<f32>,
) -> Entity {
    let e = block(
        commands,
        target,
        Vec2::new(d, h),
        foot + Vec2::new(0.0, 0.5 * h),
        0.0,
        Role::Domino,
        Mat::DOMINO,
    );
    if let Some(k) = push {
        // clockwise about the front bottom edge: v = ω × (centre − pivot)
        let w = -k * (G / h).sqrt();
        let r = Vec2::new(-0.5 * d, 0.5 * h);
        commands.entity(e).insert(Velocity {
            linear: Vec2::new(-w * r.y, w * r.x),
            angular: w,
        });
    }
    e
}

/// A box pyramid standing at rest on the ground: `levels` rows of boxes of
/// `size` px, the bottom row centred at x = 0 on a ground at y = 0.
pub fn pyramid(commands: &mut Commands, target: Target, levels: usize, size: f32) -> Vec<Entity> {
    let w = levels as f32 * size;
    ground(commands, target, -w, w, 0.0, Mat::GROUND);
    let mut boxes = Vec::new();
    for row in 0..levels {
        let n = levels - row;
        for i in 0..n {
            let x = (i as f32 - 0.5 * (n - 1) as f32) * size;
            let y = (row as f32 + 0.5) * size;
            boxes.push(block(
                commands,
                target,
                Vec2::splat(size),
                Vec2::new(x, y),
                0.0,
                Role::Block,
                Mat::WOOD,
            ));
        }
    }
    boxes
}

/// A small deterministic generator (no dependency).
#[derive(Clone, Debug)]
pub struct Lcg(pub u64);

impl Lcg {
    /// A number in [0, 1).
    pub fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }

    pub fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.next()
    }
}

/// A pile of boxes dropped in layers onto a ground: `layers` layers of
/// `per_layer` boxes (18–30 px), each layer 50 px above the one below,
/// slightly turned and shifted, falling from rest.
pub fn pile_in_layers(
    commands: &mut Commands,
    target: Target,
    layers: usize,
    per_layer: usize,
) -> Vec<Entity> {
    let mut rng = Lcg(7);
    let width = per_layer as f32 * 48.0;
    ground(
        commands,
        target,
        -2.0 * width,
        2.0 * width,
        0.0,
        Mat::GROUND,
    );
    let mut out = Vec::new();
    for layer in 0..layers {
        for i in 0..per_layer {
            // at most 30 px, turned at most 0.2 rad: 38 px across, in 48 px
            let size = Vec2::new(rng.range(18.0, 30.0), rng.range(18.0, 30.0));
            let x = (i as f32 - 0.5 * (per_layer - 1) as f32) * 48.0 + rng.range(-4.0, 4.0);
            let y = 40.0 + 50.0 * layer as f32 + rng.range(0.0, 6.0);
            out.push(block(
                commands,
                target,
                size,
                Vec2::new(x, y),
                rng.range(-0.2, 0.2),
                Role::Block,
                Mat::WOOD,
            ));
        }
    }
    out
}

/// One body of a mixed bin or pour: a ball, box, capsule or convex polygon
/// (about 14–30 px) at `at`, with velocity `v`.
pub fn mixed_body(
    commands: &mut Commands,
    target: Target,
    kind: usize,
    rng: &mut Lcg,
    at: Vec2,
    v: Vec2,
) -> Entity {
    let (collider, shape, role) = match kind % 4 {
        0 => {
            let r = rng.range(8.0, 15.0);
            (Collider::ball(r), PieceShape::Disc(r), Role::Ball)
        }
        1 => {
            let s = Vec2::new(rng.range(16.0, 30.0), rng.range(16.0, 30.0));
            (
                Collider::cuboid(0.5 * s.x, 0.5 * s.y),
                PieceShape::Rect(s),
                Role::Block,
            )
        }
        2 => {
            let (h, r) = (rng.range(6.0, 12.0), rng.range(5.0, 9.0));
            (
                Collider::capsule_x(h, r),
                PieceShape::Capsule(h, r),
                Role::Block,
            )
        }
        _ => {
            let n = 5 + (rng.next() * 3.0) as usize;
            let r = rng.range(10.0, 16.0);
            let pts: Vec<Vec2> = (0..n)
                .map(|k| Vec2::from_angle(k as f32 / n as f32 * std::f32::consts::TAU) * r)
                .collect();
            (
                Collider::convex_hull(&pts).expect("a regular polygon is convex"),
                PieceShape::Polygon(pts),
                Role::Block,
            )
        }
    };
    let mut e = commands.spawn((
        RigidBody::Dynamic,
        collider,
        Transform::from_translation(at.extend(0.0))
            .with_rotation(Quat::from_rotation_z(rng.range(0.0, 3.0))),
        Velocity::linear(v),
        Piece { shape, role },
    ));
    material(&mut e, target, Mat::WOOD);
    e.id()
}

/// A bin: a floor and two walls (a polyline, fixed), `n` balls, boxes,
/// capsules and convex polygons dropped into it from rest.
pub fn bin(commands: &mut Commands, target: Target, n: usize) -> Vec<Entity> {
    let (w, h) = (260.0, 300.0);
    let outline = vec![
        Vec2::new(-w, h),
        Vec2::new(-w, 0.0),
        Vec2::new(w, 0.0),
        Vec2::new(w, h),
    ];
    let mut e = commands.spawn((
        RigidBody::Fixed,
        Collider::polyline(outline.clone(), None),
        Transform::default(),
        Piece {
            shape: PieceShape::Line(outline),
            role: Role::Ground,
        },
    ));
    material(&mut e, target, Mat::GROUND);
    let mut rng = Lcg(11);
    let per_row = 12;
    (0..n)
        .map(|k| {
            let (row, col) = (k / per_row, k % per_row);
            let at = Vec2::new(
                (col as f32 - 0.5 * (per_row - 1) as f32) * 38.0 + rng.range(-3.0, 3.0),
                60.0 + 42.0 * row as f32,
            );
            mixed_body(commands, target, k, &mut rng, at, Vec2::ZERO)
        })
        .collect()
}

/// topple's pair rule between two scene materials (both directions).
pub fn pair_rule(commands: &mut Commands, a: Mat, b: Mat, rule: Mat) {
    commands.queue(move |world: &mut World| {
        let mut config = world.get_resource_or_insert_with(ToppleConfig::default);
        config.set_pair(a.topple(), b.topple(), rule.topple());
    });
}

/// The pour of the `pile` example: a ramp (a fixed box turned 20°) above a
/// floor between two walls (a polyline).
pub fn pour_ground(commands: &mut Commands, target: Target) {
    let outline = vec![
        Vec2::new(-600.0, 330.0),
        Vec2::new(-600.0, -300.0),
        Vec2::new(600.0, -300.0),
        Vec2::new(600.0, 100.0),
    ];
    let mut floor = commands.spawn((
        RigidBody::Fixed,
        Collider::polyline(outline.clone(), None),
        Transform::default(),
        Piece {
            shape: PieceShape::Line(outline),
            role: Role::Ground,
        },
    ));
    material(&mut floor, target, Mat::GROUND);
    let size = Vec2::new(520.0, 16.0);
    let mut ramp = commands.spawn((
        RigidBody::Fixed,
        Collider::cuboid(0.5 * size.x, 0.5 * size.y),
        Transform::from_xyz(-280.0, 60.0, 0.0).with_rotation(Quat::from_rotation_z(-0.35)),
        Piece {
            shape: PieceShape::Rect(size),
            role: Role::Ground,
        },
    ));
    material(&mut ramp, target, Mat::GROUND);
}

/// The `k`-th body of the pour: balls and boxes in turn, dropped above the
/// ramp's upper end with a small spread.
pub fn pour_body(commands: &mut Commands, target: Target, k: usize, rng: &mut Lcg) -> Entity {
    let at = Vec2::new(rng.range(-470.0, -400.0), 330.0);
    let v = Vec2::new(rng.range(0.0, 60.0), rng.range(-60.0, 0.0));
    mixed_body(commands, target, k % 2, rng, at, v)
}
