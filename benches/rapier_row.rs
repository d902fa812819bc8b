//! Work-precision report for the Rapier plugin (not a criterion bench: one run
//! per setting is minutes long). Runs the ideal Domino T row (s/h = 0.35,
//! push 1.0) through Rapier with topple and natively, for a few time steps and
//! impulse steps ΔP/P₀, and prints a markdown table: wall time per step, the
//! ratio topple/native, and the natural speed's error against the cooperative
//! model (1.8023 for this geometry, reference/theory.md).
//!
//! `cargo bench --bench rapier_row` (1,000 blocks); `TOPPLE_ROW_N=200` for a
//! shorter row, `TOPPLE_ROW_DT=1e-3,5e-4` to choose the steps.

use std::time::Instant;

use topple::rapier::scene::{build, Engine, HitTracker, RowMeasures, Scene};

const COOPERATIVE: f64 = 1.8023;

struct Run {
    steps: usize,
    seconds: f64,
    natural_speed: Option<f64>,
    impacts: u64,
}

fn run(n: usize, dt: f64, engine: Engine, impulse_step: Option<String>) -> Result<Run, String> {
    let mut text = format!(
        "duration = 100.0\n[solver]\ndt = {dt}\nlength_unit = 0.01\nmax_group_hops = 8\n\
         [row]\npreset = \"T\"\nn = {n}\nspacing = 0.35\npush = 1.0\nideal = true\n"
    );
    if let Some(t) = impulse_step {
        text = text.replace(
            "length_unit = 0.01\n",
            &format!("length_unit = 0.01\nimpulse_step = {t}\n"),
        );
    }
    let scene: Scene = toml::from_str(&text).unwrap();
    let mut sw = build(&scene, engine).unwrap();
    let mut hits = HitTracker::new();
    let start = Instant::now();
    let mut steps = 0;
    let max_steps = (scene.duration / dt) as usize;
    while hits.hit_times.len() < n && steps < max_steps {
        let t = sw.time;
        sw.step().map_err(|e| format!("at t = {t:.3} s: {e}"))?;
        steps += 1;
        hits.update(&sw, sw.time, dt);
        // a wave that stopped: nothing hit for 1 s
        if sw.time - hits.hit_times.last().copied().unwrap_or(0.0) > 1.0 {
            break;
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let row = sw.row.as_ref().unwrap();
    let m = RowMeasures::from_hit_times(
        hits.hit_times.clone(),
        n,
        row.spacing,
        row.preset.thickness,
        row.preset.height,
        9.81,
    );
    Ok(Run {
        steps,
        seconds,
        natural_speed: m.natural_speed,
        impacts: sw.topple.stats().impacts,
    })
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let n: usize = std::env::var("TOPPLE_ROW_N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000);
    let dts: Vec<f64> = std::env::var("TOPPLE_ROW_DT")
        .unwrap_or_else(|_| "1e-3,5e-4".into())
        .split(',')
        .map(|s| s.trim().parse().unwrap())
        .collect();
    println!(
        "ideal Domino T row, n = {n}, s/h = 0.35, push 1.0; cooperative v_na = {COOPERATIVE}\n"
    );
    println!(
        "| dt (s) | engine | impulse step | ms/step | topple/native | v_na | error | impacts |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    let fmt = |v: Option<f64>| match v {
        Some(v) => (
            format!("{v:.4}"),
            format!("{:+.2}%", 100.0 * (v - COOPERATIVE) / COOPERATIVE),
        ),
        None => ("stopped".into(), "-".into()),
    };
    for &dt in &dts {
        let native =
            run(n, dt, Engine::RapierNative, None).expect("native Rapier has no impact errors");
        let native_ms = 1e3 * native.seconds / native.steps as f64;
        let (v, e) = fmt(native.natural_speed);
        println!("| {dt:e} | rapier-native | - | {native_ms:.3} | 1 | {v} | {e} | - |");
        for control in ["fixed 1e-4", "fixed 1e-3"] {
            let (step, tol) = match control {
                "fixed 1e-4" => ("fixed 1e-4 P0".to_string(), None),
                c => (
                    format!("{c} P0"),
                    Some(c.trim_start_matches("fixed ").to_string()),
                ),
            };
            let r = match run(n, dt, Engine::Rapier, tol) {
                Ok(r) => r,
                Err(e) => {
                    println!("| {dt:e} | rapier (topple) | {step} | failed: {e} | | | | |");
                    continue;
                }
            };
            let ms = 1e3 * r.seconds / r.steps as f64;
            let (v, e) = fmt(r.natural_speed);
            println!(
                "| {dt:e} | rapier (topple) | {step} | {ms:.3} | {:.2} | {v} | {e} | {} |",
                ms / native_ms,
                r.impacts
            );
        }
    }
}
