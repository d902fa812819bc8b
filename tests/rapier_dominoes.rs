//! The ideal domino row (μ₁ = 0, e₁ = 0, μ₂ = 0.9, e₂ = 0), Domino T
//! (h = 0.08 m, d = 0.0096 m): topple's natural speed within 3% of Stronge's
//! cooperative group model (values for this geometry from reference/theory.md:
//! s/h 0.2 → 1.9626, 0.35 → 1.8023, 0.5 → 1.7095). Native Rapier's natural
//! speed is printed for the record.
//!
//! The natural speed is the mean v̂_i over blocks 7 ..= n − 2. At s/h = 0.2 the
//! wave needs about 20 blocks to settle from the push, so that row is longer (150 blocks).
//! Impacts use a window of 4 contacts around the blocks that start them (the
//! natural speed moves by about 0.1% between windows 2 and 8 on 40 blocks).

use topple::rapier::scene::{run_scene, Engine, RunOptions, Scene};
use topple::rapier::Precision;

fn ideal_row(spacing: f64, n: usize, dt: f64) -> Scene {
    toml::from_str(&format!(
        "duration = 5.0\n[solver]\ndt = {dt}\nlength_unit = 0.01\nmax_group_hops = 4\n\
         [row]\npreset = \"T\"\nn = {n}\nspacing = {spacing}\npush = 1.0\nideal = true\n"
    ))
    .unwrap()
}

fn natural_speed(scene: &Scene, engine: Engine) -> f64 {
    let options = RunOptions {
        stop_after_last_hit: true,
        ..RunOptions::default()
    };
    let out = run_scene(scene, engine, Precision::F64, options).unwrap();
    let row = out.row.unwrap();
    row.natural_speed.unwrap_or_else(|| {
        panic!(
            "{engine:?}: wave stopped after {} blocks",
            row.hit_times.len()
        )
    })
}

fn check(spacing: f64, cooperative: f64, n: usize) {
    let scene = ideal_row(spacing, n, DT);
    let topple = natural_speed(&scene, Engine::Rapier);
    let native = natural_speed(&scene, Engine::RapierNative);
    let rel = |v: f64| (v - cooperative) / cooperative;
    eprintln!(
        "s/h {spacing}: cooperative {cooperative}, topple {topple:.4} ({:+.2}%), native {native:.4} ({:+.2}%)",
        100.0 * rel(topple),
        100.0 * rel(native)
    );
    assert!(
        rel(topple).abs() < 0.03,
        "topple {topple} vs cooperative {cooperative}"
    );
}

const DT: f64 = 2e-4;

#[test]
fn ideal_row_s02_reaches_cooperative_speed() {
    check(0.2, 1.9626, 150);
}

#[test]
fn ideal_row_s035_reaches_cooperative_speed() {
    check(0.35, 1.8023, 40);
}

#[test]
fn ideal_row_s05_reaches_cooperative_speed() {
    check(0.5, 1.7095, 40);
}
