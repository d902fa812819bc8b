//! The `topple theory` command: JSON output, the sweep's files, bad arguments.

use std::process::Command;
use topple::theory::{solve, Geometry, Model};

fn topple(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_topple"))
        .arg("theory")
        .args(args)
        .output()
        .expect("run topple")
}

/// Arguments written on one line, split at spaces.
fn split(args: &str) -> Vec<&str> {
    args.split(' ').collect()
}

#[test]
fn json_has_natural_speed() {
    let out = topple(&split(
        "--model extended --mu 0.2 --thickness-ratio 0.12 --spacing-ratio 0.35 --json",
    ));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let lib = solve(
        &Model::Extended { mu: 0.2 },
        &Geometry::new(0.12, 0.35).unwrap(),
    )
    .unwrap()
    .natural_speed()
    .unwrap();
    // JSON text round trip of an f64 may be off by one unit in the last place
    let json_speed = v["natural_speed"].as_f64().unwrap();
    assert!(
        (json_speed - lib).abs() <= 4.0 * f64::EPSILON * lib,
        "{json_speed} vs {lib}"
    );
    assert_eq!(v["wave"], serde_json::Value::Bool(true));

    let out = topple(&split(
        "--model single --mu 0 --e 0 --thickness-ratio 0.12 --spacing-ratio 0.1 --json",
    ));
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["natural_speed"].is_null());
    assert!(v["reason"].as_str().unwrap().contains("gravity"));
}

#[test]
fn sweep_writes_csv_and_svg() {
    let dir = std::env::temp_dir().join(format!("topple-theory-{}", std::process::id()));
    let out = topple(&[
        "--thickness-ratio",
        "0.12",
        "--spacing-ratio",
        "0.1:0.9:0.1",
        "--mu",
        "0.15",
        "--e",
        "0.62",
        "--out",
        dir.to_str().unwrap(),
        "--name",
        "fig5",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join("fig5.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 1 + 9, "{csv}");
    assert!(lines[0].starts_with("s_over_h,cooperative,"));
    assert!(lines[9].starts_with("0.9,"));
    let svg = std::fs::read_to_string(dir.join("fig5.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("single collision"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_arguments_fail_cleanly() {
    // each case on one line, its arguments split at spaces
    let cases = [
        "--model cooperative --thickness-ratio 0.12 --spacing-ratio abc",
        "--model cooperative --thickness-ratio -1 --spacing-ratio 0.3",
        "--model cooperative --thickness-ratio 0.12 --spacing-ratio -0.3",
        "--model cooperative --thickness-ratio NaN --spacing-ratio 0.3",
        "--model cooperative --thickness-ratio 0.12 --spacing-ratio 0.3 --mu 0.2",
        "--model extended --thickness-ratio 0.12 --spacing-ratio 0.3",
        "--model extended --thickness-ratio 0.12 --spacing-ratio 0.3 --mu -1",
        "--model single --thickness-ratio 0.12 --spacing-ratio 0.3 --mu 0.1",
        "--model single --thickness-ratio 0.12 --spacing-ratio 0.3 --mu 0.1 --e 2",
        "--model bogus --thickness-ratio 0.12 --spacing-ratio 0.3",
        "--thickness-ratio 0.12 --spacing-ratio 0.3",
        "--thickness-ratio 0.12 --spacing-ratio 0.5:0.1:0.1 --mu 0.1 --e 0.5",
        "--thickness-ratio 0.12 --spacing-ratio 0.1:0.5 --mu 0.1 --e 0.5",
        "--thickness-ratio 0.12 --spacing-ratio 0.1:0.5:0 --mu 0.1 --e 0.5",
        "--thickness-ratio 0.12 --spacing-ratio 0.1:0.5:0.1",
    ];
    for case in cases {
        let args = split(case);
        let out = topple(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(err.starts_with("error"), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}
