//! Running the jobs of `topple paper` in parallel (rayon), with a progress
//! bar, saving each finished run for `--resume` (`super::super::resume`).

use std::sync::atomic::{AtomicUsize, Ordering};

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
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
    let results = jobs
        .par_iter()
        .map(|j| {
            let r = match resume.then(|| store.load(&j.row, &j.settings)).flatten() {
                Some(saved) => {
                    reused.fetch_add(1, Ordering::Relaxed);
                    Ok(saved)
                }
                None => run_and_save(j, store),
            };
            bar.inc(1);
            r
        })
        .collect();
    bar.finish();
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
