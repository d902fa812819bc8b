//! The ideal domino row (μ₁ = 0, e₁ = 0, e₂ = 0), Domino T (h = 0.08 m,
//! d = 0.0096 m) on a no-slip ground through the Rapier plugin at dt = 1 ms:
//! the natural speed v̂_na within 2 % of Stronge's cooperative group model,
//! solved independently by [`topple::theory`] for the same d/h and s/h.
//!
//! The cooperative model assumes pivots that never slip; the paper's Coulomb
//! ground (μ₂ = 0.9, halved inside impacts) lets the struck block's foot slide
//! and runs a few per cent faster (docs/model.md), so these rows use
//! `ground = "no-slip"`. v̂_na is the mean v̂_i over blocks 7, 8, …
//! ([`topple::domino::WaveMeasures`]); at s/h = 0.2 the wave needs about 20
//! blocks to forget the push, so that row is longer. Native Rapier's value is
//! printed for the record.

use topple::rapier::scene::{run_scene, ImpactResponse, RunOptions, Scene};
use topple::rapier::Precision;
use topple::theory::{solve, Geometry, Model};

const DT: f64 = 1e-3;

fn ideal_row(spacing: f64, n: usize) -> Scene {
    toml::from_str(&format!(
        "duration = 5.0\n[solver]\nmax_work = \"none\"\ndt = {DT}\n\
         [row]\npreset = \"T\"\nn = {n}\nspacing = {spacing}\npush = 1.0\nideal = true\n\
         ground = \"no-slip\"\n"
    ))
    .unwrap()
}

fn natural_speed(scene: &Scene, engine: ImpactResponse) -> f64 {
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

fn check(spacing: f64, n: usize) {
    let geometry = Geometry::new(0.0096 / 0.08, spacing).unwrap();
    let cooperative = solve(&Model::Cooperative, &geometry)
        .unwrap()
        .natural_speed()
        .unwrap();
    let scene = ideal_row(spacing, n);
    let topple = natural_speed(&scene, ImpactResponse::Topple);
    let native = natural_speed(&scene, ImpactResponse::Native);
    let rel = |v: f64| (v - cooperative) / cooperative;
    eprintln!(
        "s/h {spacing}: cooperative {cooperative:.4}, topple {topple:.4} ({:+.2}%), native {native:.4} ({:+.2}%)",
        100.0 * rel(topple),
        100.0 * rel(native)
    );
    assert!(
        rel(topple).abs() < 0.02,
        "topple {topple} vs cooperative {cooperative}"
    );
}

#[test]
fn ideal_no_slip_row_s02_reaches_cooperative_speed() {
    check(0.2, 100);
}

#[test]
fn ideal_no_slip_row_s035_reaches_cooperative_speed() {
    check(0.35, 40);
}

#[test]
fn ideal_no_slip_row_s05_reaches_cooperative_speed() {
    check(0.5, 40);
}
