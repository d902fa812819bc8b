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
    /// How the curve is drawn.
    pub style: Style,
    /// Colour; by default the curve's place in the palette.
    pub colour: Option<RGBColor>,
}

/// How a curve is drawn: simulation points as markers, theory as lines
/// (solid, dashed, or short dashes for the paper's dot-dash lines).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// Filled circles at the points.
    Markers,
    /// Filled circles joined by a thin line.
    MarkersLine,
    /// Open circles at the points: simulation points to be read with care
    /// (in `topple paper`'s sweeps, a wave still speeding up at the row's end).
    Open,
    /// A solid line.
    Line,
    /// A dashed line.
    Dashed,
    /// A line of short dashes (the paper's dot-dash lines).
    DotDash,
}

impl Style {
    fn is_line(self) -> bool {
        matches!(self, Style::Line | Style::Dashed | Style::DotDash)
    }
}

pub const COLOURS: [RGBColor; 6] = [
    RGBColor(200, 30, 30),
    RGBColor(30, 60, 200),
    RGBColor(20, 140, 40),
    RGBColor(160, 60, 160),
    RGBColor(220, 130, 0),
    RGBColor(0, 0, 0),
];

/// Writes an SVG plot of the curves, the legend in a corner free of points
/// (upper right above the data when no corner is free).
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
    let mut dy = (y1 - y0).max(1e-9) * 0.08;
    let (xa, xb, ya, yb) = (x0 - dx, x1 + dx, y0 - dy, y1 + dy);
    // the legend box as fractions of the plotting area (~650 x 390 px)
    let width = curves
        .iter()
        .map(|c| c.name.chars().count())
        .max()
        .unwrap_or(0) as f64;
    let (fw, fh) = (
        (40.0 + 7.0 * width) / 650.0,
        (14.0 + 20.0 * curves.iter().filter(|c| !c.name.is_empty()).count() as f64) / 390.0,
    );
    let inside = |left: bool, top: bool| -> usize {
        let (bx0, bx1) = if left {
            (xa, xa + fw * (xb - xa))
        } else {
            (xb - fw * (xb - xa), xb)
        };
        let (by0, by1) = if top {
            (yb - fh * (yb - ya), yb)
        } else {
            (ya, ya + fh * (yb - ya))
        };
        curves
            .iter()
            .flat_map(|c| c.points.iter())
            .filter(|p| p.0 >= bx0 && p.0 <= bx1 && p.1 >= by0 && p.1 <= by1)
            .count()
    };
    let legend = {
        let corners = [
            (false, true, SeriesLabelPosition::UpperRight),
            (true, true, SeriesLabelPosition::UpperLeft),
            (false, false, SeriesLabelPosition::LowerRight),
            (true, false, SeriesLabelPosition::LowerLeft),
        ];
        match corners.iter().find(|(l, t, _)| inside(*l, *t) == 0) {
            Some((_, _, pos)) => pos.clone(),
            None => {
                // room above the data
                dy += fh / (1.0 - fh) * (y1 - y0 + 2.0 * dy);
                SeriesLabelPosition::UpperRight
            }
        }
    };
    let mut svg = String::new();
    let bounds = (x0 - dx, x1 + dx, y0 - (y1 - y0).max(1e-9) * 0.08, y1 + dy);
    draw(&mut svg, title, xlabel, ylabel, curves, bounds, legend)?;
    topple::atomic::write(path, svg.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// Draws the plot into `svg` (the SVG text).
fn draw(
    svg: &mut String,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    curves: &[Curve],
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    legend: SeriesLabelPosition,
) -> anyhow::Result<()> {
    let root = SVGBackend::with_string(svg, (720, 480)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    // block numbers and other integer abscissae get integer tick labels only
    let integer_x = curves
        .iter()
        .flat_map(|c| c.points.iter())
        .all(|p| !p.0.is_finite() || p.0.fract() == 0.0);
    let integer_tick = |x: &f64| {
        if (x - x.round()).abs() < 1e-9 {
            format!("{}", x.round())
        } else {
            String::new()
        }
    };
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(xlabel).y_desc(ylabel);
    if integer_x {
        mesh.x_label_formatter(&integer_tick);
    }
    mesh.draw().map_err(|e| anyhow::anyhow!("{e}"))?;
    for (k, c) in curves.iter().enumerate() {
        let col = c.colour.unwrap_or(COLOURS[k % COLOURS.len()]);
        // contiguous runs of finite points: a non-finite y (no value) breaks a line
        let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for &p in &c.points {
            if p.0.is_finite() && p.1.is_finite() {
                segments.last_mut().expect("non-empty").push(p);
            } else if !segments.last().expect("non-empty").is_empty() {
                segments.push(Vec::new());
            }
        }
        segments.retain(|s| !s.is_empty());
        let pts: Vec<(f64, f64)> = segments.iter().flatten().cloned().collect();
        let line = col.stroke_width(2);
        let thin = col.stroke_width(1);
        let mut labelled = false;
        if c.style.is_line() {
            for seg in segments {
                let anno = match c.style {
                    Style::Dashed => chart.draw_series(DashedLineSeries::new(seg, 10, 6, line)),
                    Style::DotDash => chart.draw_series(DashedLineSeries::new(seg, 3, 5, line)),
                    _ => chart.draw_series(LineSeries::new(seg, line)),
                }
                .map_err(|e| anyhow::anyhow!("{e}"))?;
                if !labelled {
                    labelled = true;
                    label_series(anno, &c.name, c.style, col);
                }
            }
        } else {
            if c.style == Style::MarkersLine {
                for seg in &segments {
                    chart
                        .draw_series(LineSeries::new(seg.clone(), thin))
                        .map_err(|e| anyhow::anyhow!("{e}"))?;
                }
            }
            let marker = |p| match c.style {
                Style::Open => Circle::new(p, 3, col.stroke_width(1)),
                _ => Circle::new(p, 3, col.filled()),
            };
            let anno = chart
                .draw_series(pts.iter().map(|&p| marker(p)))
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            // a curve without a name adds points to an entry already shown
            if !c.name.is_empty() {
                label_series(anno, &c.name, c.style, col);
            }
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(legend)
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(())
}

/// Labels a series in the legend with a line or a marker, as it is drawn.
fn label_series<'a, DB: DrawingBackend + 'a>(
    anno: &mut plotters::chart::SeriesAnno<'a, DB>,
    name: &str,
    style: Style,
    col: RGBColor,
) {
    let line = col.stroke_width(2);
    anno.label(name).legend(move |(x, y)| {
        if style.is_line() {
            PathElement::new(vec![(x, y), (x + 20, y)], line).into_dyn()
        } else if style == Style::Open {
            Circle::new((x + 10, y), 3, col.stroke_width(1)).into_dyn()
        } else {
            Circle::new((x + 10, y), 3, col.filled()).into_dyn()
        }
    });
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
    topple::atomic::write(path, s.as_bytes()).with_context(|| format!("writing {}", path.display()))
}
