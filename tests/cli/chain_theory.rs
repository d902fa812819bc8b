//! `topple chain` prints the theory's natural speed beside the measured one:
//! the value printed is the model's, solved here through the library.

use std::process::Command;

use topple::domino::Preset;
use topple::theory::{solve, Geometry, Model};

#[test]
fn chain_prints_the_cooperative_speed_for_the_ideal_material() {
    let out = Command::new(env!("CARGO_BIN_EXE_topple"))
        .args([
            "chain",
            "--preset",
            "t",
            "--ideal",
            "--spacing-ratio",
            "0.45",
            "--n",
            "10",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text
        .lines()
        .find(|l| l.starts_with("theory: "))
        .unwrap_or_else(|| panic!("no theory line in\n{text}"));
    assert!(line.contains("cooperative model"), "{line}");
    let printed: f64 = line
        .trim_start_matches("theory: v̂_na = ")
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let b = Preset::T.params().block;
    let geom = Geometry::new(b.thickness / b.height, 0.45).unwrap();
    let v = solve(&Model::Cooperative, &geom)
        .unwrap()
        .natural_speed()
        .unwrap();
    assert!((printed - v).abs() <= 5e-5, "printed {printed}, model {v}");
}

#[test]
fn chain_names_the_single_collision_model_when_blocks_bounce() {
    let out = Command::new(env!("CARGO_BIN_EXE_topple"))
        .args([
            "chain",
            "--preset",
            "t",
            "--spacing-ratio",
            "0.45",
            "--n",
            "10",
            "--e1",
            "0.5",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.lines()
            .any(|l| l.starts_with("theory: ") && l.contains("single model")),
        "{text}"
    );
}
