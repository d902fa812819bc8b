//! Snapshots of the row: the
//! PNG drawing is checked against the geometry of hand-placed blocks (where
//! their centres and the gaps between them fall, and the area they cover),
//! and `topple chain` writes it and refuses drawing options that would be
//! silently ignored.

use std::io::Cursor;
use std::process::Command;

use topple::domino::Block;
use topple::reference::{snapshot_png, Snapshot, PNG_BLOCK};

/// Decodes an 8-bit RGB PNG into (width, height, pixels).
fn decode(png: &[u8]) -> (usize, usize, Vec<u8>) {
    let decoder = png::Decoder::new(Cursor::new(png));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width as usize, info.height as usize, buf)
}

#[test]
fn png_puts_blocks_where_they_stand() {
    // Two blocks 80 mm × 10 mm: one upright at x = 0, one turned 30° forward
    // (φ = −30°) at x = 40 mm with its centre 35 mm up. Layout (the SVG's):
    // x from the first block's centre − 0.3 h, one row 1.5 h tall with the
    // ground 0.2 h above its bottom; 4 px per mm.
    let (h, d) = (0.08, 0.01);
    let block = Block::new(h, d);
    let phi = -30f64.to_radians();
    let snap = Snapshot {
        time: 0.0,
        blocks: vec![[0.0, 0.04, 0.0], [0.04, 0.035, phi]],
    };
    let px = 4.0;
    let png = snapshot_png(&block, &[snap], 0, 1, px).unwrap();
    let (w, ht, rgb) = decode(&png);
    let x0 = -0.3 * h;
    let ground = (1.5 * h - 0.2 * h) * 1000.0; // mm from the top
    assert_eq!(w, ((0.04 + h + 0.3 * h - x0) * 1000.0 * px).ceil() as usize);
    assert_eq!(ht, (1.5 * h * 1000.0 * px).ceil() as usize);
    let pixel = |x_m: f64, y_m: f64| {
        let col = ((x_m - x0) * 1000.0 * px).floor() as usize;
        let row = ((ground - y_m * 1000.0) * px).floor() as usize;
        let k = 3 * (row * w + col);
        [rgb[k], rgb[k + 1], rgb[k + 2]]
    };
    // inside each block, off its outline
    assert_eq!(pixel(0.0, 0.04), PNG_BLOCK);
    assert_eq!(pixel(0.0, 0.07), PNG_BLOCK);
    assert_eq!(pixel(0.04, 0.035), PNG_BLOCK);
    // 25 mm along the turned block's axis from its centre
    let (s, c) = phi.sin_cos();
    assert_eq!(pixel(0.04 - 0.025 * s, 0.035 + 0.025 * c), PNG_BLOCK);
    // paper between them and above the upright one
    assert_eq!(pixel(0.015, 0.02), [255, 255, 255]);
    assert_eq!(pixel(0.0, 0.09), [255, 255, 255]);
    // the ground line is ink
    let row = (ground * px).floor() as usize;
    let k = 3 * (row * w + ((0.02 - x0) * 1000.0 * px) as usize);
    assert_eq!(&rgb[k..k + 3], &[0, 0, 0]);
    // Blocks cover 2 h d of the drawing: fill plus outline (ink) pixels
    // against the closed form, to the outline's width (perimeter × 1 px).
    let covered = rgb
        .chunks(3)
        .filter(|p| *p == PNG_BLOCK || (*p == [0, 0, 0]))
        .count() as f64
        - w as f64; // the ground line
    let area = 2.0 * h * d * 1e6 * px * px;
    let outline = 2.0 * 2.0 * (h + d) * 1000.0 * px;
    println!("covered {covered} px, closed form {area} px, outline {outline} px");
    assert!(
        (covered - area).abs() < outline,
        "{covered} px against {area} ± {outline}"
    );
}

fn chain(extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_topple"))
        .args([
            "chain",
            "--preset",
            "x",
            "--spacing-ratio",
            "0.52",
            "--n",
            "6",
        ])
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn chain_writes_png_and_svg_snapshots() {
    let dir = std::env::temp_dir().join(format!("topple-snapshots-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (png, svg) = (dir.join("row.png"), dir.join("row.svg"));
    let out = chain(&[
        "--snapshots",
        "0.05,0.1",
        "--png",
        png.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (w, h, rgb) = decode(&std::fs::read(&png).unwrap());
    assert!(w > 0 && h > 0);
    // two snapshots of six blocks: block colour present, two ground lines
    assert!(rgb.chunks(3).any(|p| p == PNG_BLOCK));
    let svg = std::fs::read_to_string(&svg).unwrap();
    assert_eq!(svg.matches("<polygon").count(), 12);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn chain_refuses_drawing_options_it_would_ignore() {
    // each refusal names the option at fault, before any work (exit 2)
    for (args, needle) in [
        (vec!["--snapshots", "0.1"], "error: --snapshots "),
        (vec!["--png", "x.png"], "error: --svg/--png "),
        (vec!["--series", "7"], "error: --series = 7"),
        (
            vec!["--engine", "rapier", "--series", "2"],
            "--engine reference only",
        ),
    ] {
        let out = chain(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn series_go_to_a_csv_file_not_to_stdout() {
    let dir = std::env::temp_dir().join(format!("topple-series-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("series.csv");
    let out = chain(&[
        "--series",
        "2,3",
        "--series-csv",
        csv.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("block,t_s,theta_rad,theta_dot_rad_per_s")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    // one CSV row per recorded sample of each block, the same values as the
    // JSON report's series (printed there with full precision)
    for s in report["series"].as_array().unwrap() {
        let block = s["block"].as_f64().unwrap();
        let theta: Vec<f64> = serde_json::from_value(s["theta"].clone()).unwrap();
        let mine: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] == block).collect();
        assert_eq!(mine.len(), theta.len());
        for (r, t) in mine.iter().zip(&theta) {
            assert!((r[2] - t).abs() < 1e-8, "{} vs {t}", r[2]);
        }
    }
    // alone, either option is refused before any work
    for args in [
        vec!["--series", "2"],
        vec!["--series-csv", csv.to_str().unwrap()],
    ] {
        let out = chain(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
