//! `topple bench`: run time against accuracy for one domino row, over engines
//! and their settings, measured in one invocation so that the ratios compare
//! runs on the same machine under the same load.
//!
//! Each run is given as `ENGINE:SETTING…`:
//!
//! | run | meaning |
//! | --- | --- |
//! | `reference:paper` | reference engine, the paper's improved Euler at 10⁻⁴ s, impacts at the resolver's default (time-domain, 2·10⁻⁶) |
//! | `reference:paper:DT` | the same at time step DT (s) |
//! | `reference:TOL` | reference engine, adaptive Dormand–Prince at tolerance TOL |
//! | `reference:…:imp:TOL` | either of the above with adaptive impulse stepping at TOL |
//! | `reference:…:imp:time-TOL` | either of the above with the time-domain resolver at TOL (docs/model.md §7) |
//! | `reference:…:imp:fixed` | either of the above with the paper's fixed impulse step ΔP = 10⁻⁴ P₀ |
//! | `rapier:DT` | Rapier with topple at its default settings, time step DT (s) |
//! | `rapier:DT:STEP` | Rapier with topple, time step DT (s), fixed impulse step ΔP/P₀ = STEP |
//! | `rapier:DT:tol:TOL` | Rapier with topple, impacts at tolerance TOL |
//! | `native:DT` | Rapier's own impact response, time step DT (s) |
//!
//! A Rapier run (`rapier…`, `native…`) may end in `:f32` or `:f64` to choose
//! the Rapier build; otherwise `--precision` chooses it (default f64).
//!
//! Every finished run's report is written to `--out DIR` as JSON; a later call
//! with the same DIR, row and engine settings reuses the saved reports instead
//! of running them again (so a long table can be built in several sittings).
//! The error of v̂_na is taken against the `--baseline` run (by default the
//! reference run with the smallest tolerance, else the reference run with the
//! smallest time step; among those, the tightest impulse stepping).
//! `--plot FILE` draws the table as a work-precision plot (SVG). Columns besides run time and v̂_na: blocks hit; "out
//! of order", intervals t_i ≤ 0 (then v̂_na is infinite and shown as none);
//! "front v̂", the front's distance over time from block 7 to the last block
//! hit over √(gh), robust to such bunches, with its own error; Rapier's wall
//! time per step and its ratio to the native run at the same step.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context};

use super::chain::{row_spec, RowArgs};
use topple::domino::{ChainReport, RowSpec};
use topple::engines::{RapierRow, ReferenceRow, RowEngine};
use topple::impact::StepControl;
use topple::rapier::scene::{ImpactResponse, SolverSpec, WorkBudget};
use topple::rapier::Precision;
use topple::reference::{Integrator, Settings};

/// Arguments of `topple bench`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The row.
    #[command(flatten)]
    pub row: RowArgs,
    /// Runs (see the module table), comma-separated, e.g.
    /// `reference:paper,reference:1e-8,rapier:1e-3:1e-4,native:1e-3`.
    #[arg(long, value_delimiter = ',', required = true)]
    pub runs: Vec<String>,
    /// The run the v̂_na errors are measured against (one of --runs).
    #[arg(long)]
    pub baseline: Option<String>,
    /// Directory for the run reports (JSON); saved reports of the same row are
    /// reused.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Rapier engines: impact window (closed contacts from the struck pair).
    #[arg(long, default_value_t = topple::coupling::ToppleSettings::DEFAULT_WINDOW)]
    pub window: usize,
    /// Reference runs: freeze blocks behind the wave below this speed
    /// (fraction of √(gh)) and acceleration (fraction of g); default 10⁻².
    /// Below 10⁻², rows whose blocks keep bouncing behind the wave
    /// (Table 1's e1, e2) cost more than linearly in the number of blocks.
    #[arg(long, allow_hyphen_values = true)]
    pub freeze_tolerance: Option<f64>,
    /// Rapier engines: stop after this much simulated time (s).
    #[arg(long, allow_hyphen_values = true, default_value_t = 600.0)]
    pub max_time: f64,
    /// Rapier build of the Rapier runs that do not end in `:f32` or `:f64`.
    #[arg(long, value_enum, default_value_t = Precision::F64)]
    pub precision: Precision,
    /// Also write the work-precision plot (SVG): log₁₀ run time against
    /// log₁₀ of the v̂_na error of every run but the baseline, one series per
    /// engine.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// One parsed run.
#[derive(Clone, Debug, PartialEq)]
enum RunKind {
    /// The reference engine with this smooth integration and impulse
    /// stepping (`None`: the default, `…:imp:TOL` / `…:imp:fixed`: given).
    Reference(Integrator, Option<StepControl>),
    /// The Rapier plugin, topple resolving the impacts or native Rapier
    /// (`response`), with the resolver's settings of a topple run.
    Rapier {
        response: ImpactResponse,
        dt: f64,
        impulse_step: Option<f64>,
        tolerance: Option<f64>,
        precision: Precision,
    },
}

impl RunKind {
    /// Native Rapier at step `dt` in build `precision`.
    fn native(dt: f64, precision: Precision) -> Self {
        RunKind::Rapier {
            response: ImpactResponse::Native,
            dt,
            impulse_step: None,
            tolerance: None,
            precision,
        }
    }
}

fn number(text: &str, what: &str, run: &str) -> anyhow::Result<f64> {
    let v: f64 = text
        .parse()
        .with_context(|| format!("run {run:?}: {what} {text:?} is not a number"))?;
    if !(v.is_finite() && v > 0.0) {
        bail!("run {run:?}: {what} must be positive and finite, got {text}");
    }
    Ok(v)
}

/// Parses one run; `default` is the Rapier build of a Rapier run that does
/// not name one.
fn parse_run(run: &str, default: Precision) -> anyhow::Result<RunKind> {
    let mut parts: Vec<&str> = run.split(':').collect();
    let named = match parts.last() {
        Some(&"f32") if parts.len() > 2 => Some(Precision::F32),
        Some(&"f64") if parts.len() > 2 => Some(Precision::F64),
        _ => None,
    };
    if named.is_some() {
        parts.pop();
    }
    let precision = named.unwrap_or(default);
    if let ["reference", head @ .., "imp", stepping] = parts.as_slice()
        && !head.is_empty()
    {
        let smooth = format!("reference:{}", head.join(":"));
        let control = if *stepping == "fixed" {
            StepControl::paper()
        } else if let Some(tol) = stepping.strip_prefix("time-") {
            StepControl::Adaptive {
                tolerance: number(tol, "impact tolerance", run)?,
            }
        } else {
            StepControl::AdaptiveImpulse {
                tolerance: number(stepping, "impact tolerance", run)?,
            }
        };
        if let RunKind::Reference(integrator, None) = parse_run(&smooth, default)? {
            return Ok(RunKind::Reference(integrator, Some(control)));
        }
    }
    Ok(match parts.as_slice() {
        ["reference", "paper"] => RunKind::Reference(Integrator::Paper { dt: 1e-4 }, None),
        ["reference", "paper", dt] => RunKind::Reference(
            Integrator::Paper {
                dt: number(dt, "time step", run)?,
            },
            None,
        ),
        ["reference", tol] => RunKind::Reference(
            Integrator::Adaptive {
                tolerance: number(tol, "tolerance", run)?,
            },
            None,
        ),
        ["rapier", dt, "tol", tol] => RunKind::Rapier {
            response: ImpactResponse::Topple,
            dt: number(dt, "time step", run)?,
            impulse_step: None,
            tolerance: Some(number(tol, "tolerance", run)?),
            precision,
        },
        ["rapier", dt] => RunKind::Rapier {
            response: ImpactResponse::Topple,
            dt: number(dt, "time step", run)?,
            impulse_step: None,
            tolerance: None,
            precision,
        },
        ["rapier", dt, step] => RunKind::Rapier {
            response: ImpactResponse::Topple,
            dt: number(dt, "time step", run)?,
            impulse_step: Some(number(step, "impulse step", run)?),
            tolerance: None,
            precision,
        },
        ["native", dt] => RunKind::native(number(dt, "time step", run)?, precision),
        _ => bail!(
            "run {run:?} is not one of reference:paper[:DT], reference:TOL (either may end in :imp:TOL or :imp:fixed), \
             rapier:DT, rapier:DT:STEP, rapier:DT:tol:TOL, native:DT (Rapier runs may end in :f32 or :f64)"
        ),
    })
}

/// The run's name with its Rapier build spelled out (`native:1e-3` run with
/// `--precision f32` is `native:1e-3:f32`): the key of its saved report, so
/// that saved reports of the two builds never mix.
fn full_name(run: &str, kind: &RunKind) -> String {
    match kind {
        RunKind::Rapier { precision, .. } if !(run.ends_with(":f32") || run.ends_with(":f64")) => {
            format!("{run}:{}", precision.name())
        }
        _ => run.to_string(),
    }
}

/// A saved run: the row it belongs to and the engine's report.
#[derive(serde::Serialize, serde::Deserialize)]
struct Saved {
    run: String,
    row: RowSpec,
    /// The whole settings of a reference run (so that a report saved under
    /// other defaults is not reused).
    #[serde(default)]
    settings: Option<Settings>,
    report: ChainReport,
}

/// The reference engine's settings of a run; `None` for a Rapier run.
fn reference_settings(kind: &RunKind, args: &Args) -> Option<Settings> {
    let RunKind::Reference(integrator, control) = *kind else {
        return None;
    };
    let mut settings = Settings {
        integrator,
        ..Default::default()
    };
    if let Some(control) = control {
        settings.impact.step_control = control;
    }
    if let Some(f) = args.freeze_tolerance {
        settings.freeze_tolerance = f;
    }
    Some(settings)
}

fn execute(kind: &RunKind, row: &RowSpec, args: &Args) -> anyhow::Result<ChainReport> {
    let bar = super::blocks_bar(row.n, "");
    let progress = |hit: usize| bar.set_position(hit as u64);
    let report = execute_with(kind, row, args, progress);
    bar.finish_and_clear();
    report
}

fn execute_with(
    kind: &RunKind,
    row: &RowSpec,
    args: &Args,
    mut progress: impl FnMut(usize),
) -> anyhow::Result<ChainReport> {
    let rapier = |engine, dt, impulse_step, tolerance, precision| RapierRow {
        engine,
        precision,
        solver: SolverSpec {
            dt,
            impulse_step,
            tolerance,
            max_group_hops: Some(args.window),
            // an accuracy run: every impact to its end, no step budget
            max_work: WorkBudget::Unbounded,
            ..Default::default()
        },
        max_time: args.max_time,
    };
    let engine: Box<dyn RowEngine> = match *kind {
        RunKind::Reference(..) => Box::new(ReferenceRow {
            settings: reference_settings(kind, args).expect("a reference run"),
        }),
        RunKind::Rapier {
            response,
            dt,
            impulse_step,
            tolerance,
            precision,
        } => Box::new(rapier(response, dt, impulse_step, tolerance, precision)),
    };
    Ok(engine.run(row, &mut progress)?)
}

fn file_name(run: &str) -> String {
    let safe: String = run
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{safe}.json")
}

/// The default baseline: the reference run with the smallest tolerance, else
/// the reference run with the smallest time step; among equals, the one with
/// the smallest impact tolerance or impulse step (the default counts as
/// [`StepControl::DEFAULT_TOLERANCE`]).
fn default_baseline(kinds: &[(String, RunKind)]) -> Option<usize> {
    let key = |k: &RunKind| {
        let RunKind::Reference(integrator, control) = *k else {
            return None;
        };
        let impacts = match control {
            Some(StepControl::Adaptive { tolerance }) => tolerance,
            Some(StepControl::AdaptiveImpulse { tolerance }) => tolerance,
            Some(StepControl::Fixed { impulse_step }) => impulse_step,
            None => StepControl::DEFAULT_TOLERANCE,
        };
        Some(match integrator {
            Integrator::Adaptive { tolerance } => (0, tolerance, impacts),
            Integrator::Paper { dt } => (1, dt, impacts),
        })
    };
    (0..kinds.len())
        .filter_map(|i| key(&kinds[i].1).map(|k| (k, i)))
        .min_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(std::cmp::Ordering::Equal))
        .map(|(_, i)| i)
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let row = row_spec(&args.row, None)?;
    row.validate()
        .map_err(|e| anyhow::anyhow!("invalid row: {e}"))?;
    let kinds: Vec<(String, RunKind)> = args
        .runs
        .iter()
        .map(|r| parse_run(r.trim(), args.precision).map(|k| (r.trim().to_string(), k)))
        .collect::<anyhow::Result<_>>()?;
    let baseline = match &args.baseline {
        Some(b) => Some(
            kinds
                .iter()
                .position(|(name, _)| name == b.trim())
                .with_context(|| format!("--baseline {b:?} is not one of --runs"))?,
        ),
        None => default_baseline(&kinds),
    };
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut reports: Vec<ChainReport> = Vec::with_capacity(kinds.len());
    for (k, (name, kind)) in kinds.iter().enumerate() {
        let key = full_name(name, kind);
        let path = args.out.as_ref().map(|d| d.join(file_name(&key)));
        // the whole settings of a reference run key its saved report
        let settings = reference_settings(kind, &args);
        let saved = path
            .as_ref()
            .filter(|p| p.exists())
            .map(|p| -> anyhow::Result<Saved> {
                let text = std::fs::read_to_string(p)
                    .with_context(|| format!("reading {}", p.display()))?;
                serde_json::from_str(&text).with_context(|| format!("parsing {}", p.display()))
            })
            .transpose()?
            .filter(|s| s.row == row && s.run == key && s.settings == settings);
        let report = match saved {
            Some(s) => {
                eprintln!("[{}/{}] {name}: saved report reused", k + 1, kinds.len());
                s.report
            }
            None => {
                eprintln!("[{}/{}] {name}: running…", k + 1, kinds.len());
                let start = Instant::now();
                let report = execute(kind, &row, &args).with_context(|| format!("run {name}"))?;
                eprintln!(
                    "[{}/{}] {name}: {:.1} s, v̂_na {}",
                    k + 1,
                    kinds.len(),
                    start.elapsed().as_secs_f64(),
                    report
                        .natural_speed
                        .map_or("none".to_string(), |v| format!("{v:.5}"))
                );
                if let Some(p) = &path {
                    let saved = Saved {
                        run: key.clone(),
                        row,
                        settings: settings.clone(),
                        report: report.clone(),
                    };
                    std::fs::write(p, serde_json::to_string_pretty(&saved)?)
                        .with_context(|| format!("writing {}", p.display()))?;
                }
                report
            }
        };
        reports.push(report);
    }
    print_table(&args, &row, &kinds, &reports, baseline);
    if let Some(path) = &args.plot {
        plot_work_precision(path, &args, &row, &kinds, &reports, baseline)?;
        eprintln!("work-precision plot: {}", path.display());
    }
    Ok(())
}

/// The engine family of a run: one series of the work-precision plot.
fn family(kind: &RunKind) -> &'static str {
    match kind {
        RunKind::Reference(_, Some(StepControl::Fixed { .. })) => "reference, fixed impulse step",
        RunKind::Reference(_, Some(StepControl::AdaptiveImpulse { .. })) => {
            "reference, adaptive impulse step"
        }
        RunKind::Reference(..) => "reference, impacts in time",
        RunKind::Rapier {
            response: ImpactResponse::Topple,
            ..
        } => "Rapier + topple",
        RunKind::Rapier {
            response: ImpactResponse::Native,
            ..
        } => "native Rapier",
    }
}

/// The work-precision plot: for every run but the baseline with a finite
/// v̂_na, (log₁₀ run time (s), log₁₀ |v̂_na error| relative to the baseline),
/// one series per engine family. An error of exactly 0 is drawn at 10⁻¹⁶.
fn plot_work_precision(
    path: &std::path::Path,
    args: &Args,
    row: &RowSpec,
    kinds: &[(String, RunKind)],
    reports: &[ChainReport],
    baseline: Option<usize>,
) -> anyhow::Result<()> {
    use super::plot::{plot, Curve, Style};
    let Some(base) = baseline
        .and_then(|b| reports[b].natural_speed)
        .filter(|v| v.is_finite())
    else {
        bail!("--plot needs a baseline run with a finite v̂_na (see --baseline)");
    };
    let mut curves: Vec<Curve> = Vec::new();
    for (k, ((_, kind), r)) in kinds.iter().zip(reports).enumerate() {
        let Some(v) = r.natural_speed.filter(|v| v.is_finite()) else {
            continue;
        };
        if Some(k) == baseline || r.run_time <= 0.0 {
            continue;
        }
        let error = ((v - base) / base).abs().max(1e-16);
        let point = (r.run_time.log10(), error.log10());
        let name = family(kind);
        match curves.iter_mut().find(|c| c.name == name) {
            Some(c) => c.points.push(point),
            None => curves.push(Curve {
                name: name.to_string(),
                points: vec![point],
                style: Style::Markers,
                colour: None,
            }),
        }
    }
    let title = format!(
        "{}{:?} row, s/h {}, {} blocks: error against {}",
        if args.row.ideal { "ideal " } else { "" },
        args.row.preset,
        args.row.spacing_ratio,
        row.n,
        baseline.map_or("", |b| kinds[b].0.as_str())
    );
    plot(
        path,
        &title,
        "log10 run time (s)",
        "log10 |v_na error| (relative)",
        &curves,
    )
}

/// The front's mean speed from block 7 to the last block hit, over √(gh):
/// distance over time, so a few blocks hit together do not make it infinite
/// (unlike the mean of the v̂_i, v̂_na). `None` when fewer than 8 blocks hit.
fn front_speed(r: &ChainReport, row: &RowSpec) -> Option<f64> {
    let first = topple::domino::FIRST_STEADY_BLOCK - 1; // 0-based
    let last = r.hit_times.len().checked_sub(1)?;
    if last <= first {
        return None;
    }
    let time = r.hit_times[last] - r.hit_times[first];
    (time > 0.0).then(|| (last - first) as f64 * row.pitch() / time / row.params.speed_scale())
}

/// Rapier time step of a run, if it is a Rapier run.
fn rapier_dt(kind: &RunKind) -> Option<f64> {
    match *kind {
        RunKind::Rapier { dt, .. } => Some(dt),
        RunKind::Reference(..) => None,
    }
}

fn print_table(
    args: &Args,
    row: &RowSpec,
    kinds: &[(String, RunKind)],
    reports: &[ChainReport],
    baseline: Option<usize>,
) {
    let base = baseline
        .and_then(|b| reports[b].natural_speed)
        .filter(|v| v.is_finite());
    let base_front = baseline.and_then(|b| front_speed(&reports[b], row));
    println!(
        "{:?} row, s/h = {}, n = {}, push = {}; error of v̂_na against {}",
        args.row.preset,
        args.row.spacing_ratio,
        row.n,
        row.push,
        baseline.map_or("nothing (no reference run)", |b| kinds[b].0.as_str())
    );
    println!();
    println!("| run | run time (s) | blocks hit | out of order | front v̂ | impacts | held / plastic | ms/step | topple/native | v̂_na | spread (std) | error | front error |");
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    // out of order: intervals t_i ≤ 0 (a block first hit no later than the
    // one before it), where v̂_i means nothing; v̂_na is then infinite or
    // meaningless and shown as "none".
    // held / plastic: impacts solved again with e = 0 contacts held, and
    // impacts resolved as plastic (reference engine only)
    for (k, ((name, kind), r)) in kinds.iter().zip(reports).enumerate() {
        // Rapier: wall time per Rapier step; the ratio against the native run
        // at the same step from this same invocation.
        let ms_per_step = rapier_dt(kind).map(|dt| {
            let steps = (r.simulated_time / dt).round().max(1.0);
            1e3 * r.run_time / steps
        });
        let precision = match *kind {
            RunKind::Rapier { precision, .. } => precision,
            RunKind::Reference(..) => Precision::F64,
        };
        let native_ms = rapier_dt(kind).and_then(|dt| {
            kinds
                .iter()
                .zip(reports)
                .find(|((_, k2), _)| *k2 == RunKind::native(dt, precision))
                .map(|(_, r2)| 1e3 * r2.run_time / (r2.simulated_time / dt).round().max(1.0))
        });
        let ratio = match (kind, ms_per_step, native_ms) {
            (
                RunKind::Rapier {
                    response: ImpactResponse::Native,
                    ..
                },
                _,
                _,
            ) => "1".into(),
            (RunKind::Rapier { .. }, Some(a), Some(b)) => format!("{:.2}", a / b),
            _ => "-".into(),
        };
        let relative = |v: Option<f64>, b: Option<f64>| match (v, b) {
            _ if Some(k) == baseline => "baseline".to_string(),
            (Some(v), Some(b)) => format!("{:.2e}", ((v - b) / b).abs()),
            _ => "-".into(),
        };
        let error = relative(r.natural_speed.filter(|v| v.is_finite()), base);
        let front_error = relative(front_speed(r, row), base_front);
        println!(
            "| {name} | {:.1} | {}/{} | {} | {} | {} | {} / {} | {} | {ratio} | {} | {} | {error} | {front_error} |",
            r.run_time,
            r.hit_times.len(),
            row.n,
            r.intervals.iter().filter(|t| t.is_nan() || **t <= 0.0).count(),
            front_speed(r, row).map_or("-".to_string(), |v| format!("{v:.5}")),
            r.impacts,
            r.held_impacts,
            r.impact_fallbacks,
            ms_per_step.map_or("-".to_string(), |m| format!("{m:.3}")),
            r.natural_speed
                .filter(|v| v.is_finite())
                .map_or("none".to_string(), |v| format!("{v:.5}")),
            r.natural_speed_spread
                .filter(|s| s.std_dev.is_finite())
                .map_or("-".to_string(), |s| format!("{:.4}", s.std_dev)),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_parse_and_bad_ones_are_refused() {
        assert_eq!(
            parse_run("reference:paper", Precision::F64).unwrap(),
            RunKind::Reference(Integrator::Paper { dt: 1e-4 }, None)
        );
        assert_eq!(
            parse_run("reference:1e-8", Precision::F64).unwrap(),
            RunKind::Reference(Integrator::Adaptive { tolerance: 1e-8 }, None)
        );
        assert_eq!(
            parse_run("reference:paper:imp:1e-4", Precision::F64).unwrap(),
            RunKind::Reference(
                Integrator::Paper { dt: 1e-4 },
                Some(StepControl::AdaptiveImpulse { tolerance: 1e-4 })
            )
        );
        assert_eq!(
            parse_run("reference:1e-6:imp:1e-5", Precision::F64).unwrap(),
            RunKind::Reference(
                Integrator::Adaptive { tolerance: 1e-6 },
                Some(StepControl::AdaptiveImpulse { tolerance: 1e-5 })
            )
        );
        assert_eq!(
            parse_run("reference:paper:imp:fixed", Precision::F64).unwrap(),
            RunKind::Reference(Integrator::Paper { dt: 1e-4 }, Some(StepControl::paper()))
        );
        assert!(parse_run("reference:imp:1e-4", Precision::F64).is_err());
        assert!(parse_run("reference:paper:imp:-1", Precision::F64).is_err());
        assert_eq!(
            parse_run("rapier:1e-3:1e-4", Precision::F64).unwrap(),
            RunKind::Rapier {
                response: ImpactResponse::Topple,
                dt: 1e-3,
                impulse_step: Some(1e-4),
                tolerance: None,
                precision: Precision::F64,
            }
        );
        assert_eq!(
            parse_run("native:5e-4", Precision::F32).unwrap(),
            RunKind::native(5e-4, Precision::F32)
        );
        assert_eq!(
            parse_run("native:5e-4:f64", Precision::F32).unwrap(),
            RunKind::native(5e-4, Precision::F64)
        );
        assert_eq!(
            parse_run("rapier:1e-3", Precision::F64).unwrap(),
            RunKind::Rapier {
                response: ImpactResponse::Topple,
                dt: 1e-3,
                impulse_step: None,
                tolerance: None,
                precision: Precision::F64,
            }
        );
        for bad in [
            "rapier:0",
            "native:-1",
            "reference:abc",
            "bullet:1e-3",
            "native:f32",
        ] {
            assert!(parse_run(bad, Precision::F64).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_default_baseline_is_the_tightest_reference_run() {
        let kinds: Vec<(String, RunKind)> = [
            "native:1e-3",
            "reference:paper",
            "reference:1e-6",
            "reference:1e-9",
        ]
        .iter()
        .map(|r| (r.to_string(), parse_run(r, Precision::F64).unwrap()))
        .collect();
        assert_eq!(default_baseline(&kinds), Some(3));
        assert_eq!(default_baseline(&kinds[..2]), Some(1));
        assert_eq!(default_baseline(&kinds[..1]), None);
    }
}
