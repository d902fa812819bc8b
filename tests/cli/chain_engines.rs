//! `topple chain --engine rapier|rapier-native` reports with the reference
//! engine's JSON keys, and bad engine arguments are errors.

use std::process::Command;

fn chain(engine: &str, extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_topple"))
        .args([
            "chain",
            "--preset",
            "t",
            "--ideal",
            "--spacing-ratio",
            "0.35",
            "--n",
            "12",
            "--push",
            "1.0",
            "--engine",
            engine,
            "--dt",
            "5e-4",
            "--json",
        ])
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn rapier_engines_report_the_reference_keys() {
    for engine in ["rapier", "rapier-native"] {
        let out = chain(engine, &[]);
        assert!(
            out.status.success(),
            "{engine}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["engine"].as_str().unwrap(), engine);
        let hits = v["hit_times"].as_array().unwrap();
        assert_eq!(hits.len(), 12, "{engine}: every block is hit");
        // hit times increase along the row
        let t: Vec<f64> = hits.iter().map(|x| x.as_f64().unwrap()).collect();
        assert!(t.windows(2).all(|w| w[1] > w[0]));
        assert!(v["speeds"].as_array().unwrap().len() >= 10);
        // 12 blocks: v̂_na over blocks 7.. exists and is near the cooperative
        // model's 1.8023 (Domino T, s/h 0.35; rapier-notes.md) within 10 %
        let na = v["natural_speed"].as_f64().unwrap();
        assert!((na - 1.8023).abs() < 0.18, "{engine}: {na}");
    }
}

#[test]
fn a_bad_time_step_is_an_error() {
    let out = chain("rapier", &["--dt", "0"]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
}

/// The issue writes `--preset X|T|P`: upper and lower case name the same row,
/// and an unknown preset is a one-line error with nothing on stdout.
#[test]
fn preset_names_ignore_case() {
    let run = |preset: &str| {
        Command::new(env!("CARGO_BIN_EXE_topple"))
            .args(["chain", "--preset", preset, "--spacing-ratio", "0.35"])
            .args(["--n", "8", "--engine", "rapier", "--dt", "1e-3", "--json"])
            .output()
            .unwrap()
    };
    let (upper, lower) = (run("T"), run("t"));
    assert!(
        upper.status.success(),
        "{}",
        String::from_utf8_lossy(&upper.stderr)
    );
    let report = |o: &std::process::Output| {
        let mut v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v.as_object_mut().unwrap().remove("run_time"); // wall clock
        v
    };
    assert_eq!(report(&upper), report(&lower));
    let bad = run("Q");
    assert!(!bad.status.success());
    assert!(bad.stdout.is_empty());
}

/// `topple scene --engine X --json` names the engine as the command line
/// does (the names a JSON report has always carried).
#[test]
fn the_scene_report_names_the_engine_as_the_command_line_does() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/cradle-3.toml");
    for engine in ["rapier", "rapier-native"] {
        let out = Command::new(env!("CARGO_BIN_EXE_topple"))
            .args(["scene", file, "--engine", engine, "--json"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{engine}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["engine"].as_str(), Some(engine), "{engine}");
    }
}
