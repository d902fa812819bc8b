//! The theory lines of the paper's Fig. 5 as an SVG plot (plotters, SVG
//! backend only: no bitmap, no system fonts).

use super::{Model, Outcome, SweepRow, TheoryError};
use plotters::prelude::*;
use std::path::Path;

/// Draws v/√(gh) against s/h, one line per model (cooperative solid black,
/// extended dashed blue, single collision short-dashed red, as in Fig. 5's
/// solid, dash and dot-dash lines); spacings without a wave leave a gap.
///
/// ```no_run
/// use topple::theory::{plot_svg, sweep, Model};
/// let models = [Model::Cooperative, Model::Extended { mu: 0.15 }];
/// let spacings: Vec<f64> = (1..90).map(|i| i as f64 * 0.01).collect();
/// let rows = sweep(&models, 0.12, &spacings).unwrap();
/// plot_svg("fig5_theory.svg".as_ref(), 0.12, &models, &rows).unwrap();
/// ```
pub fn plot_svg(
    path: &Path,
    thickness_ratio: f64,
    models: &[Model],
    rows: &[SweepRow],
) -> Result<(), TheoryError> {
    draw(path, thickness_ratio, models, rows).map_err(|e| TheoryError::Output {
        path: path.to_path_buf(),
        message: format!("plot: {e}"),
    })
}

fn draw(
    path: &Path,
    thickness_ratio: f64,
    models: &[Model],
    rows: &[SweepRow],
) -> Result<(), Box<dyn std::error::Error>> {
    if rows.is_empty() {
        return Err("no spacings to plot".into());
    }
    let x0 = rows
        .iter()
        .map(|r| r.spacing_ratio)
        .fold(f64::INFINITY, f64::min);
    let x1 = rows
        .iter()
        .map(|r| r.spacing_ratio)
        .fold(f64::NEG_INFINITY, f64::max);
    let x1 = if x1 > x0 { x1 } else { x0 + 1e-3 };
    let y_max = rows
        .iter()
        .flat_map(|r| r.outcomes.iter().filter_map(Outcome::natural_speed))
        .fold(0.0_f64, f64::max);
    let y1 = if y_max > 0.0 { 1.1 * y_max } else { 1.0 };

    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("Natural speed of the domino wave, theory (d/h = {thickness_ratio})"),
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, 0.0..y1)?;
    chart
        .configure_mesh()
        .x_desc("s/h")
        .y_desc("v / √(gh)")
        .draw()?;

    for (i, model) in models.iter().enumerate() {
        let label = match *model {
            Model::Cooperative => "cooperative group (μ = 0)".to_string(),
            Model::Extended { mu } => format!("extended group (μ = {mu})"),
            Model::Single { mu, e } => format!("single collision (μ = {mu}, e = {e})"),
        };
        let color = match model {
            Model::Cooperative => BLACK,
            Model::Extended { .. } => BLUE,
            Model::Single { .. } => RED,
        };
        let style = color.stroke_width(2);
        // contiguous runs of spacings with a wave
        let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for r in rows {
            match r.outcomes.get(i).and_then(Outcome::natural_speed) {
                Some(v) => segments
                    .last_mut()
                    .expect("non-empty")
                    .push((r.spacing_ratio, v)),
                None => {
                    if !segments.last().expect("non-empty").is_empty() {
                        segments.push(Vec::new());
                    }
                }
            }
        }
        let mut labelled = false;
        for seg in segments.into_iter().filter(|s| !s.is_empty()) {
            let anno = match model {
                Model::Cooperative => chart.draw_series(LineSeries::new(seg, style))?,
                Model::Extended { .. } => {
                    chart.draw_series(DashedLineSeries::new(seg, 10, 6, style))?
                }
                Model::Single { .. } => {
                    chart.draw_series(DashedLineSeries::new(seg, 3, 5, style))?
                }
            };
            if !labelled {
                labelled = true;
                anno.label(label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
            }
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .draw()?;
    root.present()?;
    Ok(())
}
