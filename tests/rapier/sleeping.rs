//! Sleeping costs nothing and changes nothing: a body that Rapier
//! has put to sleep and that an awake body strikes takes part in the impact
//! with its own supports, exactly as if it had been awake.
//!
//! The oracle is the same scene with every body awake. A struck stack of two
//! boxes on the ground needs both levels: the top box (touched by the ball)
//! brings the bottom box, which brings the ground. The scene has no gravity,
//! so Rapier's step moves nothing but the ball, and the two runs must agree
//! to rounding. A run without the ground shows the supports matter.

use topple::coupling::{PairMaterial, ToppleSettings};
use topple::impact::{ContactMaterial, ImpactSettings};
use topple::rapier::f64::ToppleRapier;
use topple::rapier2d_f64::prelude::*;

const HALF_W: f64 = 0.005; // m, box half width
const HALF_H: f64 = 0.025; // m, box half height
const BALL_R: f64 = 0.004; // m
const SPEED: f64 = 1.0; // m/s, ball towards the top box
const DT: f64 = 1e-3; // s

/// Ball, top box, bottom box: (linear velocity, angular velocity) after the
/// step in which the ball strikes.
fn strike(asleep: bool, ground: bool) -> Vec<([f64; 2], f64)> {
    let mut world = PhysicsWorld {
        gravity: Vector::ZERO,
        ..PhysicsWorld::default()
    };
    world.integration_parameters.dt = DT;
    // The paper's fixed impulse step: the awake and asleep runs list the same
    // contacts in another order, and only a fixed step makes the two sums
    // agree to rounding (adaptive steps would agree to their tolerance).
    let mut topple = ToppleRapier::new(ToppleSettings {
        impact: ImpactSettings::fixed(1e-4),
        ..ToppleSettings::default()
    });
    let material = topple.add_material(PairMaterial::from_table(
        ContactMaterial::hertz(2.3e8),
        0.3,  // μ
        0.35, // μ_s
        0.5,  // e
        0.5,  // impact friction factor
    ));
    if ground {
        let (_, c) = world.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5)),
            ColliderBuilder::cuboid(1.0, 0.5),
        );
        topple.manage(&mut world.colliders, c, material);
    }
    let mut handles = Vec::new();
    // bottom box on the ground, top box on the bottom one (gaps exactly 0)
    for k in 0..2 {
        let y = HALF_H * (2 * k + 1) as f64;
        let (b, c) = world.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(0.0, y)),
            ColliderBuilder::cuboid(HALF_W, HALF_H).density(1000.0),
        );
        topple.manage(&mut world.colliders, c, material);
        handles.push(b);
    }
    // one step to settle Rapier's islands, then the stack is put to sleep
    world.step_with_events(topple.hooks(), &());
    if asleep {
        for &b in &handles {
            world.bodies[b].sleep();
        }
    }
    // the ball strikes the top box high on its left face: it moves 1 mm in
    // the step and starts 0.5 mm away, so it is 0.5 mm in after the step
    let (ball, c) = world.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(-HALF_W - BALL_R - 5e-4, 3.6 * HALF_H))
            .linvel(Vector::new(SPEED, 0.0)),
        ColliderBuilder::ball(BALL_R).density(1000.0),
    );
    topple.manage(&mut world.colliders, c, material);
    handles.reverse();
    handles.insert(0, ball);
    topple.begin_step(
        world.gravity,
        &world.integration_parameters,
        &world.islands,
        &world.bodies,
    );
    world.step_with_events(topple.hooks(), &());
    if asleep {
        for &b in &handles[1..] {
            assert!(world.bodies[b].is_sleeping(), "Rapier woke a box");
        }
    }
    let impacts = topple.end_step(
        &mut world.bodies,
        &world.colliders,
        &world.narrow_phase,
        &world.broad_phase,
        &world.integration_parameters,
    );
    assert_eq!(impacts, 1);
    handles
        .iter()
        .map(|&b| {
            let rb = &world.bodies[b];
            ([rb.linvel().x, rb.linvel().y], rb.angvel())
        })
        .collect()
}

#[test]
fn a_struck_sleeping_stack_responds_as_if_awake() {
    let awake = strike(false, true);
    let asleep = strike(true, true);
    let floating = strike(false, false);
    let scale = SPEED; // velocities; ω times the box half height
    let mut differs_from_floating = 0.0f64;
    for k in 0..3 {
        let (a, s, f) = (awake[k], asleep[k], floating[k]);
        for j in 0..2 {
            assert!(
                (a.0[j] - s.0[j]).abs() < 1e-9 * scale,
                "body {k}: {a:?} vs {s:?}"
            );
            differs_from_floating = differs_from_floating.max((a.0[j] - f.0[j]).abs());
        }
        assert!(
            (a.1 - s.1).abs() * HALF_H < 1e-9 * scale,
            "body {k}: {a:?} vs {s:?}"
        );
        differs_from_floating = differs_from_floating.max((a.1 - f.1).abs() * HALF_H);
    }
    // the ground carries impulse in this impact: leaving it out (what a
    // sleeping stack's skipped pairs amounted to) changes the answer
    assert!(
        differs_from_floating > 0.01 * scale,
        "{differs_from_floating}"
    );
}
