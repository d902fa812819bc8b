//! `topple chain`: a row of dominoes through an engine; the wave speeds, energy
//! bookkeeping, time series and snapshots.

use std::path::PathBuf;

use anyhow::Context;

use topple::domino::{Ground, Preset, RowParams, RowSpec};
use topple::reference::{snapshot_png, snapshot_svg, Integrator, Settings};

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
    #[arg(long)]
    pub spacing_ratio: f64,
    /// Number of blocks.
    #[arg(long, default_value_t = 40)]
    pub n: usize,
    /// Dimensionless initial angular velocity of block 1, θ̇₁ √(h/g).
    #[arg(long, default_value_t = 1.0)]
    pub push: f64,
    /// Use the ideal material of Sec. 3.2 (μ1 = 0, e1 = 0, μ2 = 0.9, e2 = 0)
    /// before the overrides below.
    #[arg(long)]
    pub ideal: bool,
    /// Sliding friction between blocks (sets --mu1-stick too unless given).
    #[arg(long)]
    pub mu1: Option<f64>,
    /// Restitution between blocks.
    #[arg(long)]
    pub e1: Option<f64>,
    /// Sliding friction with the ground (sets --mu2-stick too unless given).
    #[arg(long)]
    pub mu2: Option<f64>,
    /// Restitution with the ground.
    #[arg(long)]
    pub e2: Option<f64>,
    /// Sticking friction between blocks.
    #[arg(long)]
    pub mu1_stick: Option<f64>,
    /// Sticking friction with the ground.
    #[arg(long)]
    pub mu2_stick: Option<f64>,
    /// Contact stiffness between blocks (N/m^α).
    #[arg(long)]
    pub k1: Option<f64>,
    /// Contact stiffness with the ground (N/m^α).
    #[arg(long)]
    pub k2: Option<f64>,
    /// Points under a standing block.
    #[arg(long)]
    pub lambda: Option<usize>,
    /// Exponent of the contact law.
    #[arg(long)]
    pub alpha: Option<f64>,
    /// Factor on the friction coefficients inside impacts (0.5 in the paper).
    #[arg(long)]
    pub impact_friction_factor: Option<f64>,
    /// Block height h (m).
    #[arg(long)]
    pub height: Option<f64>,
    /// Block thickness d (m).
    #[arg(long)]
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
    /// Accurate integration at this tolerance (adaptive Dormand–Prince;
    /// impacts keep the paper's impulse step) instead of the paper's improved
    /// Euler at --dt. With a Rapier engine: adaptive impulse stepping at this
    /// tolerance.
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Fixed time step of the paper's integration (s); with a Rapier engine,
    /// Rapier's time step.
    #[arg(long, default_value_t = 1e-4)]
    pub dt: f64,
    /// Rapier engines: impact window, the number of closed contacts from the
    /// struck pair beyond which bodies are left out of an impact.
    #[arg(long, default_value_t = topple::coupling::ToppleSettings::DEFAULT_WINDOW)]
    pub window: usize,
    /// Rapier engines: stop after this much simulated time (s) if the last
    /// block has not been hit.
    #[arg(long, default_value_t = 60.0)]
    pub max_time: f64,
    /// Freeze blocks behind the wave below this speed (fraction of √(gh)) and
    /// acceleration (fraction of g); 0 never freezes.
    #[arg(long)]
    pub freeze_tolerance: Option<f64>,
    /// Reference engine: make the heel of every block a contact on the front
    /// face of the block behind (no overlap where blocks slide back; about
    /// twice the run time, see README).
    #[arg(long)]
    pub heel_contacts: bool,
    /// Rapier engines: the Rapier build (f32 is what bevy_rapier2d uses).
    #[arg(long, value_enum, default_value_t = topple::rapier::Precision::F64)]
    pub precision: topple::rapier::Precision,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Record θ and θ̇ of these blocks (1-based, comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub series: Vec<usize>,
    /// Draw the row at these times (s) into --svg and/or --png.
    #[arg(long, value_delimiter = ',')]
    pub snapshots: Vec<f64>,
    /// SVG file for the snapshots.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// PNG file for the snapshots (same drawing, 4 px per mm, no labels).
    #[arg(long)]
    pub png: Option<PathBuf>,
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

/// The row to simulate.
pub fn row_spec(args: &RowArgs) -> anyhow::Result<RowSpec> {
    anyhow::ensure!(args.n >= 1, "--n must be at least 1");
    let p = params(args);
    Ok(RowSpec::new(
        p,
        args.spacing_ratio * p.block.height,
        args.n,
        args.push,
    ))
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let p = params(&args.row);
    let row = row_spec(&args.row)?;
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
    settings.heel_contacts = args.heel_contacts;
    settings.series_blocks = args.series.clone();
    settings.snapshot_times = args.snapshots.clone();
    let drawing = args.svg.is_some() || args.png.is_some();
    anyhow::ensure!(
        args.snapshots.is_empty() || drawing,
        "--snapshots needs --svg FILE or --png FILE to draw them into"
    );
    anyhow::ensure!(
        !drawing || !args.snapshots.is_empty(),
        "--svg and --png draw the times given by --snapshots T1,T2,…"
    );
    anyhow::ensure!(
        args.series.iter().all(|&b| b >= 1 && b <= row.n),
        "--series takes block numbers from 1 to {}",
        row.n
    );
    anyhow::ensure!(
        args.snapshots.iter().all(|t| t.is_finite() && *t >= 0.0),
        "--snapshots takes times in seconds, ≥ 0"
    );
    let rapier_engine = match args.engine {
        EngineArg::Reference => None,
        EngineArg::Rapier => Some(topple::rapier::scene::Engine::Rapier),
        EngineArg::RapierNative => Some(topple::rapier::scene::Engine::RapierNative),
    };
    if let Some(engine) = rapier_engine {
        anyhow::ensure!(
            !drawing && args.series.is_empty(),
            "--snapshots, --svg, --png and --series are for the reference engine"
        );
        anyhow::ensure!(
            args.dt > 0.0 && args.dt.is_finite(),
            "--dt must be a positive time step"
        );
        let solver = topple::rapier::scene::SolverSpec {
            dt: args.dt,
            tolerance: args.tolerance,
            max_group_hops: Some(args.window),
            ..Default::default()
        };
        let bar = super::blocks_bar(row.n, engine.name());
        let report = topple::rapier::scene::run_row(
            &row,
            engine,
            args.precision,
            solver,
            args.max_time,
            |hit| bar.set_position(hit as u64),
        );
        bar.finish_and_clear();
        let report = report?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            print_report(&report, args.row.spacing_ratio, &row);
            println!(
                "impacts {}, simulated {:.4} s in {:.3} s",
                report.impacts, report.simulated_time, report.run_time
            );
        }
        return Ok(());
    }
    let bar = super::blocks_bar(row.n, "reference");
    let out =
        topple::reference::run_with_progress(&row, &settings, |hit| bar.set_position(hit as u64));
    bar.finish_and_clear();
    let out = out?;
    if let Some(path) = &args.svg {
        let svg = snapshot_svg(&p.block, &out.snapshots, 0, row.n - 1);
        std::fs::write(path, svg).with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.png {
        let png = snapshot_png(&p.block, &out.snapshots, 0, row.n - 1, 4.0)
            .with_context(|| format!("encoding {}", path.display()))?;
        std::fs::write(path, png).with_context(|| format!("writing {}", path.display()))?;
    }
    let r = &out.report;
    if args.json {
        println!("{}", serde_json::to_string_pretty(r)?);
        return Ok(());
    }
    print_report(r, args.row.spacing_ratio, &row);
    println!(
        "impacts {} ({} with e = 0 contacts held, {} plastic fallbacks), max penetration {:.3e} m, blocks turning back: {:?}, simulated {:.4} s in {:.3} s ({} steps)",
        r.impacts,
        r.held_impacts,
        r.impact_fallbacks,
        r.max_penetration.unwrap_or(0.0),
        r.reversed_blocks,
        r.simulated_time,
        r.run_time,
        out.steps
    );
    for s in &r.series {
        println!("# series block {}: t, θ, θ̇", s.block);
        for k in 0..s.time.len() {
            println!("{:.6} {:.6} {:.6}", s.time[k], s.theta[k], s.theta_dot[k]);
        }
    }
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
    if let Some(e) = r.energy {
        println!(
            "energy (J): initial {:.6e}, kinetic {:.6e}, potential {:.6e}, impacts {:.6e}, friction {:.6e}, projection {:.3e}, frozen {:.3e}, residual {:.3e}",
            e.initial, e.kinetic, e.potential, e.impacts, e.friction, e.projection, e.frozen, e.residual
        );
    }
}
