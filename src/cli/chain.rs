//! `topple chain`: a row of dominoes through an engine; the wave speeds, energy
//! bookkeeping, time series and snapshots.

use std::path::PathBuf;

use anyhow::Context;

use topple::domino::{Ground, Preset, RowParams, RowSpec};
use topple::engines::{RapierRow, RowEngine};
use topple::impact::StepControl;
use topple::rapier::scene::{ImpactResponse, SolverSpec, WorkBudget};
use topple::reference::{snapshot_png, snapshot_svg, Integrator, Settings};
use topple::theory::{Geometry, Model, Outcome};
use topple::validate::{self, EngineKind, InputError, Naming, RunBudget};

/// Block type of Table 1.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum PresetArg {
    /// Domino X (plastic, Stronge 1987).
    X,
    /// Domino T (tufnol, Stronge & Shu 1988).
    T,
    /// Domino P (perspex, Stronge & Shu 1988).
    P,
}

impl From<PresetArg> for Preset {
    fn from(p: PresetArg) -> Preset {
        match p {
            PresetArg::X => Preset::X,
            PresetArg::T => Preset::T,
            PresetArg::P => Preset::P,
        }
    }
}

/// Simulation engine.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum EngineArg {
    /// The paper's reduced-coordinate model (src/reference).
    #[default]
    Reference,
    /// The row as a rapier2d-f64 world with topple's impacts.
    Rapier,
    /// The same world with Rapier's own impact response.
    RapierNative,
}

/// The row: preset, spacing, length, push and material overrides (shared by
/// `topple chain` and `topple bench`).
#[derive(clap::Args, Debug, Clone)]
pub struct RowArgs {
    /// Block type (Table 1); case-insensitive (X, T, P as in the paper).
    #[arg(long, value_enum, ignore_case = true, default_value = "x")]
    pub preset: PresetArg,
    /// Gap over height, s/h.
    #[arg(long, allow_hyphen_values = true)]
    pub spacing_ratio: f64,
    /// Number of blocks.
    #[arg(long, default_value_t = 40)]
    pub n: usize,
    /// Dimensionless initial angular velocity of block 1, θ̇₁ √(h/g).
    #[arg(long, allow_hyphen_values = true, default_value_t = 1.0)]
    pub push: f64,
    /// Use the ideal material of Sec. 3.2 (μ1 = 0, e1 = 0, μ2 = 0.9, e2 = 0)
    /// before the overrides below.
    #[arg(long)]
    pub ideal: bool,
    /// Sliding friction between blocks (sets --mu1-stick too unless given).
    #[arg(long, allow_hyphen_values = true)]
    pub mu1: Option<f64>,
    /// Restitution between blocks.
    #[arg(long, allow_hyphen_values = true)]
    pub e1: Option<f64>,
    /// Sliding friction with the ground (sets --mu2-stick too unless given).
    #[arg(long, allow_hyphen_values = true)]
    pub mu2: Option<f64>,
    /// Restitution with the ground.
    #[arg(long, allow_hyphen_values = true)]
    pub e2: Option<f64>,
    /// Sticking friction between blocks.
    #[arg(long, allow_hyphen_values = true)]
    pub mu1_stick: Option<f64>,
    /// Sticking friction with the ground.
    #[arg(long, allow_hyphen_values = true)]
    pub mu2_stick: Option<f64>,
    /// Contact stiffness between blocks (N/m^α).
    #[arg(long, allow_hyphen_values = true)]
    pub k1: Option<f64>,
    /// Contact stiffness with the ground (N/m^α).
    #[arg(long, allow_hyphen_values = true)]
    pub k2: Option<f64>,
    /// Points under a standing block.
    #[arg(long)]
    pub lambda: Option<usize>,
    /// Exponent of the contact law.
    #[arg(long, allow_hyphen_values = true)]
    pub alpha: Option<f64>,
    /// Factor on the friction coefficients inside impacts (0.5 in the paper).
    #[arg(long, allow_hyphen_values = true)]
    pub impact_friction_factor: Option<f64>,
    /// Block height h (m).
    #[arg(long, allow_hyphen_values = true)]
    pub height: Option<f64>,
    /// Block thickness d (m).
    #[arg(long, allow_hyphen_values = true)]
    pub thickness: Option<f64>,
    /// The ground under the feet: `coulomb` (the paper: μ2, halved inside
    /// impacts) or `no-slip` (pivots that never slide, the cooperative
    /// model's assumption).
    #[arg(long, default_value = "coulomb", value_parser = parse_ground)]
    pub ground: Ground,
}

fn parse_ground(s: &str) -> Result<Ground, String> {
    s.parse()
}

/// Arguments of `topple chain`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The row.
    #[command(flatten)]
    pub row: RowArgs,
    /// Engine.
    #[arg(long, value_enum, default_value = "reference")]
    pub engine: EngineArg,
    /// Accurate integration at this tolerance (adaptive Dormand–Prince)
    /// instead of the paper's improved Euler at --dt. With a Rapier engine:
    /// the impacts' tolerance (the time-domain resolver, docs/model.md §7).
    #[arg(long, allow_hyphen_values = true)]
    pub tolerance: Option<f64>,
    /// Fixed time step of the paper's integration (s); with a Rapier engine,
    /// Rapier's time step.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1e-4)]
    pub dt: f64,
    /// Rapier engines: impact window, the number of closed contacts from the
    /// struck pair beyond which bodies are left out of an impact.
    #[arg(long, default_value_t = topple::coupling::ToppleSettings::DEFAULT_WINDOW)]
    pub window: usize,
    /// Rapier engines: an impact ends once what is left of it is slower
    /// than this fraction of the impact threshold (default 0.01; 0: every
    /// impact runs to its end; docs/model.md §9).
    #[arg(long, allow_hyphen_values = true)]
    pub rest_fraction: Option<f64>,
    /// Rapier engines: stop after this much simulated time (s) if the last
    /// block has not been hit.
    #[arg(long, allow_hyphen_values = true, default_value_t = 60.0)]
    pub max_time: f64,
    /// Freeze blocks behind the wave below this speed (fraction of √(gh)) and
    /// acceleration (fraction of g); default 10⁻², 0 never freezes.
    #[arg(long, allow_hyphen_values = true)]
    pub freeze_tolerance: Option<f64>,
    /// Reference engine: impacts with the paper's fixed impulse step
    /// ΔP = STEP · P₀ (the paper: 10⁻⁴) instead of the time-domain
    /// resolver.
    #[arg(long, allow_hyphen_values = true)]
    pub impact_step: Option<f64>,
    /// Reference engine: the tolerance of the time-domain impact resolver
    /// (default 2·10⁻⁶, docs/model.md §7).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "impact_step")]
    pub impact_tolerance: Option<f64>,
    /// Reference engine: make the heel of every block a contact on the front
    /// face of the block behind (no overlap where blocks slide back; about
    /// twice the run time).
    #[arg(long)]
    pub heel_contacts: bool,
    /// Rapier engines: the Rapier build (f32 is what bevy_rapier2d uses).
    #[arg(long, value_enum, default_value_t = topple::rapier::Precision::F64)]
    pub precision: topple::rapier::Precision,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Record θ and θ̇ of these blocks (1-based, comma-separated) into
    /// --series-csv.
    #[arg(long, value_delimiter = ',')]
    pub series: Vec<usize>,
    /// CSV file for --series: block, t (s), θ (rad), θ̇ (rad/s), one row per
    /// recorded step (clockwise positive, the paper's sign).
    #[arg(long)]
    pub series_csv: Option<PathBuf>,
    /// Draw the row at these times (s) into --svg and/or --png.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',')]
    pub snapshots: Vec<f64>,
    /// SVG file for the snapshots.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// PNG file for the snapshots (same drawing, 4 px per mm, no labels).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Reference engine: stop after this much wall-clock time (s), print what
    /// was measured and exit with status 1.
    #[arg(long, allow_hyphen_values = true, default_value_t = 3600.0)]
    pub wall_limit: f64,
}

/// Row parameters from a preset and the overrides.
pub fn params(args: &RowArgs) -> RowParams {
    let mut p = Preset::from(args.preset).params();
    if args.ideal {
        p = p.ideal();
    }
    if let Some(v) = args.height {
        p.block.height = v;
    }
    if let Some(v) = args.thickness {
        p.block.thickness = v;
    }
    if let Some(v) = args.mu1 {
        p.mu1 = v;
        p.mu1_stick = args.mu1_stick.unwrap_or(v);
    }
    if let Some(v) = args.mu1_stick {
        p.mu1_stick = v;
    }
    if let Some(v) = args.mu2 {
        p.mu2 = v;
        p.mu2_stick = args.mu2_stick.unwrap_or(v);
    }
    if let Some(v) = args.mu2_stick {
        p.mu2_stick = v;
    }
    if let Some(v) = args.e1 {
        p.e1 = v;
    }
    if let Some(v) = args.e2 {
        p.e2 = v;
    }
    if let Some(v) = args.k1 {
        p.k1 = v;
    }
    if let Some(v) = args.k2 {
        p.k2 = v;
    }
    if let Some(v) = args.lambda {
        p.lambda_points = v;
    }
    if let Some(v) = args.impact_friction_factor {
        p.impact_friction_factor = v;
    }
    if let Some(v) = args.alpha {
        p.alpha = v;
    }
    p.ground = args.ground;
    p
}

/// The row to simulate, checked against the limits of `docs/input-limits.md`
/// for the engine and budget given (a reference run without a time step if
/// `budget` is `None`).
pub fn row_spec(args: &RowArgs, budget: Option<RunBudget>) -> anyhow::Result<RowSpec> {
    let p = params(args);
    let row = RowSpec::new(p, args.spacing_ratio * p.block.height, args.n, args.push);
    let budget = budget.unwrap_or(RunBudget {
        engine: EngineKind::Reference,
        dt: None,
        tolerance: None,
        max_time: None,
        wall_limit: None,
    });
    validate::row(&row, &budget, Naming::Flags)?;
    Ok(row)
}

/// Every flag in its range before anything runs (`docs/input-limits.md`).
fn check_args(args: &Args) -> anyhow::Result<RowSpec> {
    let engine = match args.engine {
        EngineArg::Reference => EngineKind::Reference,
        EngineArg::Rapier | EngineArg::RapierNative => EngineKind::Rapier,
    };
    let rapier = engine == EngineKind::Rapier;
    let row = row_spec(
        &args.row,
        Some(RunBudget {
            engine,
            dt: Some(args.dt),
            tolerance: args.tolerance,
            max_time: rapier.then_some(args.max_time),
            wall_limit: Some(args.wall_limit),
        }),
    )?;
    validate::check_count("--window", args.window, 1, 1_000_000)?;
    if let Some(f) = args.rest_fraction {
        validate::check_range("--rest-fraction", f, 0.0, 1.0)?;
    }
    if let Some(f) = args.freeze_tolerance {
        validate::check_range("--freeze-tolerance", f, 0.0, 1.0)?;
    }
    validate::impact_stepping(args.impact_step, args.impact_tolerance)?;
    if rapier && (args.impact_step.is_some() || args.impact_tolerance.is_some()) {
        Err(InputError::new(
            "--impact-step/--impact-tolerance",
            "given with a Rapier engine",
            "with --engine reference only (Rapier engines: --tolerance)",
        ))?;
    }
    let drawing = args.svg.is_some() || args.png.is_some();
    if !args.snapshots.is_empty() && !drawing {
        Err(InputError::new(
            "--snapshots",
            "given without a file",
            "with --svg FILE or --png FILE",
        ))?;
    }
    if drawing && args.snapshots.is_empty() {
        Err(InputError::new(
            "--svg/--png",
            "given without times",
            "with --snapshots T1,T2,…",
        ))?;
    }
    if let Some(&b) = args.series.iter().find(|&&b| b < 1 || b > row.n) {
        Err(InputError::new(
            "--series",
            b,
            format!("block numbers 1 ≤ --series ≤ {}", row.n),
        ))?;
    }
    for &t in &args.snapshots {
        validate::check_range("--snapshots", t, 0.0, 1e6)?;
    }
    if rapier && (drawing || !args.series.is_empty()) {
        Err(InputError::new(
            "--snapshots/--svg/--png/--series",
            "given with a Rapier engine",
            "with --engine reference only",
        ))?;
    }
    if args.series.is_empty() != args.series_csv.is_none() {
        Err(InputError::new(
            "--series/--series-csv",
            "given alone",
            "together: --series BLOCKS --series-csv FILE",
        ))?;
    }
    Ok(row)
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let row = check_args(&args)?;
    match args.engine {
        EngineArg::Reference => run_reference(&args, &row),
        EngineArg::Rapier => run_rapier(&args, &row, ImpactResponse::Topple),
        EngineArg::RapierNative => run_rapier(&args, &row, ImpactResponse::Native),
    }
}

/// The reference engine's settings from the command line.
fn reference_settings(args: &Args) -> Settings {
    let mut settings = match args.tolerance {
        Some(tol) => Settings::accurate(tol),
        None => Settings {
            integrator: Integrator::Paper { dt: args.dt },
            ..Default::default()
        },
    };
    if let Some(f) = args.freeze_tolerance {
        settings.freeze_tolerance = f;
    }
    if let Some(impulse_step) = args.impact_step {
        settings.impact.step_control = StepControl::Fixed { impulse_step };
    }
    if let Some(tolerance) = args.impact_tolerance {
        settings.impact.step_control = StepControl::Adaptive { tolerance };
    }
    settings.heel_contacts = args.heel_contacts;
    settings.series_blocks = args.series.clone();
    settings.snapshot_times = args.snapshots.clone();
    settings.wall_time_limit = Some(args.wall_limit);
    settings
}

/// A row through Rapier, with topple or natively.
fn run_rapier(args: &Args, row: &RowSpec, engine: ImpactResponse) -> anyhow::Result<()> {
    let rapier = RapierRow {
        engine,
        precision: args.precision,
        solver: SolverSpec {
            dt: args.dt,
            tolerance: args.tolerance,
            max_group_hops: Some(args.window),
            rest_fraction: args.rest_fraction,
            // an accuracy run: every impact to its end, no step budget
            max_work: WorkBudget::Unbounded,
            ..Default::default()
        },
        max_time: args.max_time,
    };
    let bar = super::blocks_bar(row.n, engine.name());
    let report = rapier.run(row, &mut |hit| bar.set_position(hit as u64));
    bar.finish_and_clear();
    let report = report?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_report(&report, args.row.spacing_ratio, row);
        println!(
            "impacts {}, simulated {:.4} s in {:.3} s",
            report.impacts, report.simulated_time, report.run_time
        );
    }
    Ok(())
}

/// A row through the reference engine, with its drawings and series (which
/// only this engine records, so it is called directly rather than through
/// [`RowEngine`]).
fn run_reference(args: &Args, row: &RowSpec) -> anyhow::Result<()> {
    let settings = reference_settings(args);
    let p = row.params;
    let bar = super::blocks_bar(row.n, "reference");
    let out =
        topple::reference::run_with_progress(row, &settings, |hit| bar.set_position(hit as u64));
    bar.finish_and_clear();
    let out = out?;
    if let Some(path) = &args.svg {
        let svg = snapshot_svg(&p.block, &out.snapshots, 0, row.n - 1);
        topple::atomic::write(path, svg.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.png {
        let png = snapshot_png(&p.block, &out.snapshots, 0, row.n - 1, 4.0)
            .with_context(|| format!("encoding {}", path.display()))?;
        topple::atomic::write(path, &png).with_context(|| format!("writing {}", path.display()))?;
    }
    let r = &out.report;
    if let Some(path) = &args.series_csv {
        topple::atomic::write(path, series_csv(&r.series).as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(r)?);
        return budget_end(r, row, args.wall_limit);
    }
    print_report(r, args.row.spacing_ratio, row);
    println!(
        "impacts {} ({} with e = 0 contacts held, {} plastic fallbacks), max penetration {:.3e} m, blocks turning back: {}, simulated {:.4} s in {:.3} s ({} steps)",
        r.impacts,
        r.held_impacts,
        r.impact_fallbacks,
        r.max_penetration.unwrap_or(0.0),
        block_ranges(&r.reversed_blocks),
        r.simulated_time,
        r.run_time,
        out.steps
    );
    budget_end(r, row, args.wall_limit)
}

/// Ranges of consecutive blocks shown before the rest is summed up.
const RANGES_SHOWN: usize = 8;

/// A set of block indices for a person to read: their count and their runs
/// of consecutive indices, "999 blocks (1–999)", "4 blocks (2, 5–7)",
/// "none"; past [`RANGES_SHOWN`] runs the rest is counted, not listed
/// (`--json` keeps the full list).
fn block_ranges(blocks: &[usize]) -> String {
    let mut sorted = blocks.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    let Some(&first) = sorted.first() else {
        return "none".to_string();
    };
    let mut runs: Vec<(usize, usize)> = vec![(first, first)];
    for &b in &sorted[1..] {
        match runs.last_mut() {
            Some(run) if b == run.1 + 1 => run.1 = b,
            _ => runs.push((b, b)),
        }
    }
    let shown: Vec<String> = runs
        .iter()
        .take(RANGES_SHOWN)
        .map(|&(a, b)| {
            if a == b {
                a.to_string()
            } else {
                format!("{a}–{b}")
            }
        })
        .collect();
    let more = match runs.len().saturating_sub(RANGES_SHOWN) {
        0 => String::new(),
        k => format!(" and {k} more ranges"),
    };
    let noun = if sorted.len() == 1 { "block" } else { "blocks" };
    format!("{} {noun} ({}{more})", sorted.len(), shown.join(", "))
}

/// The θ, θ̇ series of `topple chain --series` as CSV.
fn series_csv(series: &[topple::domino::BlockSeries]) -> String {
    let mut csv = String::from("block,t_s,theta_rad,theta_dot_rad_per_s\n");
    for s in series {
        for k in 0..s.time.len() {
            csv.push_str(&format!(
                "{},{:.9},{:.9},{:.9}\n",
                s.block, s.time[k], s.theta[k], s.theta_dot[k]
            ));
        }
    }
    csv
}

/// A reference run that hit its wall-clock budget: what it measured is
/// printed; the command then fails with that budget named.
fn budget_end(r: &topple::domino::ChainReport, row: &RowSpec, limit: f64) -> anyhow::Result<()> {
    anyhow::ensure!(
        !r.stopped_early,
        "stopped by its budget, --wall-limit {limit} s, after {} of {} blocks were hit (their measures are printed above)",
        r.hit_times.len(),
        row.n
    );
    Ok(())
}

/// The text report shared by every engine.
fn print_report(r: &topple::domino::ChainReport, spacing_ratio: f64, row: &RowSpec) {
    println!(
        "engine {}  s/h = {}  n = {}  push = {}",
        r.engine, spacing_ratio, row.n, row.push
    );
    println!("block  hit time (s)   t_i (s)     v̂_i");
    for (i, t) in r.hit_times.iter().enumerate() {
        match (r.intervals.get(i), r.speeds.get(i)) {
            (Some(ti), Some(v)) => println!("{:5}  {:12.6}  {:10.6}  {:8.4}", i + 1, t, ti, v),
            _ => println!("{:5}  {:12.6}", i + 1, t),
        }
    }
    match r.natural_speed_spread {
        Some(s) => println!(
            "natural speed v̂_na = {:.4} ± {:.4} (min {:.4}, max {:.4}, {} blocks)",
            s.mean, s.std_dev, s.min, s.max, s.count
        ),
        None => println!("natural speed: the wave stopped before block 8"),
    }
    println!("{}", theory_line(&row.params, spacing_ratio));
    if let Some(e) = r.energy {
        println!(
            "energy (J): initial {:.6e}, kinetic {:.6e}, potential {:.6e}, impacts {:.6e}, friction {:.6e}, projection {:.3e}, frozen {:.3e}, residual {:.3e}",
            e.initial, e.kinetic, e.potential, e.impacts, e.friction, e.projection, e.frozen, e.residual
        );
    }
}

/// The theory model whose assumptions the row's material meets
/// (docs/theory.md): the group models need collisions that keep the blocks
/// leaning on each other (e1 = 0), the cooperative one frictionless contacts
/// between blocks (μ1 = 0), the extended one adds μ1; with e1 > 0 only the
/// single collision model (μ1, e1) holds.
pub fn theory_model(p: &RowParams) -> (Model, &'static str) {
    if p.e1 == 0.0 && p.mu1 == 0.0 {
        (Model::Cooperative, "mu1 = 0, e1 = 0")
    } else if p.e1 == 0.0 {
        (Model::Extended { mu: p.mu1 }, "e1 = 0, mu1 > 0")
    } else {
        (
            Model::Single { mu: p.mu1, e: p.e1 },
            "e1 > 0: the group models assume e1 = 0",
        )
    }
}

/// The line of the text report that gives the theory's natural speed v̂_na
/// for the row's d/h and s/h, from the model [`theory_model`] picks.
fn theory_line(p: &RowParams, spacing_ratio: f64) -> String {
    let (model, why) = theory_model(p);
    let outcome = Geometry::new(p.block.thickness / p.block.height, spacing_ratio)
        .and_then(|g| topple::theory::solve(&model, &g));
    match outcome {
        Ok(Outcome::Wave(w)) => format!(
            "theory: v̂_na = {:.4} ({} model, {why})",
            w.natural_speed,
            model.name()
        ),
        Ok(Outcome::NoWave(reason)) => {
            format!("theory: no wave ({} model, {why}): {reason}", model.name())
        }
        Err(e) => format!("theory: not solved ({} model, {why}): {e}", model.name()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_ranges_count_and_join_consecutive_blocks() {
        let row: Vec<usize> = (1..1000).collect();
        assert_eq!(block_ranges(&row), "999 blocks (1–999)");
        assert_eq!(block_ranges(&[]), "none");
        assert_eq!(block_ranges(&[7]), "1 block (7)");
        assert_eq!(block_ranges(&[9, 2, 5, 6, 7, 6]), "5 blocks (2, 5–7, 9)");
        // every other block: 20 runs of one, 8 listed
        let sparse: Vec<usize> = (0..20).map(|k| 2 * k).collect();
        assert_eq!(
            block_ranges(&sparse),
            "20 blocks (0, 2, 4, 6, 8, 10, 12, 14 and 12 more ranges)"
        );
    }

    #[test]
    fn theory_picks_the_model_whose_assumptions_hold() {
        let ideal = Preset::T.params().ideal();
        assert_eq!(theory_model(&ideal).0, Model::Cooperative);
        let mut rough = ideal;
        rough.mu1 = 0.2;
        assert_eq!(theory_model(&rough).0, Model::Extended { mu: 0.2 });
        rough.e1 = 0.6;
        assert_eq!(theory_model(&rough).0, Model::Single { mu: 0.2, e: 0.6 });
    }

    #[test]
    fn theory_line_is_the_cooperative_speed_of_van_leeuwens_example() {
        // docs/theory.md: h = 48 mm, d = 7.5 mm, λ = 16 mm, g = 9.8 m/s²
        // give 1.380 m/s in the cooperative model
        let mut p = Preset::T.params().ideal();
        p.block.height = 0.048;
        p.block.thickness = 0.0075;
        let v = 1.380 / (9.8f64 * 0.048).sqrt();
        let line = theory_line(&p, (0.016 - 0.0075) / 0.048);
        let printed: f64 = line["theory: v̂_na = ".len()..][..6].parse().unwrap();
        assert!(
            (printed - v).abs() < 0.005 / (9.8f64 * 0.048).sqrt() + 1e-4,
            "{line}"
        );
        assert!(line.contains("cooperative model"), "{line}");
        assert!(theory_line(&p, 1.2).contains("no wave"));
    }
}
