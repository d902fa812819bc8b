//! The domino row of `topple chain` run through Rapier, with topple's impacts
//! or natively, reported in the reference engine's [`ChainReport`].

use std::time::Instant;

use crate::domino::{ChainReport, RowSpec};
use crate::rapier::scene::{row_scene, ImpactResponse, SceneResult, SolverSpec};

use super::{build, HitTracker};

/// Runs `row` through this Rapier build until its last block is hit (or
/// nothing was hit for 2 s, or `max_time` (s) passed) and reports hit times,
/// v̂_i and v̂_na with the same keys as the reference engine; calls
/// `progress` with the number of blocks hit so far each time the wave reaches
/// another block. See [`crate::rapier::scene::run_row`] for either build.
pub fn run_row(
    row: &RowSpec,
    engine: ImpactResponse,
    solver: SolverSpec,
    max_time: f64,
    mut progress: impl FnMut(usize),
) -> SceneResult<ChainReport> {
    let scene = row_scene(row, solver, max_time);
    let start = Instant::now();
    let mut sw = build(&scene, engine)?;
    let dt = f64::from(sw.world.integration_parameters.dt);
    let mut hits = HitTracker::new();
    while hits.hit_times.len() < row.n && sw.time < max_time {
        sw.step();
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
