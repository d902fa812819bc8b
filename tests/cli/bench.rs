//! `topple bench`: one table row per run, errors against the baseline run
//! computed from the saved reports, saved runs reused, bad runs refused.

use std::process::{Command, Output};

fn bench(out: &std::path::Path, runs: &str, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_topple"))
        .args([
            "bench",
            "--preset",
            "x",
            "--spacing-ratio",
            "0.52",
            "--n",
            "12",
            "--runs",
            runs,
            "--out",
        ])
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

fn saved_speed(dir: &std::path::Path, file: &str) -> f64 {
    let text = std::fs::read_to_string(dir.join(file)).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["report"]["natural_speed"].as_f64().unwrap()
}

#[test]
fn table_errors_are_against_the_baseline_and_saved_runs_are_reused() {
    let dir = std::env::temp_dir().join(format!("topple-cli-bench-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let runs = "reference:paper,reference:paper:5e-5,native:1e-3";
    let first = bench(&dir, runs, &[]);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let table = String::from_utf8(first.stdout).unwrap();
    // no adaptive run: the baseline is the reference run with the smaller step
    assert!(
        table
            .lines()
            .next()
            .unwrap()
            .ends_with("against reference:paper:5e-5"),
        "{table}"
    );
    let row = |name: &str| -> Vec<String> {
        let line = table
            .lines()
            .find(|l| l.starts_with(&format!("| {name} |")))
            .unwrap_or_else(|| panic!("no row {name} in\n{table}"));
        line.split('|').map(|c| c.trim().to_string()).collect()
    };
    // the error column, recomputed from the two saved reports
    let (v, base) = (
        saved_speed(&dir, "reference_paper.json"),
        saved_speed(&dir, "reference_paper_5e-5.json"),
    );
    let printed: f64 = row("reference:paper")[12].parse().unwrap();
    let expected = ((v - base) / base).abs();
    assert!(
        (printed - expected).abs() <= 0.01 * expected + 1e-12,
        "{printed} vs {expected}"
    );
    assert_eq!(row("reference:paper:5e-5")[12], "baseline");
    // native Rapier: time per step and its ratio column
    assert_eq!(row("native:1e-3")[9], "1");
    // every block hit in every run
    for name in ["reference:paper", "reference:paper:5e-5", "native:1e-3"] {
        assert_eq!(row(name)[3], "12/12", "{name}");
    }
    // the reference engine hits the blocks in order
    assert_eq!(row("reference:paper")[4], "0");
    // the front speed is distance over time, the harmonic mean of the v̂_i
    // over the same blocks, so it cannot exceed their arithmetic mean v̂_na
    let front: f64 = row("reference:paper")[5].parse().unwrap();
    assert!(front > 0.0 && front <= v * (1.0 + 1e-9), "{front} vs {v}");
    let stderr = String::from_utf8_lossy(&first.stderr);
    assert!(
        stderr.contains("[1/3] reference:paper: running"),
        "{stderr}"
    );

    // a second call reuses the saved reports: same table, nothing run
    let second = bench(&dir, runs, &[]);
    assert!(second.status.success());
    assert_eq!(String::from_utf8(second.stdout).unwrap(), table);
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert_eq!(stderr.matches("saved report reused").count(), 3, "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_runs_and_baselines_are_refused_with_one_line() {
    let dir = std::env::temp_dir().join(format!("topple-cli-bench-bad-{}", std::process::id()));
    for (runs, extra) in [
        ("rapier:1e-3:f16", &[][..]),
        ("rapier:fast", &[][..]),
        ("native:0", &[][..]),
        ("reference:fast", &[][..]),
        ("reference:paper", &["--baseline", "native:1e-3"][..]),
    ] {
        let out = bench(&dir, runs, extra);
        assert_eq!(out.status.code(), Some(1), "{runs} {extra:?}");
        assert!(out.stdout.is_empty());
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("error: "), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_plot_has_a_series_per_engine_and_changed_settings_rerun() {
    let dir = std::env::temp_dir().join(format!("topple-cli-bench-plot-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let svg = dir.join("work-precision.svg");
    let runs = "reference:paper:imp:fixed,reference:paper,native:1e-3";
    let extra = [
        "--baseline",
        "reference:paper:imp:fixed",
        "--plot",
        svg.to_str().unwrap(),
    ];
    let first = bench(&dir, runs, &extra);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let plot = std::fs::read_to_string(&svg).unwrap();
    assert!(plot.starts_with("<svg"), "{}", &plot[..80.min(plot.len())]);
    // the baseline is the only fixed-step run, so that series is empty
    assert!(plot.contains("reference, impacts in time"));
    assert!(plot.contains("native Rapier"));
    assert!(!plot.contains("reference, fixed impulse step"));

    // another freeze tolerance: the reference runs' saved reports do not
    // match their settings and run again; the Rapier run is reused
    let mut changed = extra.to_vec();
    changed.extend(["--freeze-tolerance", "1e-3"]);
    let second = bench(&dir, runs, &changed);
    assert!(second.status.success());
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert_eq!(stderr.matches(": running").count(), 2, "{stderr}");
    assert_eq!(stderr.matches("saved report reused").count(), 1, "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}
