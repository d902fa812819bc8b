//! Snapshots of the row as SVG (paper Fig. 6).

use std::fmt::Write;

use super::engine::Snapshot;
use crate::domino::Block;

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
    let mm = 1000.0;
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
    let width = (x1 - x0) * mm;
    let height = row_h * snaps.len() as f64 * mm;
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width:.2} {height:.2}" width="{:.0}" height="{:.0}">"#,
        width * 4.0,
        height * 4.0
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (k, s) in snaps.iter().enumerate() {
        let base = (k as f64 + 1.0) * row_h * mm - 0.2 * block.height * mm;
        let _ = writeln!(
            out,
            r#"<line x1="0" y1="{base:.2}" x2="{width:.2}" y2="{base:.2}" stroke="black" stroke-width="0.3"/>"#
        );
        let _ = writeln!(
            out,
            r#"<text x="1" y="{:.2}" font-size="{:.1}" font-family="sans-serif">t = {:.4} s</text>"#,
            base - 0.95 * block.height * mm,
            0.12 * block.height * mm,
            s.time
        );
        for q in s.blocks.iter().take(last + 1).skip(first) {
            let c = block.world_corners([q[0], q[1]], q[2]);
            let pts: Vec<String> = c
                .iter()
                .map(|p| format!("{:.3},{:.3}", (p[0] - x0) * mm, base - p[1] * mm))
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
