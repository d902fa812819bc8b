//! `topple paper --out DIR`: regenerates the paper's Figs. 3–10 with the
//! reference engine, as CSV files and SVG plots. Sweeps run in parallel
//! (rayon) with a progress bar.

use std::path::{Path, PathBuf};

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::plot::{csv, plot, Curve, Style, COLOURS};
use plotters::style::RGBColor;
use topple::domino::{ChainReport, Ground, Preset, RowParams, RowSpec};
use topple::reference::{run, snapshot_svg, Integrator, Settings};
use topple::theory::{self, Model};
use topple::validate::{self, EngineKind, InputError};

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
    /// Resolve impacts with the resolver's adaptive impulse stepping at this
    /// relative tolerance instead of the paper's fixed ΔP = 10⁻⁴ P₀ (ideal
    /// Domino T, s/h 0.45, 30 blocks: v̂_na 1.776038 at 10⁻⁴ and 1.776038 at
    /// 10⁻⁶ against 1.7760 fixed, 5 times faster).
    #[arg(long)]
    pub impact_tolerance: Option<f64>,
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

struct Job {
    fig: u32,
    /// Curve key within the figure.
    key: String,
    /// x coordinate in the figure (parameter value) when it is a sweep.
    x: f64,
    row: RowSpec,
    settings: Settings,
}

fn with_ground_ideal(mut p: RowParams) -> RowParams {
    p.mu2 = 0.9;
    p.mu2_stick = 0.9;
    p.e2 = 0.0;
    p
}

fn set_mu1(mut p: RowParams, mu: f64) -> RowParams {
    p.mu1 = mu;
    p.mu1_stick = mu;
    p
}

fn set_mu2(mut p: RowParams, mu: f64) -> RowParams {
    p.mu2 = mu;
    p.mu2_stick = mu;
    p
}

/// Job id of the figure `fig5_ground`.
const GROUND_FIG: u32 = 50;
/// Friction between blocks of the second set of rows in `fig5_ground`.
const GROUND_MU1: f64 = 0.15;

/// The rows of `fig5_ground`: the ideal Domino T row with μ1 = 0 and 0.15,
/// each on a no-slip ground, with the paper's halved impact friction and
/// with full impact friction (μ2 = 0.9 in and out of impacts). The no-slip
/// rows keep μ1 at full value inside impacts too, as the extended model
/// assumes. Curve names hold no commas (they go into a CSV header).
fn ground_variants() -> Vec<(String, RowParams)> {
    let ideal = Preset::T.params().ideal();
    let mut v = Vec::new();
    for mu1 in [0.0, GROUND_MU1] {
        let p = set_mu1(ideal, mu1);
        let mut full = p;
        full.impact_friction_factor = 1.0;
        let mut no_slip = full;
        no_slip.ground = Ground::NoSlip;
        v.push((format!("no-slip ground; mu1 = {mu1}"), no_slip));
        v.push((format!("halved impact friction; mu1 = {mu1}"), p));
        v.push((format!("full impact friction; mu1 = {mu1}"), full));
    }
    v
}

/// A theory line of Figs. 4 and 5 (`crate::theory`).
#[derive(Clone)]
struct TheoryLine {
    name: String,
    thickness_ratio: f64,
    model: Model,
    style: Style,
    colour: RGBColor,
}

fn thickness_ratio(p: Preset) -> f64 {
    let b = p.params().block;
    b.thickness / b.height
}

/// Spacings of a theory line: every 0.005 across the simulated spacings, and
/// the simulated spacings themselves (so that the CSV holds the theory at each
/// simulation point).
fn theory_grid(xs: &[f64]) -> Vec<f64> {
    let lo = xs.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        return Vec::new();
    }
    let steps = ((hi - lo) / 0.005).round() as usize;
    let mut g: Vec<f64> = (0..=steps)
        .map(|k| ((lo + (hi - lo) * k as f64 / steps.max(1) as f64) * 1e9).round() / 1e9)
        .collect();
    g.extend_from_slice(xs);
    g.retain(|x| *x > 0.0);
    g.sort_by(|a, b| a.total_cmp(b));
    g.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    g
}

fn natural(r: &ChainReport) -> f64 {
    r.natural_speed.unwrap_or(f64::NAN)
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
    Ok(())
}

pub fn run_cmd(args: Args) -> anyhow::Result<()> {
    check_args(&args)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let want = |f: u32| args.figs.is_empty() || args.figs.contains(&f);
    let mut base = match args.tolerance {
        Some(t) => Settings::accurate(t),
        None => Settings {
            integrator: Integrator::Paper { dt: 1e-4 },
            ..Default::default()
        },
    };
    base.wall_time_limit = Some(args.run_limit);
    if let Some(tol) = args.impact_tolerance {
        anyhow::ensure!(
            tol > 0.0 && tol < 1.0,
            "--impact-tolerance must be in (0, 1), got {tol}"
        );
        base.impact.step_control = topple::impact::StepControl::Adaptive { tolerance: tol };
    }
    let n = args.n;
    let mut jobs: Vec<Job> = Vec::new();
    let x = Preset::X.params();
    let spacings: Vec<f64> = if args.spacings.is_empty() {
        (0..11).map(|k| (1.0 + 0.5 * k as f64) / 10.0).collect()
    } else {
        args.spacings.clone()
    };
    let three = [0.18, 0.35, 0.52];
    let mk = |fig: u32,
              key: String,
              xv: f64,
              p: RowParams,
              sh: f64,
              push: f64,
              n: usize,
              s: &Settings| Job {
        fig,
        key,
        x: xv,
        row: RowSpec::new(p, sh * p.block.height, n, push),
        settings: s.clone(),
    };
    if want(3) {
        for push in [1.8, 0.5] {
            jobs.push(mk(3, format!("push {push}"), 0.0, x, 0.18, push, n, &base));
        }
    }
    if want(4) {
        for (name, pr) in [("T", Preset::T), ("P", Preset::P)] {
            for &sh in &spacings {
                jobs.push(mk(4, name.into(), sh, pr.params(), sh, 1.0, n, &base));
            }
        }
    }
    if want(5) {
        let t = Preset::T.params();
        for &sh in &spacings {
            jobs.push(mk(
                5,
                "mu1 = 0, e1 = 0".into(),
                sh,
                t.ideal(),
                sh,
                1.0,
                n,
                &base,
            ));
            jobs.push(mk(
                5,
                "mu1 = 0.15, e1 = 0".into(),
                sh,
                set_mu1(t.ideal(), 0.15),
                sh,
                1.0,
                n,
                &base,
            ));
        }
    }
    if want(5) {
        // fig5_ground (id 50): the ground law under the ideal row
        for (name, p) in ground_variants() {
            for &sh in &spacings {
                jobs.push(mk(GROUND_FIG, name.clone(), sh, p, sh, 1.0, n, &base));
            }
        }
    }
    if want(6) || want(7) {
        let series = Settings {
            series_blocks: vec![7, 8, 9, 10],
            series_interval: 2e-4,
            ..base.clone()
        };
        jobs.push(mk(7, "Table 1".into(), 0.0, x, 0.52, 1.0, 20, &series));
        jobs.push(mk(
            7,
            "ideal".into(),
            0.0,
            x.ideal(),
            0.52,
            1.0,
            20,
            &series,
        ));
    }
    if want(8) {
        for push in [0.5, 1.0, 1.8] {
            jobs.push(mk(
                8,
                format!("Table 1, push {push}"),
                0.0,
                x,
                0.52,
                push,
                n,
                &base,
            ));
            jobs.push(mk(
                8,
                format!("ideal, push {push}"),
                0.0,
                x.ideal(),
                0.52,
                push,
                n,
                &base,
            ));
        }
    }
    if want(9) {
        let g = with_ground_ideal(x);
        for &sh in &three {
            for mu1 in [0.0, 0.1, 0.2, 0.3, 0.4, 0.5] {
                let mut p = set_mu1(g, mu1);
                p.e1 = 0.0;
                jobs.push(mk(9, format!("a s/h {sh}"), mu1, p, sh, 1.0, n, &base));
            }
            for e1 in [0.0, 0.2, 0.4, 0.6, 0.8, 0.9] {
                let mut p = set_mu1(g, 0.0);
                p.e1 = e1;
                jobs.push(mk(9, format!("b s/h {sh}"), e1, p, sh, 1.0, n, &base));
            }
        }
    }
    if want(10) {
        for &sh in &three {
            for mu2 in [0.2, 0.3, 0.4, 0.5, 0.7, 0.9] {
                let mut p = set_mu2(set_mu1(x, 0.0), mu2);
                p.e1 = 0.0;
                p.e2 = 0.0;
                jobs.push(mk(10, format!("a s/h {sh}"), mu2, p, sh, 1.0, n, &base));
            }
            for e2 in [0.0, 0.2, 0.4, 0.6, 0.8] {
                let mut p = set_mu1(with_ground_ideal(x), 0.0);
                p.e1 = 0.0;
                p.e2 = e2;
                jobs.push(mk(10, format!("b s/h {sh}"), e2, p, sh, 1.0, n, &base));
            }
        }
    }
    let bar = ProgressBar::new(jobs.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs, {elapsed} elapsed, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let store = super::resume::RunStore::new(&args.out);
    let reused = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<Result<ChainReport, String>> = jobs
        .par_iter()
        .map(|j| {
            if args.resume {
                if let Some(r) = store.load(&j.row, &j.settings) {
                    reused.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    bar.inc(1);
                    return Ok(r);
                }
            }
            let r = run(&j.row, &j.settings)
                .map(|o| o.report)
                .map_err(|e| format!("fig {} {} x={}: {e}", j.fig, j.key, j.x));
            if let Ok(report) = &r {
                // a run cut by its wall-clock limit is not kept for reuse
                if !report.stopped_early {
                    if let Err(e) = store.save(&j.row, &j.settings, report) {
                        eprintln!("warning: could not save a finished run: {e:#}");
                    }
                }
            }
            bar.inc(1);
            r
        })
        .collect();
    if args.resume {
        eprintln!(
            "reused {} of {} runs saved in {}",
            reused.into_inner(),
            jobs.len(),
            args.out.join("runs").display()
        );
    }
    bar.finish();
    for (j, r) in jobs.iter().zip(results.iter()) {
        match r {
            Err(e) => eprintln!("warning: {e}"),
            Ok(r) if r.stopped_early || r.impact_fallbacks > 0 || r.held_impacts > 0 => eprintln!(
                "warning: fig {} {} x={}: {}{} plastic fallbacks, {} held impacts, {} of {} blocks reached",
                j.fig,
                j.key,
                j.x,
                if r.stopped_early {
                    "run limit hit, "
                } else {
                    ""
                },
                r.impact_fallbacks,
                r.held_impacts,
                r.hit_times.len(),
                j.row.n
            ),
            _ => {}
        }
    }
    let out = &args.out;
    let pick = |fig: u32| -> Vec<(&Job, &ChainReport)> {
        jobs.iter()
            .zip(results.iter())
            .filter(|(j, _)| j.fig == fig)
            .filter_map(|(j, r)| r.as_ref().ok().map(|r| (j, r)))
            .collect()
    };
    let keys = |v: &[(&Job, &ChainReport)]| -> Vec<String> {
        let mut k: Vec<String> = Vec::new();
        for (j, _) in v {
            if !k.contains(&j.key) {
                k.push(j.key.clone());
            }
        }
        k
    };
    // speeds along the row (Figs. 3, 8)
    let along = |fig: u32, title: &str| -> anyhow::Result<()> {
        let v = pick(fig);
        let mut rows = Vec::new();
        let mut curves = Vec::new();
        for (j, r) in &v {
            let pts: Vec<(f64, f64)> = r
                .speeds
                .iter()
                .enumerate()
                .map(|(i, s)| ((i + 1) as f64, *s))
                .collect();
            for (i, s) in &pts {
                rows.push(vec![j.row.push, *i, *s]);
            }
            curves.push(Curve {
                name: j.key.clone(),
                points: pts,
                style: Style::Markers,
                colour: None,
            });
        }
        csv(
            &out.join(format!("fig{fig}.csv")),
            "push,block,v_hat",
            &rows,
        )?;
        plot(
            &out.join(format!("fig{fig}.svg")),
            title,
            "block n",
            "v̂",
            &curves,
        )
    };
    if want(3) {
        along(3, "Fig. 3: Domino X, Table 1, s/h = 0.18")?;
    }
    if want(8) {
        along(8, "Fig. 8: Domino X, s/h = 0.52, pushes 0.5/1.0/1.8")?;
    }
    // sweeps (Figs. 4, 5, 9, 10); theory lines (Figs. 4, 5) after the simulations
    let sweep_named = |fig: u32,
                       sub: &str,
                       name: &str,
                       title: &str,
                       xl: &str,
                       lines: &[TheoryLine]|
     -> anyhow::Result<()> {
        let v: Vec<(&Job, &ChainReport)> = pick(fig)
            .into_iter()
            .filter(|(j, _)| sub.is_empty() || j.key.starts_with(sub))
            .collect();
        let mut rows = Vec::new();
        let mut curves = Vec::new();
        let mut names = keys(&v);
        for (ki, k) in keys(&v).iter().enumerate() {
            let pts: Vec<(f64, f64)> = v
                .iter()
                .filter(|(j, _)| &j.key == k)
                .map(|(j, r)| (j.x, natural(r)))
                .collect();
            for (xv, yv) in &pts {
                let spread = v
                    .iter()
                    .find(|(j, _)| &j.key == k && j.x == *xv)
                    .and_then(|(_, r)| r.natural_speed_spread)
                    .map(|s| s.std_dev)
                    .unwrap_or(f64::NAN);
                rows.push(vec![ki as f64, *xv, *yv, spread]);
            }
            curves.push(Curve {
                name: k.trim_start_matches(sub).trim().to_string(),
                points: pts,
                // with theory lines the simulations are points; alone, the
                // points of a parameter sweep are joined to show the trend
                style: if lines.is_empty() {
                    Style::MarkersLine
                } else {
                    Style::Markers
                },
                colour: None,
            });
        }
        let grid = theory_grid(&v.iter().map(|(j, _)| j.x).collect::<Vec<_>>());
        for line in lines {
            let ki = names.len();
            names.push(format!("theory {}", line.name));
            let sweep = theory::sweep(&[line.model], line.thickness_ratio, &grid)
                .map_err(|e| anyhow::anyhow!("fig {fig} theory {}: {e}", line.name))?;
            let pts: Vec<(f64, f64)> = sweep
                .iter()
                .map(|r| {
                    let y = r.outcomes[0].natural_speed().unwrap_or(f64::NAN);
                    (r.spacing_ratio, y)
                })
                .collect();
            // no wave: no row in the CSV, a gap in the line
            for (xv, yv) in pts.iter().filter(|p| p.1.is_finite()) {
                rows.push(vec![ki as f64, *xv, *yv, f64::NAN]);
            }
            curves.push(Curve {
                name: line.name.clone(),
                points: pts,
                style: line.style,
                colour: Some(line.colour),
            });
        }
        let header = format!("curve({}),x,v_na,v_na_std", names.join("|"));
        csv(&out.join(format!("{name}.csv")), &header, &rows)?;
        plot(&out.join(format!("{name}.svg")), title, xl, "v̂_na", &curves)
    };
    let sweep = |fig: u32, sub: &str, title: &str, xl: &str, lines: &[TheoryLine]| {
        sweep_named(fig, sub, &format!("fig{fig}{sub}"), title, xl, lines)
    };
    if want(4) {
        // Fig. 4: Stronge's cooperative group model for T (solid) and P (dot-dash)
        let lines: Vec<TheoryLine> = [
            ("T", Preset::T, Style::Line),
            ("P", Preset::P, Style::DotDash),
        ]
        .into_iter()
        .enumerate()
        .map(|(k, (name, pr, style))| TheoryLine {
            name: format!("cooperative, {name}"),
            thickness_ratio: thickness_ratio(pr),
            model: Model::Cooperative,
            style,
            colour: COLOURS[k],
        })
        .collect();
        sweep(4, "", "Fig. 4: Domino T and P, Table 1", "s/h", &lines)?;
    }
    if want(5) {
        // Fig. 5: cooperative (solid), extended with Table 1's μ1 (dash),
        // single collision with Table 1's μ1 and e1 (dot-dash; the paper does
        // not state the values it used)
        let t = Preset::T.params();
        let lines = [
            TheoryLine {
                name: "cooperative (mu = 0)".into(),
                thickness_ratio: thickness_ratio(Preset::T),
                model: Model::Cooperative,
                style: Style::Line,
                colour: COLOURS[5],
            },
            TheoryLine {
                name: format!("extended (mu = {})", t.mu1),
                thickness_ratio: thickness_ratio(Preset::T),
                model: Model::Extended { mu: t.mu1 },
                style: Style::Dashed,
                colour: COLOURS[1],
            },
            TheoryLine {
                name: format!("single (mu = {}, e = {})", t.mu1, t.e1),
                thickness_ratio: thickness_ratio(Preset::T),
                model: Model::Single { mu: t.mu1, e: t.e1 },
                style: Style::DotDash,
                colour: COLOURS[2],
            },
        ];
        sweep(5, "", "Fig. 5: Domino T, mu2 = 0.9, e2 = 0", "s/h", &lines)?;
        let mu = GROUND_MU1;
        let ground_lines = [
            TheoryLine {
                name: "cooperative (mu = 0)".into(),
                model: Model::Cooperative,
                style: Style::Line,
                // grey: the six point colours include black and blue
                colour: RGBColor(120, 120, 120),
                ..lines[0].clone()
            },
            TheoryLine {
                name: format!("extended (mu = {mu})"),
                model: Model::Extended { mu },
                style: Style::Dashed,
                colour: RGBColor(120, 120, 120),
                ..lines[1].clone()
            },
        ];
        sweep_named(
            GROUND_FIG,
            "",
            "fig5_ground",
            "Ideal Domino T (mu2 = 0.9, e1 = e2 = 0): the ground law",
            "s/h",
            &ground_lines,
        )?;
    }
    if want(9) {
        sweep(9, "a", "Fig. 9a: X, mu2 = 0.9, e1 = e2 = 0", "mu1", &[])?;
        sweep(9, "b", "Fig. 9b: X, mu2 = 0.9, mu1 = e2 = 0", "e1", &[])?;
    }
    if want(10) {
        sweep(10, "a", "Fig. 10a: X, mu1 = e1 = e2 = 0", "mu2", &[])?;
        sweep(10, "b", "Fig. 10b: X, mu2 = 0.9, mu1 = e1 = 0", "e2", &[])?;
    }
    if want(7) || want(6) {
        let v = pick(7);
        for (j, r) in &v {
            let tbar = j.row.params.time_scale();
            let mut rows = Vec::new();
            let mut curves = Vec::new();
            for s in &r.series {
                let t0 = r.hit_times.get(s.block - 1).cloned().unwrap_or(0.0);
                let pts: Vec<(f64, f64)> = s
                    .time
                    .iter()
                    .zip(s.theta_dot.iter())
                    .filter(|(t, _)| **t >= t0)
                    .map(|(t, w)| ((t - t0) / tbar, w * tbar))
                    .collect();
                for (a, b) in &pts {
                    rows.push(vec![s.block as f64, *a, *b]);
                }
                curves.push(Curve {
                    name: format!("block {}", s.block),
                    points: pts,
                    style: Style::Line,
                    colour: None,
                });
            }
            let tag = if j.key == "ideal" { "b" } else { "a" };
            csv(
                &out.join(format!("fig7{tag}.csv")),
                "block,t_over_tbar,theta_dot_hat",
                &rows,
            )?;
            if want(7) {
                plot(
                    &out.join(format!("fig7{tag}.svg")),
                    &format!("Fig. 7{tag}: Domino X, s/h = 0.52, {}", j.key),
                    "t / t̄ (from the block's hit)",
                    "θ̂ (clockwise)",
                    &curves,
                )?;
            }
            if want(6) {
                // second pass with snapshots while the wave crosses blocks 8–12
                let t8 = r.hit_times.get(7).cloned().unwrap_or(0.0);
                let t12 = r.hit_times.get(11).cloned().unwrap_or(t8 + 0.1);
                let times: Vec<f64> = (0..5).map(|k| t8 + (t12 - t8) * k as f64 / 4.0).collect();
                let s = Settings {
                    snapshot_times: times,
                    series_blocks: Vec::new(),
                    ..j.settings.clone()
                };
                let o = run(&j.row, &s).map_err(|e| anyhow::anyhow!("fig 6: {e}"))?;
                let svg = snapshot_svg(&j.row.params.block, &o.snapshots, 4, 14.min(j.row.n - 1));
                write(&out.join(format!("fig6{tag}.svg")), &svg)?;
            }
        }
    }
    println!("wrote figures to {}", out.display());
    Ok(())
}

fn write(path: &Path, s: &str) -> anyhow::Result<()> {
    topple::atomic::write(path, s.as_bytes()).with_context(|| format!("writing {}", path.display()))
}
