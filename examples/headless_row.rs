//! A domino row in a headless Bevy app (MinimalPlugins, no window), with
//! topple's impacts or native bevy_rapier, printing the row's measures with
//! the keys of `topple chain --json`.
//!
//! ```text
//! cargo run --release --features bevy --example headless_row -- \
//!     --preset t --ideal --spacing-ratio 0.45 --n 100 --dt 0.0166667 --json
//! ```
//!
//! Flags (the values `topple chain` accepts): `--preset x|t|p` (default x),
//! `--ideal`, `--spacing-ratio S` (default 0.45), `--n N` (default 40),
//! `--push P` (default 1), `--dt DT` (s, default 1/60), `--max-time T`
//! (simulated s, default 20), `--native`, `--json`.

use std::process::ExitCode;

use topple::bevy::{headless_row_app, DominoRow, DominoRowState, ImpactResponse, ToppleFrameStats};
use topple::domino::{Preset, RowSpec};
use topple::validate::{row as check_row, EngineKind, Naming, RunBudget};

struct Args {
    preset: Preset,
    ideal: bool,
    spacing_ratio: f64,
    n: usize,
    push: f64,
    dt: f64,
    max_time: f64,
    native: bool,
    json: bool,
}

fn parse() -> Result<Args, String> {
    let mut a = Args {
        preset: Preset::X,
        ideal: false,
        spacing_ratio: 0.45,
        n: 40,
        push: 1.0,
        dt: 1.0 / 60.0,
        max_time: 20.0,
        native: false,
        json: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{flag} needs a value"));
        let number = |s: String| s.parse::<f64>().map_err(|e| format!("{flag}: {e}"));
        match flag.as_str() {
            "--preset" => a.preset = value()?.parse()?,
            "--ideal" => a.ideal = true,
            "--spacing-ratio" => a.spacing_ratio = number(value()?)?,
            "--n" => a.n = value()?.parse().map_err(|e| format!("--n: {e}"))?,
            "--push" => a.push = number(value()?)?,
            "--dt" => a.dt = number(value()?)?,
            "--max-time" => a.max_time = number(value()?)?,
            "--native" => a.native = true,
            "--json" => a.json = true,
            "--help" | "-h" => {
                println!("headless_row [--preset x|t|p] [--ideal] [--spacing-ratio S] [--n N] [--push P] [--dt DT] [--max-time T] [--native] [--json]");
                std::process::exit(0);
            }
            other => return Err(format!("unknown flag {other} (see --help)")),
        }
    }
    Ok(a)
}

fn run() -> Result<(), String> {
    let a = parse()?;
    let mut p = a.preset.params();
    if a.ideal {
        p = p.ideal();
    }
    let spec = RowSpec::new(p, a.spacing_ratio * p.block.height, a.n, a.push);
    let budget = RunBudget {
        engine: EngineKind::Rapier,
        dt: Some(a.dt),
        tolerance: None,
        max_time: Some(a.max_time),
        wall_limit: None,
    };
    check_row(&spec, &budget, Naming::Flags).map_err(|e| e.to_string())?;
    let row = DominoRow {
        physics: if a.native {
            ImpactResponse::Native
        } else {
            ImpactResponse::Topple
        },
        ..DominoRow::new(spec)
    };
    let start = std::time::Instant::now();
    let (mut app, id) = headless_row_app(&row, a.dt)?;
    let frames = (a.max_time / a.dt).ceil() as usize;
    let (mut impacts, mut fallbacks) = (0, 0);
    let mut last_hit = 0.0;
    for frame in 0..frames {
        app.update();
        let stats = app.world().resource::<ToppleFrameStats>();
        impacts += stats.impacts;
        fallbacks += stats.fallbacks;
        let state = app.world().get::<DominoRowState>(id).expect("the row");
        if state.finished() {
            break;
        }
        let t = (frame + 1) as f64 * a.dt;
        last_hit = state.hit_times().last().copied().unwrap_or(0.0);
        if t - last_hit > 2.0 {
            break; // the wave stopped
        }
    }
    let state = app.world().get::<DominoRowState>(id).expect("the row");
    let mut report = state.report();
    report.impacts = impacts as usize;
    report.impact_fallbacks = fallbacks as usize;
    report.stopped_early = !state.finished();
    report.simulated_time = state.hit_times().last().copied().unwrap_or(last_hit);
    report.run_time = start.elapsed().as_secs_f64();
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
        );
    } else {
        let v = report
            .natural_speed
            .map_or("n/a (row too short or the wave stopped)".into(), |v| {
                format!("{v:.4}")
            });
        println!(
            "{} s/h {} n {} dt {:.6}: blocks hit {}/{}, v̂_na {v}, impacts {}, {:.2} s",
            report.engine,
            a.spacing_ratio,
            a.n,
            a.dt,
            report.hit_times.len(),
            a.n,
            report.impacts,
            report.run_time
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
