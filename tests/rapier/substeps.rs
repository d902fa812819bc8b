//! A frame longer than [`ToppleSettings::max_substep`] is taken as equal
//! Rapier steps, each with the app's own Rapier parameters but its
//! `num_solver_iterations` N shared out over the pieces, so that Rapier's
//! own substep stays the frame's Δt / N (each piece of Δt / 4 solved in
//! round(N / 4) substeps, at least 1; bodies that turn fast keep N per
//! piece: docs/stress.md, "Native Rapier's substep inside the pieces"):
//! while managed bodies move in contact without turning and nothing
//! closes, a 1/60 s frame of topple ends where native Rapier ends after
//! four steps of 1/240 s with one solver iteration each, whatever the
//! app's N. The native run is topple's native twin
//! ([`ToppleRapier::native`]: the same hook setting friction and
//! restitution, never sub-stepped, no impact pass), stepped four times by
//! hand. An app that sets one solver iteration gets native's solver work
//! per frame, and so does one that keeps Rapier's default of four.

use topple::coupling::{PairMaterial, ToppleSettings};
use topple::impact::ContactMaterial;
use topple::rapier::f64::ToppleRapier;
use topple::rapier::ToppleStats;
use topple::rapier2d_f64::prelude::*;

const FRAME: f64 = 1.0 / 60.0;

/// A box of 0.1 m sliding at 4 m/s on a managed ground (friction 0.3; fast
/// enough to move further than half Rapier's prediction distance, 1 cm, in
/// every 1/240 s, so that topple sub-steps the whole frame),
/// stepped `frames` times by `dt` (s) with `iterations` solver iterations;
/// returns the box's pose and velocity (x, y, angle, vx, vy, ω) and the
/// adapter's totals.
fn slide(
    mut topple: ToppleRapier,
    dt: f64,
    frames: usize,
    iterations: usize,
) -> (Vec<[f64; 6]>, ToppleStats) {
    let mut world = PhysicsWorld::default();
    world.integration_parameters.dt = dt;
    world.integration_parameters.num_solver_iterations = iterations;
    let material = topple.add_material(PairMaterial {
        impact: ContactMaterial::hertz(1e9).with_restitution(0.0),
        smooth_friction: 0.3,
    });
    let ground = world.insert_collider(
        ColliderBuilder::cuboid(5.0, 0.1).translation(Vector::new(0.0, -0.1)),
        None,
    );
    topple.manage(&mut world.colliders, ground, material);
    let (body, collider) = world.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, 0.05))
            .linvel(Vector::new(4.0, 0.0)),
        ColliderBuilder::cuboid(0.05, 0.05),
    );
    topple.manage(&mut world.colliders, collider, material);
    for _ in 0..frames {
        topple.step(&mut world);
    }
    let rb = &world.bodies[body];
    let (p, v) = (rb.translation(), rb.linvel());
    let state = vec![[p.x, p.y, rb.rotation().angle(), v.x, v.y, rb.angvel()]];
    (state, topple.stats())
}

fn largest_difference(a: &[[f64; 6]], b: &[[f64; 6]]) -> f64 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_frame_is_four_rapier_steps_at_the_frames_rapier_substep() {
    let frames = 6;
    let settings = ToppleSettings::default();
    assert_eq!(settings.max_substep, Some(1.0 / 240.0));
    for iterations in [1, 4] {
        let (topple, stats) = slide(ToppleRapier::new(settings), FRAME, frames, iterations);
        // a quarter frame of a frame solved in `iterations` substeps:
        // round(iterations / 4), at least 1
        let (native, _) = slide(ToppleRapier::native(), FRAME / 4.0, 4 * frames, 1);
        // sub-stepped (the box moves in contact), and nothing to resolve
        assert_eq!(stats.rapier_steps, 4 * frames as u64, "{stats:?}");
        assert_eq!(stats.impacts, 0, "{stats:?}");
        // the sub-step boundaries are FRAME·k/4, not sums of FRAME/4: they
        // differ by roundings only (m, m/s, rad)
        let diff = largest_difference(&topple, &native);
        assert!(
            diff < 1e-12,
            "{iterations} iterations: topple {topple:?} against native {native:?}"
        );
    }
    // the iterations matter here, so the comparison above tells them apart
    let (one, _) = slide(ToppleRapier::native(), FRAME / 4.0, 4 * frames, 1);
    let (four, _) = slide(ToppleRapier::native(), FRAME / 4.0, 4 * frames, 4);
    assert!(
        largest_difference(&one, &four) > 1e-9,
        "{one:?} against {four:?}"
    );
}

/// The f32 build (bevy_rapier's) cuts a 1/60 s frame into the same four
/// pieces of 1/240 s as the f64 build: 1/60 s as f32 over 1/240 s is
/// 4.0000002, and the count of pieces must not depend on that rounding (it
/// was 5 in the f32 build). The same sliding box as above, in f32.
#[test]
fn the_f32_build_cuts_a_sixtieth_of_a_second_into_four_pieces_too() {
    use topple::rapier::f32::ToppleRapier as ToppleRapier32;
    use topple::rapier2d::prelude as r32;
    let frames = 6;
    let mut topple = ToppleRapier32::new(ToppleSettings::default());
    let mut world = r32::PhysicsWorld::default();
    world.integration_parameters.dt = 1.0 / 60.0;
    let material = topple.add_material(PairMaterial {
        impact: ContactMaterial::hertz(1e9).with_restitution(0.0),
        smooth_friction: 0.3,
    });
    let ground = world.insert_collider(
        r32::ColliderBuilder::cuboid(5.0, 0.1).translation(r32::Vector::new(0.0, -0.1)),
        None,
    );
    topple.manage(&mut world.colliders, ground, material);
    let (_, collider) = world.insert(
        r32::RigidBodyBuilder::dynamic()
            .translation(r32::Vector::new(0.0, 0.05))
            .linvel(r32::Vector::new(4.0, 0.0)),
        r32::ColliderBuilder::cuboid(0.05, 0.05),
    );
    topple.manage(&mut world.colliders, collider, material);
    for _ in 0..frames {
        topple.step(&mut world);
    }
    let stats = topple.stats();
    assert_eq!(stats.rapier_steps, 4 * frames as u64, "{stats:?}");
    assert_eq!(stats.impacts, 0, "{stats:?}");
}
