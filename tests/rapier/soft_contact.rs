//! Rapier's soft contact at a shorter step (docs/stress.md, "Rapier's soft
//! contact at a shorter step"): the steady sag of a resting contact under
//! load, derived from rapier2d 0.35's solver, is a / ω² whatever the step,
//! a = F / m the load over the contact's projected mass, ω = 2π f its
//! softness' angular frequency. Against native Rapier (no topple): a ball
//! on the fixed ground at the frame step 1/60 s and at a quarter and a fifth
//! of it (the adapter's sub-steps), and a heavy ball on a light one, whose
//! two contacts in series sag a little less than the single-contact closed
//! form and less, not more, at the shorter steps. So matching the frame
//! step's steady sag asks for no change of softness per sub-step; what
//! topple's sub-steps change in the stacks of the scene sweep is not that
//! steady state.

use std::f64::consts::PI;

use topple::rapier2d_f64::prelude::*;

const FRAME: f64 = 1.0 / 60.0; // s
const R: f64 = 0.05; // m, ball radius
const G: f64 = 9.81; // m/s²

/// The sag (m) after 3 s of frames, each taken as `per_frame` Rapier steps:
/// of a ball resting on the ground, or (`upper` the mass ratio) of a ball
/// `upper` times heavier resting on it.
fn sag(per_frame: usize, upper: Option<f64>) -> f64 {
    let mut world = PhysicsWorld::default();
    world.integration_parameters.dt = FRAME / per_frame as f64;
    world.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5)),
        ColliderBuilder::cuboid(5.0, 0.5),
    );
    let ball = |y: f64| {
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, y))
            .locked_axes(LockedAxes::ROTATION_LOCKED)
    };
    let (low, _) = world.insert(ball(R), ColliderBuilder::ball(R).density(1.0));
    let high = upper.map(|ratio| {
        world
            .insert(ball(3.0 * R), ColliderBuilder::ball(R).density(ratio))
            .0
    });
    for _ in 0..180 * per_frame {
        world.step();
    }
    let y_low = world.bodies[low].translation().y;
    match high {
        None => R - y_low,
        Some(h) => y_low + 2.0 * R - world.bodies[h].translation().y,
    }
}

#[test]
fn a_resting_contact_sags_by_the_closed_form_at_every_step() {
    let params = IntegrationParameters::default();
    let omega_fixed = 2.0 * PI * params.static_contact_softness.natural_frequency;
    let omega = 2.0 * PI * params.contact_softness.natural_frequency;
    // one contact against the fixed ground: a = g
    let closed = G / (omega_fixed * omega_fixed);
    for n in [1, 4, 5] {
        let s = sag(n, None);
        assert!(
            (s - closed).abs() < 1e-3 * closed,
            "{n} steps per frame: {s} m against {closed} m"
        );
    }
    // a ball 10 times heavier on it: the upper contact's load over its
    // projected mass, a = 10 m g (1/m + 1/(10 m)) = 11 g; two contacts in
    // series, each relaxed by one Gauss–Seidel pass, sag 8–14 % less than
    // one contact would, and less at the shorter steps (measured 2.80,
    // 2.65, 2.61 mm against 3.04 mm)
    let closed = 11.0 * G / (omega * omega);
    let frame = sag(1, Some(10.0));
    assert!(
        frame < closed && frame > 0.85 * closed,
        "{frame} m against {closed} m"
    );
    for n in [4, 5] {
        let s = sag(n, Some(10.0));
        assert!(
            s <= frame && s > 0.85 * closed,
            "{n} steps per frame: {s} m, one: {frame} m"
        );
    }
}
