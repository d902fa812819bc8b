//! Running the jobs of `topple paper` in parallel (one worker per thread of
//! rayon's pool), longest first, with a progress bar, saving each finished
//! run for `--resume` (`super::super::resume`).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use indicatif::{ProgressBar, ProgressStyle};
use topple::domino::ChainReport;
use topple::reference::run;

use super::jobs::Job;
use crate::cli::resume::RunStore;

/// The result of each job, in job order: a report or the error's text.
pub type Results = Vec<Result<ChainReport, String>>;

/// Runs every job (reusing saved runs when `resume`), with a bar on stderr.
pub fn run_jobs(jobs: &[Job], store: &RunStore, resume: bool) -> Results {
    let bar = ProgressBar::new(jobs.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs, {elapsed} elapsed, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let reused = AtomicUsize::new(0);
    let order = longest_first(jobs);
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<Option<Result<ChainReport, String>>>> =
        Mutex::new(jobs.iter().map(|_| None).collect());
    let run_one = |k: usize| {
        let j = &jobs[k];
        let r = match resume.then(|| store.load(&j.row, &j.settings)).flatten() {
            Some(saved) => {
                reused.fetch_add(1, Ordering::Relaxed);
                Ok(saved)
            }
            None => run_and_save(j, store),
        };
        bar.inc(1);
        if let Ok(mut d) = done.lock() {
            d[k] = Some(r);
        }
    };
    // every worker takes the next job of the list until none is left, so
    // both cores stay busy to the end and the last to start are the shortest
    let worker = || {
        while let Some(&k) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
            run_one(k);
        }
    };
    rayon::scope(|s| {
        for _ in 0..rayon::current_num_threads().max(1) {
            s.spawn(|_| worker());
        }
    });
    bar.finish();
    let results = done
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .map(|r| r.unwrap_or_else(|| Err("the run did not finish".to_string())))
        .collect();
    if resume {
        eprintln!(
            "reused {} of {} runs saved in {}",
            reused.into_inner(),
            jobs.len(),
            store.dir().display()
        );
    }
    results
}

/// The jobs' indices, the most expensive first ([`expected_cost`]): with
/// one worker per core taking the next job as it becomes free, the long
/// rows start at once and the run ends on short ones, not on a long row
/// left to one core at the end (the longest-processing-time-first rule,
/// on estimated times).
fn longest_first(jobs: &[Job]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..jobs.len()).collect();
    order.sort_by(|&a, &b| expected_cost(&jobs[b]).total_cmp(&expected_cost(&jobs[a])));
    order
}

/// A job's cost relative to the others, only for their order: the blocks
/// of the row, times 3 for rows whose blocks both bounce and rub on each
/// other (e1 > 0 and μ1 > 0: the Table 1 rows, whose chatter makes most of
/// the impacts), over the spacing ratio (a close row keeps more blocks in
/// each impact and in the moving window), floored at 0.1. On the run
/// times of a full `topple paper` run, this order ends within 0.1 % of the
/// best list order of those times (docs/reference-performance.md).
fn expected_cost(j: &Job) -> f64 {
    let p = &j.row.params;
    let bouncing = if p.e1 > 0.0 && p.mu1 > 0.0 { 3.0 } else { 1.0 };
    let sh = j.row.spacing / p.block.height;
    j.row.n as f64 * bouncing / sh.max(0.1)
}

/// How a job's figure is named in messages: `fig 5`, or `fig5_ground` for
/// the ground-law figure (job id [`super::jobs::GROUND_FIG`]).
fn figure_label(fig: u32) -> String {
    if fig == super::jobs::GROUND_FIG {
        "fig5_ground".to_string()
    } else {
        format!("fig {fig}")
    }
}

/// One run; a finished one (not cut by its wall-clock limit) is saved.
fn run_and_save(j: &Job, store: &RunStore) -> Result<ChainReport, String> {
    let report = run(&j.row, &j.settings)
        .map(|o| o.report)
        .map_err(|e| format!("{} {} x={}: {e}", figure_label(j.fig), j.key, j.x))?;
    if !report.stopped_early
        && let Err(e) = store.save(&j.row, &j.settings, &report)
    {
        eprintln!("warning: could not save a finished run: {e:#}");
    }
    Ok(report)
}

/// A warning on stderr for each run that failed, hit its run limit, or
/// needed the impact fallback policy.
pub fn warn_incomplete(jobs: &[Job], results: &Results) {
    for (j, r) in jobs.iter().zip(results) {
        match r {
            Err(e) => eprintln!("warning: {e}"),
            Ok(r) if r.stopped_early || r.impact_fallbacks > 0 || r.held_impacts > 0 => eprintln!(
                "warning: {} {} x={}: {}{} plastic fallbacks, {} held impacts, {} of {} blocks reached",
                figure_label(j.fig),
                j.key,
                j.x,
                if r.stopped_early { "run limit hit, " } else { "" },
                r.impact_fallbacks,
                r.held_impacts,
                r.hit_times.len(),
                j.row.n
            ),
            _ => {}
        }
    }
}
