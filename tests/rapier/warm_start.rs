//! Open: a stack at rest under topple sinks deeper than under native
//! Rapier while the adapter cuts the frames around it into sub-steps and
//! split steps of other lengths. This test shows it and fails today; it is
//! ignored until the adapter's stepping is fixed (docs/bevy.md, "Warm start
//! across sub-steps"). Run it with
//! `cargo test --release --test rapier -- warm_start --ignored --nocapture`.
//!
//! The oracle is native Rapier on the same scene (`ToppleRapier::native`,
//! which steps Rapier once per frame, the pairs' friction and restitution
//! set by the same hook). A stack of four boxes whose masses double per
//! level (0.25 to 2 kg, the heaviest on top) rests on the ground: Rapier's
//! soft contacts let a heavier box sink into a lighter one under load, by
//! an amount set by its solver and warm start. A ball bounces (e = 1) on
//! the ground beside it, so that topple sub-steps the frames in which the
//! ball closes on the ground and splits them at its impacts, and takes the
//! others whole: the stack's contacts see Rapier steps of several lengths.
//! The stack takes part in no impact (its contacts approach slower than the
//! impact threshold), so whatever depth it reaches beyond native's is the
//! adapter's stepping, not an impact. Measured: native 6.81·10⁻³ m,
//! topple 9.03·10⁻³ m (+33 %), no impact in the stack.

use topple::coupling::{PairMaterial, ToppleSettings};
use topple::impact::ContactMaterial;
use topple::rapier::f64::ToppleRapier;
use topple::rapier2d_f64::prelude::*;

use super::stack::{Run, HALF, LEVELS};

const DT: f64 = 1.0 / 60.0; // s
const FRAMES: usize = 180; // 3 s

fn run(topple_mode: bool) -> Run {
    run_with(topple_mode, 2.0, LEVELS, 1.0)
}

fn run_with(topple_mode: bool, ratio: f64, levels: usize, ball_e: f64) -> Run {
    let mut world = PhysicsWorld::default();
    world.integration_parameters.dt = DT;
    let mut topple = if topple_mode {
        ToppleRapier::new(ToppleSettings::default())
    } else {
        ToppleRapier::native()
    };
    let wood = super::stack::wood(&mut topple);
    let rubber = topple.add_material(PairMaterial::from_table(
        ContactMaterial::hertz(1e8),
        0.5,
        0.6,
        ball_e,
        1.0,
    ));
    let (_, ground) = world.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5)),
        ColliderBuilder::cuboid(5.0, 0.5),
    );
    topple.manage(&mut world.colliders, ground, wood);
    // masses ratio^(k−2) kg, the heaviest on top
    let (stack, colliders) =
        super::stack::column(&mut world, &mut topple, ground, wood, (HALF, levels, ratio));
    // the ball that keeps topple sub-stepping and splitting, 1 m away
    let (_, ball) = world.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(1.0, 0.6)),
        ColliderBuilder::ball(0.05).density(1000.0),
    );
    topple.manage(&mut world.colliders, ball, rubber);
    let mut out = Run::default();
    for _ in 0..FRAMES {
        topple.step(&mut world);
        out.watch(&topple, &world, &stack, &colliders);
    }
    out
}

#[test]
#[ignore = "open: topple's stepping sinks a resting stack deeper than native Rapier (docs/bevy.md)"]
fn a_resting_stack_sinks_no_deeper_than_in_native_rapier() {
    let native = run(false);
    let topple = run(true);
    eprintln!(
        "deepest overlap: native {:.6e} m, topple {:.6e} m; topple: {} impacts ({} in the stack), {} Rapier steps in {FRAMES} frames",
        native.deepest, topple.deepest, topple.impacts, topple.stack_impacts, topple.rapier_steps
    );
    // the scene does what it is for: the ball's impacts make topple step
    // Rapier in pieces of several lengths, the stack takes no impact, and
    // native Rapier lets the heavy boxes sink measurably
    assert!(topple.impacts >= 3, "{}", topple.impacts);
    assert_eq!(topple.stack_impacts, 0);
    assert!(topple.rapier_steps > FRAMES as u64);
    assert!(native.deepest > 1e-4, "{}", native.deepest);
    // no deeper than native, to 1 % of native's depth
    assert!(
        topple.deepest <= 1.01 * native.deepest,
        "topple {} m against native {} m",
        topple.deepest,
        native.deepest
    );
}
