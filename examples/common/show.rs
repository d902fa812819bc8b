//! The domino show (example `domino_show`, frame benchmark): in pixel units
//! (100 px per metre), all pushed at once,
//!
//! - `fronts` parallel rows on shelves (one wave front each), on the left;
//! - dominoes that grow by 1.5× along a row (each topples the next, larger
//!   one), the last and largest falling onto a tower of dominoes stacked
//!   flat, which it knocks into a pile, at the top right;
//! - a row down a flight of steps (a polyline), at the bottom right.
//!
//! Dominoes are Table 1's Tufnol (e = 0.62, μ = 0.15 between dominoes;
//! e = 0.5, μ = 0.5 on the tables and steps).

#![allow(dead_code)]

use bevy::prelude::*;
use bevy_rapier2d::prelude::*;

use super::scenes::{self, Mat, Piece, PieceShape, Role, Target};

/// Height and thickness of a front's dominoes (px) and their spacing over
/// height.
pub const FRONT_H: f32 = 32.0;
pub const FRONT_D: f32 = 7.0;
pub const FRONT_S: f32 = 0.5;
/// Vertical distance between the fronts' shelves (px).
pub const SHELF_GAP: f32 = 48.0;
/// Top of the floor under the whole show (px).
pub const FLOOR_Y: f32 = -560.0;

/// A straight row of the show: its dominoes in order and where its shelf is.
#[derive(Clone, Debug)]
pub struct ShowRow {
    pub dominoes: Vec<Entity>,
    /// Top face of the shelf (px).
    pub shelf_y: f32,
    /// x of the first domino's back face and the last one's front face (px).
    pub x0: f32,
    pub x1: f32,
    /// Domino height (px).
    pub height: f32,
}

/// What the show spawned.
#[derive(Resource, Clone, Debug, Default)]
pub struct ShowLayout {
    /// The parallel fronts.
    pub rows: Vec<ShowRow>,
    /// The growing dominoes, smallest first.
    pub growing: Vec<Entity>,
    /// The tower of dominoes stacked flat.
    pub tower: Vec<Entity>,
    /// The dominoes on the steps.
    pub steps: Vec<Entity>,
    /// Every body of the show.
    pub all: Vec<Entity>,
}

/// A domino standing with its bottom centre at `foot` (px); the first of a
/// row is pushed to turn about its front bottom edge at θ̇ = √(g/h) (the
/// paper's push of 1), the others stand asleep until struck.
fn domino(
    commands: &mut Commands,
    target: Target,
    h: f32,
    d: f32,
    foot: Vec2,
    pushed: bool,
) -> Entity {
    let e = scenes::standing_domino(commands, target, h, d, foot, pushed.then_some(1.0));
    if !pushed {
        commands.entity(e).insert(Sleeping {
            sleeping: true,
            ..Sleeping::default()
        });
    }
    e
}

/// A fixed shelf with its top face at `y`, from `x0` to `x1` (px).
fn shelf(commands: &mut Commands, target: Target, x0: f32, x1: f32, y: f32) -> Entity {
    let half = Vec2::new(0.5 * (x1 - x0), 4.0);
    let mut e = commands.spawn((
        RigidBody::Fixed,
        Collider::cuboid(half.x, half.y),
        Transform::from_xyz(0.5 * (x0 + x1), y - half.y, 0.0),
        Piece {
            shape: PieceShape::Rect(2.0 * half),
            role: Role::Ground,
        },
    ));
    scenes::material(&mut e, target, Mat::TABLE);
    e.id()
}

/// A straight row of `n` dominoes on a shelf from `x0`, pushed.
fn front(commands: &mut Commands, target: Target, x0: f32, shelf_y: f32, n: usize) -> ShowRow {
    let pitch = FRONT_S * FRONT_H + FRONT_D;
    let x1 = x0 + pitch * (n - 1) as f32 + FRONT_D;
    shelf(commands, target, x0 - 10.0, x1 + 2.0 * FRONT_H, shelf_y);
    let dominoes = (0..n)
        .map(|i| {
            let x = x0 + 0.5 * FRONT_D + pitch * i as f32;
            domino(
                commands,
                target,
                FRONT_H,
                FRONT_D,
                Vec2::new(x, shelf_y),
                i == 0,
            )
        })
        .collect();
    ShowRow {
        dominoes,
        shelf_y,
        x0,
        x1,
        height: FRONT_H,
    }
}

/// Spawns the show with `fronts` parallel rows (see the module docs) and
/// returns its layout; the table pair rule goes into `ToppleConfig`.
pub fn domino_show(commands: &mut Commands, target: Target, fronts: usize) -> ShowLayout {
    scenes::pair_rule(commands, Mat::DOMINO, Mat::TABLE, Mat::TABLE);
    let mut show = ShowLayout::default();
    // the fronts, on the left
    for k in 0..fronts {
        let row = front(commands, target, -610.0, 240.0 - SHELF_GAP * k as f32, 23);
        show.all.extend(&row.dominoes);
        show.rows.push(row);
    }
    // growing dominoes onto a flat-stacked tower, top right
    let table_y = 110.0;
    shelf(commands, target, 0.0, 630.0, table_y);
    let mut x = 30.0;
    let mut h = 14.0;
    for i in 0..7 {
        let d = 0.18 * h;
        let e = domino(
            commands,
            target,
            h,
            d,
            Vec2::new(x + 0.5 * d, table_y),
            i == 0,
        );
        show.growing.push(e);
        x += d + 0.5 * h;
        h *= 1.5;
    }
    // the tower: 14 dominoes stacked flat, set back by turns, 0.3 of the
    // last domino's height beyond it
    let last = 14.0 * 1.5f32.powi(6);
    let brick = Vec2::new(56.0, 12.0);
    let tower_x = x - 0.5 * last + 0.3 * last;
    for course in 0..14 {
        let shift = if course % 2 == 0 { 0.0 } else { 6.0 };
        {
            let at = Vec2::new(
                tower_x + shift + 0.5 * brick.x,
                table_y + (course as f32 + 0.5) * brick.y,
            );
            let e = scenes::block(commands, target, brick, at, 0.0, Role::Domino, Mat::DOMINO);
            commands.entity(e).insert(Sleeping {
                sleeping: true,
                ..Sleeping::default()
            });
            show.tower.push(e);
        }
    }
    // a row down a flight of steps, bottom right
    let (step_w, drop, steps) = (70.0, 24.0, 6);
    let top = Vec2::new(20.0, -40.0);
    let mut outline = vec![top + Vec2::new(-20.0, 0.0)];
    for s in 0..steps {
        let corner = top + Vec2::new(step_w * (s + 1) as f32, -drop * s as f32);
        outline.push(corner);
        outline.push(corner - Vec2::new(0.0, drop));
    }
    let bottom = *outline.last().expect("steps have corners");
    outline.push(bottom + Vec2::new(160.0, 0.0));
    let mut stairs = commands.spawn((
        RigidBody::Fixed,
        Collider::polyline(outline.clone(), None),
        Transform::default(),
        Piece {
            shape: PieceShape::Line(outline),
            role: Role::Ground,
        },
    ));
    scenes::material(&mut stairs, target, Mat::TABLE);
    for s in 0..=steps {
        let (x0, y) = (top.x + step_w * s as f32, top.y - drop * s as f32);
        for (k, dx) in [8.0, 31.0, 54.0].into_iter().enumerate() {
            let e = domino(
                commands,
                target,
                FRONT_H,
                FRONT_D,
                Vec2::new(x0 + dx, y),
                s == 0 && k == 0,
            );
            show.steps.push(e);
        }
    }
    // a floor under everything, should anything fall off, and a wall at
    // each side of the window (a domino of the tower can be thrown off its
    // table far enough to miss the floor)
    shelf(commands, target, -640.0, 640.0, FLOOR_Y);
    for x in [-648.0, 648.0] {
        let mut wall = commands.spawn((
            RigidBody::Fixed,
            Collider::cuboid(8.0, 0.5 * (400.0 - FLOOR_Y)),
            Transform::from_xyz(x, 0.5 * (400.0 + FLOOR_Y), 0.0),
            Piece {
                shape: PieceShape::Rect(Vec2::new(16.0, 400.0 - FLOOR_Y)),
                role: Role::Ground,
            },
        ));
        scenes::material(&mut wall, target, Mat::TABLE);
    }
    show.all.extend(&show.growing);
    show.all.extend(&show.tower);
    show.all.extend(&show.steps);
    show
}
