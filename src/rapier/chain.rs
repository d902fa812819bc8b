//! The domino row of `topple chain` run through Rapier, with topple's impacts
//! or natively, reported in the reference engine's [`ChainReport`].

use std::time::Instant;

use crate::domino::{ChainReport, RowSpec};

use super::scene::{
    build, Engine, HitTracker, RowOverrides, RowSpec as SceneRow, Scene, SolverSpec,
};

/// Runs `row` through Rapier until its last block is hit (or nothing was hit
/// for 2 s, or `max_time` passed) and reports hit times, v̂_i and v̂_na with
/// the same keys as the reference engine.
pub fn run_row(
    row: &RowSpec,
    engine: Engine,
    solver: SolverSpec,
    max_time: f64,
) -> anyhow::Result<ChainReport> {
    run_row_with_progress(row, engine, solver, max_time, |_| {})
}

/// [`run_row`], calling `progress` with the number of blocks hit so far each
/// time the wave reaches another block.
pub fn run_row_with_progress(
    row: &RowSpec,
    engine: Engine,
    solver: SolverSpec,
    max_time: f64,
    mut progress: impl FnMut(usize),
) -> anyhow::Result<ChainReport> {
    let p = &row.params;
    let scene = Scene {
        description: String::new(),
        duration: max_time,
        gravity: [0.0, -p.gravity],
        solver: SolverSpec {
            lambda: p.lambda_points,
            ..solver
        },
        materials: Vec::new(),
        pairs: Vec::new(),
        ground: None,
        bodies: Vec::new(),
        row: Some(SceneRow {
            preset: "T".into(), // every value is overridden below
            n: row.n,
            spacing: row.spacing_ratio(),
            push: row.push,
            ideal: false,
            density: 1000.0,
            mass: Some(p.block.mass),
            overrides: RowOverrides {
                height: Some(p.block.height),
                thickness: Some(p.block.thickness),
                mu1: Some(p.mu1),
                mu1_stick: Some(p.mu1_stick),
                e1: Some(p.e1),
                k1: Some(p.k1),
                mu2: Some(p.mu2),
                mu2_stick: Some(p.mu2_stick),
                e2: Some(p.e2),
                k2: Some(p.k2),
                alpha: Some(p.alpha),
                impact_friction_factor: Some(p.impact_friction_factor),
            },
        }),
    };
    let start = Instant::now();
    let mut sw = build(&scene, engine)?;
    let dt = sw.world.integration_parameters.dt;
    let mut hits = HitTracker::new();
    while hits.hit_times.len() < row.n && sw.time < max_time {
        sw.step()?;
        let before = hits.hit_times.len();
        hits.update(&sw, sw.time, dt);
        for hit in before + 1..=hits.hit_times.len() {
            progress(hit);
        }
        if sw.time - hits.hit_times.last().copied().unwrap_or(0.0) > 2.0 {
            break;
        }
    }
    let mut report = ChainReport::new(engine.name(), row, hits.hit_times.clone());
    report.impacts = sw.topple.stats().impacts as usize;
    report.simulated_time = sw.time;
    report.run_time = start.elapsed().as_secs_f64();
    Ok(report)
}
