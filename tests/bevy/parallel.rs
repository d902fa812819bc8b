//! A show's far-apart fronts in Bevy (pixel units, 1/60 s,
//! `TopplePlugin::default()`): with the step's independent impacts solved
//! in batches, side by side on rayon's threads, every domino's transform
//! and velocity at every frame and every `ToppleImpact` message are the
//! same bits as with one instant at a time (docs/bevy.md, "Independent
//! impacts side by side").

use crate::example_scenes as scenes;

use bevy::prelude::*;
use bevy_rapier2d::prelude::*;
use scenes::{Mat, Target};
use topple::bevy::{ImpactResponse, ToppleFrameStats, ToppleImpact, ToppleWorld};

/// `fronts` rows of 12 dominoes (32 × 7 px at s/h 0.5) on their own
/// shelves 48 px apart, as the show's fronts; row k's first domino pushed
/// at (1 + k/10) √(g/h) so that the fronts hit at different instants.
fn spawn_fronts(commands: &mut Commands, fronts: usize) -> Vec<Entity> {
    let target = Target {
        physics: ImpactResponse::Topple,
        context: None,
    };
    scenes::pair_rule(commands, Mat::DOMINO, Mat::TABLE, Mat::TABLE);
    let (h, d) = (32.0, 7.0);
    let pitch = 0.5 * h + d;
    let mut all = Vec::new();
    for k in 0..fronts {
        let y = 240.0 - 48.0 * k as f32;
        let x0 = -610.0;
        scenes::ground(
            commands,
            target,
            x0 - 10.0,
            x0 + 12.0 * pitch + 2.0 * h,
            y,
            Mat::TABLE,
        );
        for i in 0..12 {
            let foot = Vec2::new(x0 + 0.5 * d + pitch * i as f32, y);
            let push = (i == 0).then_some(1.0 + 0.1 * k as f32);
            all.push(scenes::standing_domino(commands, target, h, d, foot, push));
        }
    }
    all
}

/// Per frame: every domino's transform and velocity (bits) and the frame's
/// impact messages; the impacts solved in batches.
fn run(batches: bool, frames: usize) -> (Vec<(Vec<u32>, String)>, u64) {
    let mut app = scenes::headless_app(ImpactResponse::Topple);
    let mut dominoes = Vec::new();
    scenes::spawn_in(&mut app, |c| dominoes = spawn_fronts(c, 6));
    let mut batched = 0;
    let mut trace = Vec::with_capacity(frames);
    for frame in 0..frames {
        app.update();
        if frame == 0 {
            let world = app.world_mut();
            let mut q = world.query::<&mut ToppleWorld>();
            for mut w in q.iter_mut(world) {
                w.set_impact_batches(batches);
            }
        }
        batched += app.world().resource::<ToppleFrameStats>().batched_impacts;
        let messages: Vec<ToppleImpact> = app
            .world_mut()
            .resource_mut::<Messages<ToppleImpact>>()
            .drain()
            .collect();
        let bits = dominoes
            .iter()
            .flat_map(|&e| {
                let t = app.world().get::<Transform>(e).unwrap();
                let v = app.world().get::<Velocity>(e).unwrap();
                [
                    t.translation.x,
                    t.translation.y,
                    t.rotation.z,
                    t.rotation.w,
                    v.linear.x,
                    v.linear.y,
                    v.angular,
                ]
                .map(f32::to_bits)
            })
            .collect();
        trace.push((bits, format!("{messages:?}")));
    }
    (trace, batched)
}

#[test]
fn far_apart_fronts_give_the_same_bits_in_batches() {
    let frames = 150;
    let (one, none) = run(false, frames);
    let (batched, count) = run(true, frames);
    assert_eq!(none, 0);
    assert!(count > 0, "no impact was solved in a batch");
    for (k, (a, b)) in one.iter().zip(&batched).enumerate() {
        assert_eq!(a.1, b.1, "frame {k}: the impacts differ");
        assert_eq!(a.0, b.0, "frame {k}: the dominoes differ");
    }
}
