//! `topple paper --out DIR`: regenerates the paper's Figs. 3–10 (and
//! `fig5_ground`) with the reference engine, as CSV files and SVG plots.
//!
//! | step | file |
//! | --- | --- |
//! | flags checked, base settings | `mod.rs` |
//! | the runs of each figure | `jobs.rs` |
//! | runs in parallel (rayon), progress bar, saved for `--resume` | `run.rs` |
//! | CSV and SVG of each figure | `figures.rs` |

mod figures;
mod jobs;
mod run;

use std::path::PathBuf;

use anyhow::Context;
use topple::impact::StepControl;
use topple::reference::{Integrator, Settings};
use topple::validate::{self, EngineKind, InputError};

use crate::cli::resume::RunStore;
use figures::{fig4_lines, fig5_lines, ground_lines, Figures};
use jobs::{Plan, GROUND_FIG};

/// Arguments of `topple paper`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Blocks per row in the sweeps.
    #[arg(long, default_value_t = 40)]
    pub n: usize,
    /// Only these figures (3..=10); all by default.
    #[arg(long, value_delimiter = ',')]
    pub figs: Vec<u32>,
    /// Accurate integration at this tolerance instead of the paper's.
    #[arg(long, allow_hyphen_values = true)]
    pub tolerance: Option<f64>,
    /// Spacing ratios s/h of the sweeps of Figs. 4 and 5 (default 0.1 to 0.6
    /// in steps of 0.05).
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',')]
    pub spacings: Vec<f64>,
    /// The tolerance of the time-domain impact resolver (default 2·10⁻⁶,
    /// docs/model.md §7).
    #[arg(long)]
    pub impact_tolerance: Option<f64>,
    /// Impacts with the paper's fixed impulse step ΔP = STEP · P₀ (the
    /// paper: 10⁻⁴) instead of the time-domain resolver.
    #[arg(long, conflicts_with = "impact_tolerance")]
    pub impact_step: Option<f64>,
    /// Wall-clock limit per run (s); a run that hits it keeps the blocks it
    /// measured and is reported on stderr.
    #[arg(long, allow_hyphen_values = true, default_value_t = 120.0)]
    pub run_limit: f64,
    /// Reuse the runs an earlier (interrupted) call saved in OUT/runs/ when
    /// their row and settings match exactly; every finished run is saved
    /// there as it ends.
    #[arg(long)]
    pub resume: bool,
}

/// Every flag in its range before anything runs (`docs/input-limits.md`).
fn check_args(args: &Args) -> Result<(), InputError> {
    validate::check_count("--n", args.n, 2, 100_000)?;
    validate::check_memory("--n", args.n, EngineKind::Reference, None)?;
    if let Some(&f) = args.figs.iter().find(|f| !(3..=10).contains(*f)) {
        return Err(InputError::new(
            "--figs",
            f,
            "figure numbers 3 ≤ --figs ≤ 10",
        ));
    }
    if let Some(t) = args.tolerance {
        validate::check_range("--tolerance", t, 1e-12, 1e-3)?;
    }
    for &sh in &args.spacings {
        validate::check_open_low("--spacings", sh, 0.0, 0.999)?;
    }
    validate::check_open_low("--run-limit", args.run_limit, 0.0, 1e7)?;
    validate::impact_stepping(args.impact_step, args.impact_tolerance)?;
    Ok(())
}

/// The paper's integration (fixed Δt = 10⁻⁴ s, `docs/model.md`) or the
/// accurate one at `--tolerance`, with the run limit and impact stepping.
fn base_settings(args: &Args) -> Settings {
    let mut base = match args.tolerance {
        Some(t) => Settings::accurate(t),
        None => Settings {
            integrator: Integrator::Paper { dt: 1e-4 },
            ..Default::default()
        },
    };
    base.wall_time_limit = Some(args.run_limit);
    if let Some(tolerance) = args.impact_tolerance {
        base.impact.step_control = StepControl::Adaptive { tolerance };
    }
    if let Some(impulse_step) = args.impact_step {
        base.impact.step_control = StepControl::Fixed { impulse_step };
    }
    base
}

/// The spacings s/h of the sweeps: `--spacings`, or 0.1 to 0.6 in steps of 0.05.
fn spacings(args: &Args) -> Vec<f64> {
    if args.spacings.is_empty() {
        (0..11).map(|k| (1.0 + 0.5 * k as f64) / 10.0).collect()
    } else {
        args.spacings.clone()
    }
}

pub fn run_cmd(args: Args) -> anyhow::Result<()> {
    check_args(&args)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let want = |f: u32| args.figs.is_empty() || args.figs.contains(&f);
    let base = base_settings(&args);
    let spacings = spacings(&args);
    let plan = Plan {
        n: args.n,
        spacings: &spacings,
        base: &base,
    };
    let jobs = plan.jobs(want);
    let results = run::run_jobs(&jobs, &RunStore::new(&args.out), args.resume);
    run::warn_incomplete(&jobs, &results);
    let figures = Figures {
        jobs: &jobs,
        results: &results,
        out: &args.out,
    };
    write_figures(&figures, want)?;
    println!("wrote figures to {}", args.out.display());
    Ok(())
}

/// Every wanted figure from the finished runs.
fn write_figures(f: &Figures, want: impl Fn(u32) -> bool) -> anyhow::Result<()> {
    if want(3) {
        f.along(3, "Fig. 3: Domino X, Table 1, s/h = 0.18")?;
    }
    if want(4) {
        let title = "Fig. 4: Domino T and P, Table 1";
        f.sweep((4, "", "fig4"), title, "s/h", &fig4_lines())?;
    }
    if want(5) {
        let title = "Fig. 5: Domino T, mu2 = 0.9, e2 = 0";
        f.sweep((5, "", "fig5"), title, "s/h", &fig5_lines())?;
        let title = "Ideal Domino T (mu2 = 0.9, e1 = e2 = 0): the ground law";
        f.sweep(
            (GROUND_FIG, "", "fig5_ground"),
            title,
            "s/h",
            &ground_lines(),
        )?;
    }
    if want(6) {
        f.snapshots()?;
    }
    if want(7) {
        f.series()?;
    }
    if want(8) {
        f.along(8, "Fig. 8: Domino X, s/h = 0.52, pushes 0.5/1.0/1.8")?;
    }
    if want(9) {
        f.sweep(
            (9, "a", "fig9a"),
            "Fig. 9a: X, mu2 = 0.9, e1 = e2 = 0",
            "mu1",
            &[],
        )?;
        f.sweep(
            (9, "b", "fig9b"),
            "Fig. 9b: X, mu2 = 0.9, mu1 = e2 = 0",
            "e1",
            &[],
        )?;
    }
    if want(10) {
        f.sweep(
            (10, "a", "fig10a"),
            "Fig. 10a: X, mu1 = e1 = e2 = 0",
            "mu2",
            &[],
        )?;
        f.sweep(
            (10, "b", "fig10b"),
            "Fig. 10b: X, mu2 = 0.9, mu1 = e1 = 0",
            "e2",
            &[],
        )?;
    }
    Ok(())
}
