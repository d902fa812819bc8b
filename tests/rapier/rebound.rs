//! The rebound threshold (docs/bevy.md, "Rebounds and chatter";
//! docs/game-rate.md, "The rebound threshold at one Rapier step's
//! approach"): a managed pair with e > 0 that Rapier's solver has not held
//! lately is topple's impact when it approaches faster than |g| Δt/n, the
//! approach gravity gives a contact in one Rapier step of a frame cut into
//! n sub-steps (0.041 m/s at 1/60 s in four pieces); a slower approach is
//! left to Rapier, which stops it (restitution 0 on managed pairs).
//!
//! A ball slides without friction on the ground into a fixed wall at 1/60 s
//! (the sliding contact cuts every frame into four pieces of 1/240 s). Its
//! rebound is checked against the closed form of a frictionless ball on a
//! fixed wall, v' = −e v (one contact: Newton's and the energetic
//! restitution agree), at a speed between |g| Δt/n and the former threshold
//! 2 |g| Δt/n (0.082 m/s, which stopped that ball dead), at one above both,
//! and below |g| Δt/n, where Rapier stops the ball.

use topple::rapier::scene::{run_scene, ImpactResponse, RunOptions, Scene};
use topple::rapier::Precision;

const G: f64 = 9.81; // m/s²
const DT: f64 = 1.0 / 60.0; // s
const E: f64 = 0.5;
const R: f64 = 0.05; // m, the ball's radius
const GAP: f64 = 0.01; // m, between the ball and the wall at the start

/// The ball at rest on the ground, moving at `v` (m/s) towards a fixed
/// wall `GAP` ahead; one material: e = 0.5, no friction.
fn wall_scene(v: f64) -> Scene {
    let wall_x = R + GAP + 0.05;
    toml::from_str(&format!(
        "duration = 0.6\ngravity = [0.0, -{G}]\n[solver]\nmax_work = \"none\"\ndt = {DT}\n\
         length_unit = 0.1\n\
         [[materials]]\nname = \"m\"\nstiffness = 1e9\nrestitution = {E}\nfriction = 0.0\n\
         stick_friction = 0.0\n\
         [ground]\ny = 0.0\nmaterial = \"m\"\n\
         [[bodies]]\nname = \"ball\"\nshape = \"ball\"\nradius = {R}\nposition = [0.0, {R}]\n\
         velocity = [{v}, 0.0]\nmass = 1.0\nmaterial = \"m\"\n\
         [[bodies]]\nname = \"wall\"\nshape = \"box\"\nsize = [0.1, 0.4]\nposition = [{wall_x}, 0.21]\n\
         fixed = true\nmaterial = \"m\"\n"
    ))
    .unwrap()
}

/// The ball's horizontal velocity (m/s) at the end, and the impacts topple
/// resolved.
fn run(v: f64, precision: Precision) -> (f64, usize) {
    let out = run_scene(
        &wall_scene(v),
        ImpactResponse::Topple,
        precision,
        RunOptions::default(),
    )
    .unwrap();
    let ball = out.bodies.iter().find(|b| b.name == "ball").unwrap();
    (ball.velocity[0], out.impacts.len())
}

#[test]
fn a_slow_rebound_off_a_wall_follows_the_closed_form_down_to_one_rapier_steps_approach() {
    let n = 4.0; // pieces of the 1/60 s frame (max_substep 1/240 s)
    let (lower, former) = (G * DT / n, 2.0 * G * DT / n);
    assert!(lower < 0.06 && 0.06 < former && former < 0.12);
    for precision in [Precision::F64, Precision::F32] {
        // between the threshold and the former one, and above both
        for v in [0.06, 0.12] {
            let (vx, impacts) = run(v, precision);
            eprintln!("{precision:?}: v = {v} m/s -> {vx:.6} m/s, {impacts} impacts");
            assert!(
                (vx + E * v).abs() < 1e-3 * v,
                "{precision:?}: the ball left the wall at {vx} m/s, closed form {}",
                -E * v
            );
        }
        // below |g| Δt/n: Rapier's, stopped at the wall
        let v = 0.03;
        let (vx, impacts) = run(v, precision);
        eprintln!("{precision:?}: v = {v} m/s -> {vx:.6} m/s, {impacts} impacts");
        assert!(v < lower);
        assert!(vx.abs() < 0.1 * v, "{precision:?}: {vx} m/s after the wall");
    }
}
