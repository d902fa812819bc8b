//! Frame time of a headless Bevy domino scene (the `dominoes` example's rows
//! without the window): 1,000 and 10,000 ideal Domino T blocks at s/h 0.45,
//! pushed, stepped at 1/60 s for 10 s of simulated time, native bevy_rapier
//! and topple measured in the same run.
//!
//! ```text
//! cargo bench --features bevy --bench bevy_frames
//! ```
//!
//! Prints per case the mean and worst frame time, the real-time factor
//! (simulated over wall time) and topple's cost over native's, for topple's
//! default settings (a frame taken as four 1/240 s pieces) and for whole
//! 1/60 s steps (`ToppleSettings::max_substep = None`).

use std::time::Instant;

use topple::bevy::{
    headless_row_app, DominoRow, DominoRowState, RowPhysics, ToppleConfig, ToppleFrameStats,
};
use topple::domino::{Preset, RowSpec};

const DT: f64 = 1.0 / 60.0;
const FRAMES: usize = 600;

struct Case {
    mean_ms: f64,
    worst_ms: f64,
    realtime: f64,
    hit: usize,
    impacts: u64,
}

fn run(n: usize, physics: RowPhysics, substeps: bool) -> Case {
    let p = Preset::T.params().ideal();
    let row = DominoRow {
        physics,
        ..DominoRow::new(RowSpec::new(p, 0.45 * p.block.height, n, 1.0))
    };
    let (mut app, id) = headless_row_app(&row, DT).expect("a valid row");
    if !substeps {
        app.world_mut()
            .resource_mut::<ToppleConfig>()
            .settings
            .max_substep = None;
    }
    let (mut worst, mut impacts) = (0.0f64, 0);
    let start = Instant::now();
    for _ in 0..FRAMES {
        let t = Instant::now();
        app.update();
        worst = worst.max(t.elapsed().as_secs_f64());
        impacts += app.world().resource::<ToppleFrameStats>().impacts;
    }
    let wall = start.elapsed().as_secs_f64();
    let hit = app
        .world()
        .get::<DominoRowState>(id)
        .unwrap()
        .hit_times()
        .len();
    Case {
        mean_ms: 1e3 * wall / FRAMES as f64,
        worst_ms: 1e3 * worst,
        realtime: FRAMES as f64 * DT / wall,
        hit,
        impacts,
    }
}

fn main() {
    println!("| blocks | engine | mean frame (ms) | worst frame (ms) | × real time | blocks hit | impacts | topple / native |");
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    for n in [1_000, 10_000] {
        let native = run(n, RowPhysics::Native, false);
        let topple = run(n, RowPhysics::Topple, true);
        let whole = run(n, RowPhysics::Topple, false);
        for (name, c) in [
            ("native", &native),
            ("topple (1/240 s pieces, default)", &topple),
            ("topple (whole 1/60 s steps)", &whole),
        ] {
            println!(
                "| {n} | {name} | {:.3} | {:.2} | {:.0} | {} | {} | {} |",
                c.mean_ms,
                c.worst_ms,
                c.realtime,
                c.hit,
                c.impacts,
                if name != "native" {
                    format!("{:.2}", c.mean_ms / native.mean_ms)
                } else {
                    "".into()
                }
            );
        }
    }
}
