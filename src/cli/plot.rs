//! Small SVG plots (plotters) and CSV files for `topple paper`.

use std::path::Path;

use anyhow::Context;
use plotters::prelude::*;

/// One curve of a plot.
pub struct Curve {
    /// Legend entry.
    pub name: String,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
    /// Draw markers (true) or a line (false).
    pub markers: bool,
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(200, 30, 30),
    RGBColor(30, 60, 200),
    RGBColor(20, 140, 40),
    RGBColor(160, 60, 160),
    RGBColor(220, 130, 0),
    RGBColor(0, 0, 0),
];

/// Writes an SVG plot of the curves.
pub fn plot(
    path: &Path,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    curves: &[Curve],
) -> anyhow::Result<()> {
    let pts = curves
        .iter()
        .flat_map(|c| c.points.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let dx = (x1 - x0).max(1e-9) * 0.05;
    let dy = (y1 - y0).max(1e-9) * 0.08;
    let root = SVGBackend::new(path, (720, 480)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(x0 - dx..x1 + dx, y0 - dy..y1 + dy)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc(xlabel)
        .y_desc(ylabel)
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    for (k, c) in curves.iter().enumerate() {
        let col = COLOURS[k % COLOURS.len()];
        let pts: Vec<(f64, f64)> = c
            .points
            .iter()
            .cloned()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        if c.markers {
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, col.filled())))
                .map_err(|e| anyhow::anyhow!("{e}"))?
                .label(c.name.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), 3, col.filled()));
        } else {
            chart
                .draw_series(LineSeries::new(pts, col.stroke_width(2)))
                .map_err(|e| anyhow::anyhow!("{e}"))?
                .label(c.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                });
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(())
}

/// Writes a CSV file: a header line and rows.
pub fn csv(path: &Path, header: &str, rows: &[Vec<f64>]) -> anyhow::Result<()> {
    let mut s = String::from(header);
    s.push('\n');
    for r in rows {
        let line: Vec<String> = r.iter().map(|v| format!("{v}")).collect();
        s.push_str(&line.join(","));
        s.push('\n');
    }
    std::fs::write(path, s).with_context(|| format!("writing {}", path.display()))
}
