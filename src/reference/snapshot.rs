//! Snapshots of the row as SVG or PNG (paper Fig. 6).

use std::fmt::Write;

use crate::domino::Block;

/// The whole row at one time.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Snapshot {
    /// Time (s).
    pub time: f64,
    /// (x, y, φ) of every block: centre (m) and counter-clockwise angle (rad).
    pub blocks: Vec<[f64; 3]>,
}

/// An SVG drawing of the row at the given snapshots, one above the other,
/// blocks from `first` to `last` (0-based, inclusive). Coordinates in mm.
///
/// ```
/// use topple::domino::Block;
/// use topple::reference::{snapshot_svg, Snapshot};
/// let s = Snapshot { time: 0.0, blocks: vec![[0.0, 0.04, 0.0], [0.03, 0.04, 0.0]] };
/// let svg = snapshot_svg(&Block::new(0.08, 0.01), &[s], 0, 1);
/// assert!(svg.starts_with("<svg") && svg.matches("<polygon").count() == 2);
/// ```
pub fn snapshot_svg(block: &Block, snaps: &[Snapshot], first: usize, last: usize) -> String {
    let layout = Layout::new(block, snaps, first, last);
    let (width, height) = (layout.width, layout.height);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width:.2} {height:.2}" width="{:.0}" height="{:.0}">"#,
        width * 4.0,
        height * 4.0
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (k, s) in snaps.iter().enumerate() {
        let base = layout.baseline(k);
        let _ = writeln!(
            out,
            r#"<line x1="0" y1="{base:.2}" x2="{width:.2}" y2="{base:.2}" stroke="black" stroke-width="0.3"/>"#
        );
        let _ = writeln!(
            out,
            r#"<text x="1" y="{:.2}" font-size="{:.1}" font-family="sans-serif">t = {:.4} s</text>"#,
            base - 0.95 * block.height * MM,
            0.12 * block.height * MM,
            s.time
        );
        for q in s.blocks.iter().take(last + 1).skip(first) {
            let pts: Vec<String> = layout
                .corners(block, q, base)
                .iter()
                .map(|p| format!("{:.3},{:.3}", p[0], p[1]))
                .collect();
            let _ = writeln!(
                out,
                r##"<polygon points="{}" fill="#d9a441" stroke="black" stroke-width="0.2"/>"##,
                pts.join(" ")
            );
        }
    }
    out.push_str("</svg>\n");
    out
}

/// Millimetres per metre: drawings are laid out in mm.
const MM: f64 = 1000.0;

/// Fill of a block in the PNG (the SVG's colour), its outline and the ground.
pub const PNG_BLOCK: [u8; 3] = [0xd9, 0xa4, 0x41];
#[cfg(feature = "plots")]
const PNG_INK: [u8; 3] = [0, 0, 0];
#[cfg(feature = "plots")]
const PNG_PAPER: [u8; 3] = [0xff, 0xff, 0xff];

/// The drawing's frame, in mm: snapshots stacked top to bottom, each row
/// 1.5 h tall with its ground line 0.2 h above the row's bottom edge.
struct Layout {
    x0: f64,
    row_h: f64,
    drop: f64,
    width: f64,
    height: f64,
}

impl Layout {
    fn new(block: &Block, snaps: &[Snapshot], first: usize, last: usize) -> Self {
        let pad = 0.3 * block.height;
        let x0 = snaps
            .iter()
            .filter_map(|s| s.blocks.get(first))
            .map(|q| q[0])
            .fold(f64::INFINITY, f64::min)
            - pad;
        let x1 = snaps
            .iter()
            .filter_map(|s| s.blocks.get(last))
            .map(|q| q[0])
            .fold(f64::NEG_INFINITY, f64::max)
            + block.height
            + pad;
        let row_h = 1.5 * block.height;
        Layout {
            x0,
            row_h,
            drop: 0.2 * block.height * MM,
            width: (x1 - x0) * MM,
            height: row_h * snaps.len() as f64 * MM,
        }
    }

    /// y (mm, downwards) of snapshot k's ground line.
    fn baseline(&self, k: usize) -> f64 {
        (k as f64 + 1.0) * self.row_h * MM - self.drop
    }

    /// The corners of a block at (x, y, φ) in drawing mm.
    fn corners(&self, block: &Block, q: &[f64; 3], base: f64) -> [[f64; 2]; 4] {
        block
            .world_corners([q[0], q[1]], q[2])
            .map(|p| [(p[0] - self.x0) * MM, base - p[1] * MM])
    }
}

/// A PNG drawing (feature `plots`) of the same snapshots as [`snapshot_svg`] (same layout,
/// without the time labels: there is no font rasteriser here), at
/// `px_per_mm` pixels per millimetre of the drawing (4 matches the SVG's
/// nominal size; the width is capped at 16,384 px). Blocks are filled with
/// [`PNG_BLOCK`] and outlined in black; the ground of each snapshot is a
/// black line.
///
/// ```
/// use topple::domino::Block;
/// use topple::reference::{snapshot_png, Snapshot};
/// let s = Snapshot { time: 0.0, blocks: vec![[0.0, 0.04, 0.0], [0.03, 0.04, 0.0]] };
/// let png = snapshot_png(&Block::new(0.08, 0.01), &[s], 0, 1, 4.0).unwrap();
/// assert_eq!(&png[1..4], b"PNG");
/// ```
#[cfg(feature = "plots")]
pub fn snapshot_png(
    block: &Block,
    snaps: &[Snapshot],
    first: usize,
    last: usize,
    px_per_mm: f64,
) -> Result<Vec<u8>, png::EncodingError> {
    let layout = Layout::new(block, snaps, first, last);
    let scale = px_per_mm.min(16_384.0 / layout.width.max(1e-9)).max(1e-3);
    let w = ((layout.width * scale).ceil() as usize).max(1);
    let h = ((layout.height * scale).ceil() as usize).max(1);
    let mut canvas = Canvas {
        w,
        h,
        rgb: PNG_PAPER.repeat(w * h),
    };
    for (k, s) in snaps.iter().enumerate() {
        let base = layout.baseline(k);
        canvas.line([0.0, base * scale], [w as f64, base * scale], PNG_INK);
        for q in s.blocks.iter().take(last + 1).skip(first) {
            let c = layout
                .corners(block, q, base)
                .map(|p| [p[0] * scale, p[1] * scale]);
            canvas.fill_convex(&c, PNG_BLOCK);
            for e in 0..4 {
                canvas.line(c[e], c[(e + 1) % 4], PNG_INK);
            }
        }
    }
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w as u32, h as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&canvas.rgb)?;
    writer.finish()?;
    Ok(out)
}

#[cfg(feature = "plots")]
/// An RGB raster, row by row from the top.
struct Canvas {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
}

#[cfg(feature = "plots")]
impl Canvas {
    fn put(&mut self, x: i64, y: i64, colour: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as usize) < self.w && (y as usize) < self.h {
            let k = 3 * (y as usize * self.w + x as usize);
            self.rgb[k..k + 3].copy_from_slice(&colour);
        }
    }

    /// Fills a convex polygon: every pixel whose centre lies inside.
    fn fill_convex(&mut self, poly: &[[f64; 2]], colour: [u8; 3]) {
        let (ymin, ymax) = poly
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p[1]), b.max(p[1]))
            });
        let first = (ymin - 0.5).ceil().max(0.0) as i64;
        let last = ((ymax - 0.5).floor() as i64).min(self.h as i64 - 1);
        for py in first..=last {
            let yc = py as f64 + 0.5;
            // the row of pixel centres crosses the polygon's edges at two x
            let (mut xl, mut xr) = (f64::INFINITY, f64::NEG_INFINITY);
            for e in 0..poly.len() {
                let (a, b) = (poly[e], poly[(e + 1) % poly.len()]);
                if (a[1] <= yc && yc < b[1]) || (b[1] <= yc && yc < a[1]) {
                    let x = a[0] + (yc - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                    xl = xl.min(x);
                    xr = xr.max(x);
                }
            }
            if xl > xr {
                continue;
            }
            let from = (xl - 0.5).ceil() as i64;
            let to = (xr - 0.5).floor() as i64;
            for px in from..=to {
                self.put(px, py, colour);
            }
        }
    }

    /// A one-pixel line (DDA).
    fn line(&mut self, a: [f64; 2], b: [f64; 2], colour: [u8; 3]) {
        let n = (b[0] - a[0]).abs().max((b[1] - a[1]).abs()).ceil().max(1.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let x = a[0] + t * (b[0] - a[0]);
            let y = a[1] + t * (b[1] - a[1]);
            self.put(x.floor() as i64, y.floor() as i64, colour);
        }
    }
}
