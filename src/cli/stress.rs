//! `topple stress [--family rows | scenes] [--quick | --full] [--seed S]
//! [--combo K] [--engine E]`: the seeded sweeps of `topple::stress` (domino
//! rows, or random scenes for the Rapier plugin); prints the table, exits
//! non-zero on any violation of topple's engines (native Rapier's are
//! printed as the baseline and not counted).

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use topple::stress::scene::{scene_sweep, scene_table, scene_violations, SceneSpec};
use topple::stress::{combos_of, sweep, table, StressEngine, SweepSpec};

/// Which sweep `topple stress` runs.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Family {
    /// Domino rows through every engine (reference, Rapier f64 and f32,
    /// native) and free-body impacts.
    #[default]
    Rows,
    /// Random scenes for the Rapier plugin: piles, stacks, pyramids of every
    /// supported shape, any length unit, time step and precision.
    Scenes,
}

/// Arguments of `topple stress`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Which sweep.
    #[arg(long, value_enum, default_value_t = Family::Rows)]
    pub family: Family,
    /// The CI sweep: 400 combinations of 3 to 8 blocks (the default).
    #[arg(long, conflicts_with = "full")]
    pub quick: bool,
    /// The full sweep: 3,000 combinations of 3 to 20 blocks.
    #[arg(long)]
    pub full: bool,
    /// Seed of the draws.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Run only this combination (as printed in a reproduce line).
    #[arg(long)]
    pub combo: Option<usize>,
    /// Run only the combinations of this engine (reference, rapier-f64,
    /// rapier-f32, native, impact).
    #[arg(long, value_parser = parse_engine, conflicts_with = "combo")]
    pub engine: Option<StressEngine>,
    /// With --combo: draw the row at its deepest penetration and three
    /// moments before it, then around the first drop of its fallen count,
    /// into this file, SVG or PNG by its extension (rows).
    #[arg(long, requires = "combo")]
    pub draw: Option<PathBuf>,
    /// With --combo: write the scene as TOML (`topple scene FILE` runs it)
    /// into this file (scenes).
    #[arg(long, requires = "combo")]
    pub toml: Option<PathBuf>,
    /// Print every violation, not only the worst.
    #[arg(long)]
    pub verbose: bool,
}

fn parse_engine(s: &str) -> Result<StressEngine, String> {
    StressEngine::by_name(s).ok_or_else(|| {
        let names: Vec<&str> = StressEngine::ALL.iter().map(|e| e.name()).collect();
        format!("one of {}", names.join(", "))
    })
}

/// Progress on stderr: the bar on a terminal, else a line every 5 %.
struct Progress {
    bar: indicatif::ProgressBar,
    lines: bool,
    n: usize,
    start: Instant,
    done: AtomicUsize,
    found: AtomicUsize,
    printed: Mutex<usize>,
}

impl Progress {
    fn new(n: usize) -> Self {
        Progress {
            bar: indicatif::ProgressBar::new(n as u64),
            lines: !std::io::stderr().is_terminal(),
            n,
            start: Instant::now(),
            done: AtomicUsize::new(0),
            found: AtomicUsize::new(0),
            printed: Mutex::new(0),
        }
    }

    /// One run done, with `counted` violations of topple's engines.
    fn tick(&self, counted: usize) {
        self.bar.inc(1);
        let k = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        self.found.fetch_add(counted, Ordering::Relaxed);
        if self.lines {
            let step = (self.n / 20).max(1);
            let mut last = self.printed.lock().unwrap_or_else(|e| e.into_inner());
            if k == self.n || k >= *last + step {
                *last = k;
                eprintln!(
                    "stress: {k}/{} runs, {} violations in topple's engines, {:.0} s",
                    self.n,
                    self.found.load(Ordering::Relaxed),
                    self.start.elapsed().as_secs_f64()
                );
            }
        }
    }
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if args.family == Family::Scenes {
        return run_scenes(&args);
    }
    anyhow::ensure!(args.toml.is_none(), "--toml is for --family scenes");
    let mut spec = if args.full {
        SweepSpec::full(args.seed)
    } else {
        SweepSpec::quick(args.seed)
    };
    spec.engine = args.engine;
    if let Some(k) = args.combo {
        topple::validate::check_count("--combo", k, 0, spec.combos - 1)?;
    }
    let n = combos_of(&spec, args.combo).len();
    let progress = Progress::new(n);
    let r = sweep(&spec, args.combo, |c, o| {
        let v = topple::stress::violations(c, o);
        progress.tick(if c.engine.is_baseline() { 0 } else { v.len() });
    });
    progress.bar.finish_and_clear();
    print!("{}", table(&spec, &r));
    println!("wall time {:.0} s", progress.start.elapsed().as_secs_f64());
    if args.verbose || args.combo.is_some() {
        for v in &r.violations {
            println!(
                "  combo {}: {}{} = {:.3e}: {}",
                v.combo,
                v.kind.name(),
                if v.engine.is_baseline() {
                    " (baseline)"
                } else {
                    ""
                },
                v.value,
                v.detail
            );
        }
    }
    if let (Some(path), Some((c, o))) = (&args.draw, &r.single) {
        draw(path, c, o)?;
    }
    let counted = r.counted().count();
    anyhow::ensure!(
        counted == 0,
        "{counted} violations of topple's engines in {n} combinations"
    );
    Ok(())
}

/// `topple stress --family scenes`.
fn run_scenes(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(args.draw.is_none(), "--draw is for --family rows");
    anyhow::ensure!(args.engine.is_none(), "--engine is for --family rows");
    let spec = if args.full {
        SceneSpec::full(args.seed)
    } else {
        SceneSpec::quick(args.seed)
    };
    if let Some(k) = args.combo {
        topple::validate::check_count("--combo", k, 0, spec.scenes - 1)?;
    }
    let n = args.combo.map_or(spec.scenes, |_| 1);
    let progress = Progress::new(n);
    let r = scene_sweep(&spec, args.combo, |c, o| {
        let v = scene_violations(c, o);
        progress.tick(if c.engine.is_baseline() { 0 } else { v.len() });
    });
    progress.bar.finish_and_clear();
    print!("{}", scene_table(&spec, &r));
    println!("wall time {:.0} s", progress.start.elapsed().as_secs_f64());
    if args.verbose || args.combo.is_some() {
        for v in &r.violations {
            println!(
                "  scene {}: {}{} = {:.3e}: {}",
                v.combo,
                v.kind.name(),
                if v.engine.is_baseline() {
                    " (baseline)"
                } else {
                    ""
                },
                v.value,
                v.detail
            );
        }
    }
    if let (Some(path), Some((c, _))) = (&args.toml, &r.single) {
        std::fs::write(path, c.toml())
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
        println!("scene written to {}", path.display());
    }
    let counted = r.counted().count();
    anyhow::ensure!(
        counted == 0,
        "{counted} violations of topple's engines in {n} scenes"
    );
    Ok(())
}

/// Draws the looks around a row's deepest penetration into `path` (SVG, or
/// PNG at 4 px per mm).
fn draw(
    path: &std::path::Path,
    c: &topple::stress::Combo,
    o: &topple::stress::Observation,
) -> anyhow::Result<()> {
    use topple::reference::{snapshot_png, snapshot_svg, Snapshot};
    anyhow::ensure!(
        !o.deepest.is_empty() || !o.dropped.is_empty(),
        "combo {} shows no overlap and no drop of the fallen count to draw",
        c.index
    );
    let snaps: Vec<Snapshot> = o
        .deepest
        .iter()
        .chain(&o.dropped)
        .map(|(time, blocks)| Snapshot {
            time: *time,
            blocks: blocks.clone(),
        })
        .collect();
    let block = &c.row.params.block;
    let last = c.row.n - 1;
    let bytes = if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        snapshot_png(block, &snaps, 0, last, 4.0)?
    } else {
        snapshot_svg(block, &snaps, 0, last).into_bytes()
    };
    std::fs::write(path, bytes)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    println!(
        "drawn into {} ({} moments up to t = {:.4} s)",
        path.display(),
        snaps.len(),
        snaps[snaps.len() - 1].time
    );
    Ok(())
}
