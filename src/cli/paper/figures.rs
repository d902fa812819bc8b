//! Writing the figures of `topple paper` from the finished runs: CSV files
//! and SVG plots, axes in the paper's units (v̂ = v/√(gh), s/h, t/t̄ with
//! t̄ = √(h/g), block numbers).
//!
//! | function | figures |
//! | --- | --- |
//! | [`Figures::along`] | 3, 8: v̂_i along the row |
//! | [`Figures::sweep`] | 4, 5, `fig5_ground`, 9, 10: v̂_na against a parameter, with theory lines |
//! | [`Figures::series`] | 7: θ̂ of blocks 7–10 after their hit |
//! | [`Figures::snapshots`] | 6: the row while the wave crosses blocks 8–12 |

use std::path::Path;

use anyhow::Context;
use plotters::style::RGBColor;
use topple::domino::{ChainReport, Preset};
use topple::reference::{run, snapshot_svg, Settings};
use topple::theory::{self, Model};

use super::jobs::{Job, GROUND_MU1};
use super::run::Results;
use crate::cli::plot::{csv, plot, Curve, Style, COLOURS};

/// Label of v̂_na axes: the mean wave speed in the paper's units.
const V_NA: &str = "v̂_na = v/√(gh)";

/// A theory line of Figs. 4 and 5 (`topple::theory`).
#[derive(Clone)]
pub struct TheoryLine {
    name: String,
    thickness_ratio: f64,
    model: Model,
    style: Style,
    colour: RGBColor,
}

/// d/h of a preset's block.
fn thickness_ratio(p: Preset) -> f64 {
    let b = p.params().block;
    b.thickness / b.height
}

/// Fig. 4: Stronge's cooperative group model for T (solid) and P (dot-dash).
pub fn fig4_lines() -> Vec<TheoryLine> {
    [
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
    .collect()
}

/// Fig. 5: cooperative (solid), extended with Table 1's μ1 (dash), single
/// collision with Table 1's μ1 and e1 (dot-dash; the paper does not state
/// the values it used).
pub fn fig5_lines() -> Vec<TheoryLine> {
    let t = Preset::T.params();
    let line = |name: String, model: Model, style: Style, colour: RGBColor| TheoryLine {
        name,
        thickness_ratio: thickness_ratio(Preset::T),
        model,
        style,
        colour,
    };
    vec![
        line(
            "cooperative (mu = 0)".into(),
            Model::Cooperative,
            Style::Line,
            COLOURS[5],
        ),
        line(
            format!("extended (mu = {})", t.mu1),
            Model::Extended { mu: t.mu1 },
            Style::Dashed,
            COLOURS[1],
        ),
        line(
            format!("single (mu = {}, e = {})", t.mu1, t.e1),
            Model::Single { mu: t.mu1, e: t.e1 },
            Style::DotDash,
            COLOURS[2],
        ),
    ]
}

/// Whether a row's wave is no longer speeding up at the row's end. Over
/// v̂_i of the last ten blocks before the last two (the end of the row
/// slows its last blocks), the least-squares line through them rises by
/// less than [`STEADY_RISE`] of their mean from the first block to the
/// last, or its slope is within two standard errors of zero (the blocks of
/// a chattering Table 1 row scatter by several per cent, which alone is no
/// trend). A row too short to have twelve speeds does not count as steady.
pub fn wave_is_steady(speeds: &[f64]) -> bool {
    let n = speeds.len();
    if n < 12 {
        return false;
    }
    let tail = &speeds[n - 12..n - 2];
    let k = tail.len() as f64;
    let mean = tail.iter().sum::<f64>() / k;
    let xm = (k - 1.0) / 2.0;
    let sxx: f64 = (0..tail.len()).map(|i| (i as f64 - xm).powi(2)).sum();
    let slope = tail
        .iter()
        .enumerate()
        .map(|(i, y)| (i as f64 - xm) * (y - mean))
        .sum::<f64>()
        / sxx;
    let residual: f64 = tail
        .iter()
        .enumerate()
        .map(|(i, y)| (y - mean - slope * (i as f64 - xm)).powi(2))
        .sum();
    let standard_error = (residual / (k - 2.0) / sxx).sqrt();
    if !(mean.is_finite() && slope.is_finite() && standard_error.is_finite()) {
        return false;
    }
    slope * (k - 1.0) < STEADY_RISE * mean || slope <= 2.0 * standard_error
}

/// Largest relative rise of v̂_i over the tail of a steady wave
/// ([`wave_is_steady`]): 1 %, well below the 15 % by which a wave still
/// speeding up lags behind the cooperative model at s/h 0.1.
pub const STEADY_RISE: f64 = 0.01;

/// `fig5_ground`: the cooperative and extended (μ = [`GROUND_MU1`]) lines,
/// grey, since the six point colours include black and blue.
pub fn ground_lines() -> Vec<TheoryLine> {
    let grey = RGBColor(120, 120, 120);
    let mu = GROUND_MU1;
    vec![
        TheoryLine {
            name: "cooperative (mu = 0)".into(),
            thickness_ratio: thickness_ratio(Preset::T),
            model: Model::Cooperative,
            style: Style::Line,
            colour: grey,
        },
        TheoryLine {
            name: format!("extended (mu = {mu})"),
            thickness_ratio: thickness_ratio(Preset::T),
            model: Model::Extended { mu },
            style: Style::Dashed,
            colour: grey,
        },
    ]
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

/// Curve keys in order of first appearance.
fn keys(v: &[(&Job, &ChainReport)]) -> Vec<String> {
    let mut k: Vec<String> = Vec::new();
    for (j, _) in v {
        if !k.contains(&j.key) {
            k.push(j.key.clone());
        }
    }
    k
}

/// The finished runs and the directory the figures go to.
pub struct Figures<'a> {
    pub jobs: &'a [Job],
    pub results: &'a Results,
    pub out: &'a Path,
}

impl Figures<'_> {
    /// The successful runs of figure `fig`, in job order.
    fn pick(&self, fig: u32) -> Vec<(&Job, &ChainReport)> {
        self.jobs
            .iter()
            .zip(self.results.iter())
            .filter(|(j, _)| j.fig == fig)
            .filter_map(|(j, r)| r.as_ref().ok().map(|r| (j, r)))
            .collect()
    }

    /// Figs. 3 and 8: v̂_i against the block number, one curve per run.
    pub fn along(&self, fig: u32, title: &str) -> anyhow::Result<()> {
        let mut rows = Vec::new();
        let mut curves = Vec::new();
        for (j, r) in self.pick(fig) {
            let pts: Vec<(f64, f64)> = (1..)
                .map(|i| i as f64)
                .zip(r.speeds.iter().copied())
                .collect();
            rows.extend(pts.iter().map(|(i, s)| vec![j.row.push, *i, *s]));
            curves.push(Curve {
                name: j.key.clone(),
                points: pts,
                style: Style::Markers,
                colour: None,
            });
        }
        let path = |ext: &str| self.out.join(format!("fig{fig}.{ext}"));
        csv(&path("csv"), "push,block,v_hat", &rows)?;
        plot(&path("svg"), title, "block n", "v̂ = v/√(gh)", &curves)
    }

    /// A v̂_na sweep (Figs. 4, 5, 9, 10, `fig5_ground`) into `name`.csv/.svg:
    /// the runs of figure `fig` whose key starts with `sub`, one curve per
    /// key, and the theory `lines` on a fine grid over the same x range.
    pub fn sweep(
        &self,
        (fig, sub, name): (u32, &str, &str),
        title: &str,
        xlabel: &str,
        lines: &[TheoryLine],
    ) -> anyhow::Result<()> {
        let v: Vec<(&Job, &ChainReport)> = self
            .pick(fig)
            .into_iter()
            .filter(|(j, _)| j.key.starts_with(sub))
            .collect();
        let mut names = keys(&v);
        let mut rows = Vec::new();
        let mut curves = Vec::new();
        let mut unsteady = Vec::new();
        for (ki, k) in names.iter().enumerate() {
            let runs = v.iter().filter(|(j, _)| &j.key == k);
            let colour = COLOURS[ki % COLOURS.len()];
            let (steady, rising): (Vec<_>, Vec<_>) = runs
                .clone()
                .map(|(j, r)| {
                    (
                        j.x,
                        r.natural_speed.unwrap_or(f64::NAN),
                        wave_is_steady(&r.speeds),
                    )
                })
                .partition(|p| p.2);
            rows.extend(runs.map(|(j, r)| {
                let spread = r.natural_speed_spread.map_or(f64::NAN, |s| s.std_dev);
                let steady = if wave_is_steady(&r.speeds) { 1.0 } else { 0.0 };
                vec![
                    ki as f64,
                    j.x,
                    r.natural_speed.unwrap_or(f64::NAN),
                    spread,
                    steady,
                ]
            }));
            curves.push(Curve {
                name: k.trim_start_matches(sub).trim().to_string(),
                points: steady.iter().map(|p| (p.0, p.1)).collect(),
                // with theory lines the simulations are points; alone, the
                // points of a parameter sweep are joined to show the trend
                style: if lines.is_empty() {
                    Style::MarkersLine
                } else {
                    Style::Markers
                },
                colour: Some(colour),
            });
            unsteady.extend(rising.iter().map(|p| (p.0, p.1, colour)));
        }
        // rows whose wave still speeds up at their end: v̂_na is below the
        // steady speed the theory lines give (open circles, one legend entry)
        if !unsteady.is_empty() {
            curves.push(Curve {
                name: "open: wave still speeding up at the row's end".to_string(),
                points: Vec::new(),
                style: Style::Open,
                colour: Some(COLOURS[5]),
            });
        }
        curves.extend(unsteady.into_iter().map(|(x, y, colour)| Curve {
            name: String::new(),
            points: vec![(x, y)],
            style: Style::Open,
            colour: Some(colour),
        }));
        let grid = theory_grid(&v.iter().map(|(j, _)| j.x).collect::<Vec<_>>());
        for line in lines {
            let ki = names.len() as f64;
            names.push(format!("theory {}", line.name));
            let pts = theory_points(line, &grid)
                .with_context(|| format!("fig {fig} theory {}", line.name))?;
            // no wave: no row in the CSV, a gap in the line
            rows.extend(
                pts.iter()
                    .filter(|p| p.1.is_finite())
                    .map(|(x, y)| vec![ki, *x, *y, f64::NAN, 1.0]),
            );
            curves.push(Curve {
                name: line.name.clone(),
                points: pts,
                style: line.style,
                colour: Some(line.colour),
            });
        }
        let header = format!("curve({}),x,v_na,v_na_std,steady", names.join("|"));
        csv(&self.out.join(format!("{name}.csv")), &header, &rows)?;
        plot(
            &self.out.join(format!("{name}.svg")),
            title,
            xlabel,
            V_NA,
            &curves,
        )
    }

    /// Fig. 7a/7b: θ̂ = θ̇ t̄ of the series blocks against (t − t_hit)/t̄.
    pub fn series(&self) -> anyhow::Result<()> {
        for (j, r) in self.pick(7) {
            let tbar = j.row.params.time_scale();
            let mut rows = Vec::new();
            let mut curves = Vec::new();
            for s in &r.series {
                let t0 = r.hit_times.get(s.block - 1).copied().unwrap_or(0.0);
                let pts: Vec<(f64, f64)> = s
                    .time
                    .iter()
                    .zip(&s.theta_dot)
                    .filter(|(t, _)| **t >= t0)
                    .map(|(t, w)| ((t - t0) / tbar, w * tbar))
                    .collect();
                rows.extend(pts.iter().map(|(a, b)| vec![s.block as f64, *a, *b]));
                curves.push(Curve {
                    name: format!("block {}", s.block),
                    points: pts,
                    style: Style::Line,
                    colour: None,
                });
            }
            let tag = series_tag(j);
            let path = |ext: &str| self.out.join(format!("fig7{tag}.{ext}"));
            csv(&path("csv"), "block,t_over_tbar,theta_dot_hat", &rows)?;
            plot(
                &path("svg"),
                &format!("Fig. 7{tag}: Domino X, s/h = 0.52, {}", j.key),
                "t / t̄ (from the block's hit), t̄ = √(h/g)",
                "θ̂ = θ̇ t̄ (clockwise)",
                &curves,
            )?;
        }
        Ok(())
    }

    /// Fig. 6a/6b: a second pass over the Fig. 7 rows with five snapshots
    /// while the wave crosses blocks 8–12.
    pub fn snapshots(&self) -> anyhow::Result<()> {
        for (j, r) in self.pick(7) {
            let t8 = r.hit_times.get(7).copied().unwrap_or(0.0);
            let t12 = r.hit_times.get(11).copied().unwrap_or(t8 + 0.1);
            let settings = Settings {
                snapshot_times: (0..5).map(|k| t8 + (t12 - t8) * k as f64 / 4.0).collect(),
                series_blocks: Vec::new(),
                ..j.settings.clone()
            };
            let o = run(&j.row, &settings).map_err(|e| anyhow::anyhow!("fig 6: {e}"))?;
            let svg = snapshot_svg(&j.row.params.block, &o.snapshots, 4, 14.min(j.row.n - 1));
            let path = self.out.join(format!("fig6{}.svg", series_tag(j)));
            topple::atomic::write(&path, svg.as_bytes())
                .with_context(|| format!("writing {}", path.display()))?;
        }
        Ok(())
    }
}

/// `a` for the Table 1 row of Figs. 6/7, `b` for the ideal one.
fn series_tag(j: &Job) -> &'static str {
    if j.key == "ideal" {
        "b"
    } else {
        "a"
    }
}

/// The theory line's v̂_na at each spacing of the grid (NaN: no wave).
fn theory_points(line: &TheoryLine, grid: &[f64]) -> anyhow::Result<Vec<(f64, f64)>> {
    let sweep = theory::sweep(&[line.model], line.thickness_ratio, grid)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(sweep
        .iter()
        .map(|r| {
            let y = r.outcomes[0].natural_speed().unwrap_or(f64::NAN);
            (r.spacing_ratio, y)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::wave_is_steady;

    /// v̂_i = v∞ (1 − a e^(−i/L)): a wave that settles over L blocks.
    fn settling(n: usize, length: f64) -> Vec<f64> {
        (0..n)
            .map(|i| 2.0 * (1.0 - 0.3 * (-(i as f64) / length).exp()))
            .collect()
    }

    #[test]
    fn a_wave_that_settles_within_the_row_is_steady_and_a_rising_one_is_not() {
        // 40 blocks, settling over 5: the tail rises by 0.6 e^(−28/5) (1 − e^(−9/5)) ≈ 1.8·10⁻³, 0.09 %
        assert!(wave_is_steady(&settling(40, 5.0)));
        // settling over 20 blocks: the tail still rises by 0.6 (e^(−1.4) − e^(−1.85)) ≈ 0.054, 2.8 %
        assert!(!wave_is_steady(&settling(40, 20.0)));
        // a wave slowing down at the end is not "speeding up"
        let mut slowing = vec![2.0; 40];
        for (i, v) in slowing.iter_mut().enumerate().skip(28) {
            *v -= 0.01 * (i - 28) as f64;
        }
        assert!(wave_is_steady(&slowing));
        // a flat wave whose blocks scatter by ±4 %: no trend
        let scattered: Vec<f64> = (0..40)
            .map(|i| if i % 2 == 0 { 1.92 } else { 2.08 })
            .collect();
        assert!(wave_is_steady(&scattered));
        // too short to tell, or not finite
        assert!(!wave_is_steady(&[2.0; 11]));
        assert!(!wave_is_steady(&[f64::INFINITY; 20]));
    }
}
