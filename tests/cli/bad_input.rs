//! Bad input is refused before any work starts: exit status 2, one line on
//! stderr naming the field, the value and the allowed range, nothing on
//! stdout and no output file. One test per row of the table of bad inputs
//! found by trying the CLI as a new user would, and the classes they stand
//! for (zero, negative, NaN, infinite, too large, degenerate, inconsistent).

use std::path::{Path, PathBuf};
use std::process::Command;

fn topple(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_topple"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// A fresh empty directory under the system's temp dir.
fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topple-bad-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Refused with status 2 and one line naming `field` (and `value`), nothing
/// on stdout.
fn refused(args: &[&str], field: &str, value: &str) -> String {
    let (code, stdout, stderr) = topple(args);
    assert_eq!(code, 2, "{args:?}: stdout {stdout} stderr {stderr}");
    assert!(stdout.is_empty(), "{args:?}: {stdout}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(stderr.contains(field), "{args:?}: {stderr} lacks {field}");
    assert!(stderr.contains(value), "{args:?}: {stderr} lacks {value}");
    stderr
}

fn chain(extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = ["chain", "--spacing-ratio", "0.3", "--n", "5"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    v.extend(extra.iter().map(|s| s.to_string()));
    v
}

fn refused_chain(extra: &[&str], field: &str, value: &str) -> String {
    let args = chain(extra);
    let a: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    refused(&a, field, value)
}

#[test]
fn time_step_zero_negative_nan_or_too_large_is_refused() {
    // a zero step used to hang the reference engine; NaN and 1 s gave
    // meaningless numbers with exit 0
    for dt in ["0", "-1e-4", "-0", "NaN", "inf", "1", "0.01", "1e-9"] {
        let e = refused_chain(&["--dt", dt], "--dt", "allowed 1e-7 ≤ --dt ≤ 0.0033");
        assert!(e.contains("--dt = "), "{e}");
    }
    for engine in ["rapier", "rapier-native"] {
        for dt in ["0", "-1", "NaN", "0.1", "1e-7"] {
            refused_chain(&["--engine", engine, "--dt", dt], "--dt", "1e-6 ≤ --dt");
        }
    }
}

#[test]
fn a_run_too_long_for_its_budget_is_refused_before_it_starts() {
    // 60 s at 1 µs: 6·10⁷ Rapier steps
    refused_chain(
        &["--engine", "rapier", "--dt", "1e-6"],
        "--max-time",
        "1e7 Rapier steps",
    );
}

#[test]
fn a_row_too_large_for_memory_is_refused_with_an_estimate() {
    // used to be killed by the kernel after 24 GB, with no message
    let e = refused(
        &["chain", "--spacing-ratio", "0.3", "--n", "1000000000"],
        "--n = 1000000000",
        "needs about",
    );
    assert!(e.contains("GiB"), "{e}");
    refused(
        &[
            "chain",
            "--spacing-ratio",
            "0.3",
            "--n",
            "1000000000",
            "--engine",
            "rapier",
        ],
        "--n",
        "needs about",
    );
}

#[test]
fn row_sizes_out_of_range_are_refused() {
    for n in ["0", "1"] {
        refused(
            &["chain", "--spacing-ratio", "0.3", "--n", n],
            "--n",
            "2 ≤ --n",
        );
    }
}

#[test]
fn row_parameters_out_of_range_are_refused() {
    let cases: &[(&[&str], &str)] = &[
        (&["--push", "0"], "--push"),
        (&["--push", "-1"], "--push"),
        (&["--push", "NaN"], "--push"),
        (&["--mu1", "-0.1"], "--mu1"),
        (&["--mu2", "inf"], "--mu2"),
        (&["--e1", "1.5"], "--e1"),
        (&["--e2", "-0.2"], "--e2"),
        (&["--k1", "0"], "--k1"),
        (&["--alpha", "0"], "--alpha"),
        (&["--lambda", "1"], "--lambda"),
        (&["--height", "-0.04"], "--height"),
        (&["--thickness", "0.1"], "--thickness"),
        (
            &["--impact-friction-factor", "2"],
            "--impact-friction-factor",
        ),
        (&["--mu1", "0.3", "--mu1-stick", "0.2"], "--mu1-stick"),
        (&["--tolerance", "0"], "--tolerance"),
        (&["--tolerance", "NaN"], "--tolerance"),
        (&["--window", "0"], "--window"),
        (&["--wall-limit", "0"], "--wall-limit"),
        (&["--series", "9"], "--series"),
        (&["--impact-step", "0"], "--impact-step"),
        (&["--impact-step", "1"], "--impact-step"),
        (&["--impact-tolerance", "NaN"], "--impact-tolerance"),
        (&["--impact-tolerance", "0.5"], "--impact-tolerance"),
        (
            &["--engine", "rapier", "--impact-step", "1e-4"],
            "--impact-step/--impact-tolerance",
        ),
    ];
    for (extra, field) in cases {
        refused_chain(extra, field, "allowed");
    }
    for sh in ["0", "-0.3", "1", "1.5", "NaN"] {
        refused(
            &["chain", "--spacing-ratio", sh, "--n", "5"],
            "--spacing-ratio",
            "0 < --spacing-ratio < 1",
        );
    }
}

#[test]
fn snapshot_files_are_not_written_for_a_refused_run() {
    let d = temp_dir("snap");
    let svg = d.join("row.svg");
    let s = svg.to_str().unwrap();
    refused_chain(
        &["--dt", "0", "--snapshots", "0.1", "--svg", s],
        "--dt",
        "0",
    );
    assert!(!svg.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn paper_refuses_bad_figures_and_sizes_and_writes_nothing() {
    // `--figs 11` said it succeeded and wrote nothing; `--n 0` exited 0
    let d = temp_dir("paper");
    let out = d.join("figs");
    let o = out.to_str().unwrap();
    refused(&["paper", "--out", o, "--figs", "11"], "--figs", "11");
    refused(&["paper", "--out", o, "--figs", "2,3"], "--figs", "2");
    refused(&["paper", "--out", o, "--n", "0"], "--n", "0");
    refused(
        &["paper", "--out", o, "--tolerance", "0"],
        "--tolerance",
        "0",
    );
    refused(
        &["paper", "--out", o, "--spacings", "0.3,-0.1"],
        "--spacings",
        "-0.1",
    );
    refused(
        &["paper", "--out", o, "--run-limit", "0"],
        "--run-limit",
        "0",
    );
    assert!(!out.exists(), "a refused run created {}", out.display());
    std::fs::remove_dir_all(&d).unwrap();
}

fn impact_file(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

const ONE_BALL: &str = r#"{"bodies": [{"mass": 1.0, "inertia": 0.1, "position": [0.0, 0.0], "angle": 0.0,
 "velocity": [V, 0.0], "angular_velocity": 0.0, "fixed": false}],
 "contacts": [{"bodies": [0, null], "point": [0.5, 0.0], "normal": [1.0, 0.0],
 "stiffness": 1e9, "exponent": 1.5, "restitution": 1.0, "friction": 0.0, "stick_friction": 0.0}],
 "impulse_step": 1e-4, "tolerance": null}"#;

#[test]
fn impact_magnitudes_that_overflow_or_underflow_are_refused() {
    // v = 1e200 used to end in a misleading step-limit error
    let d = temp_dir("impact");
    for (v, field) in [
        ("1e200", "bodies[0].velocity[0] = 1e200"),
        ("-1e7", "bodies[0].velocity[0]"),
        ("1e-300", "the fastest body speed = 1e-300"),
    ] {
        let f = impact_file(&d, "i.json", &ONE_BALL.replace('V', v));
        refused(&["impact", &f], field, "allowed");
    }
    let good = impact_file(&d, "g.json", &ONE_BALL.replace('V', "1.0"));
    assert_eq!(topple(&["impact", &good]).0, 0);
    let bad_normal = impact_file(
        &d,
        "n.json",
        &ONE_BALL
            .replace('V', "1.0")
            .replace("\"normal\": [1.0, 0.0]", "\"normal\": [2.0, 0.0]"),
    );
    refused(
        &["impact", &bad_normal],
        "contacts[0].normal",
        "unit vector",
    );
    let bad_json = impact_file(&d, "j.json", "{\"bodies\": [}");
    refused(&["impact", &bad_json], "input JSON:1:", "expected");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn negative_numbers_in_flags_read_as_numbers() {
    // clap used to report "unexpected argument '-1'" for `--dt -1e-4`
    let e = refused_chain(&["--dt", "-1e-4"], "--dt = -0.0001", "allowed");
    assert!(!e.contains("unexpected argument"), "{e}");
}

const ROW_SCENE: &str = r#"duration = 1.0
[solver]
dt = 5e-4
[row]
preset = "X"
n = 10
spacing = SPACING
push = PUSH
"#;

fn scene_refused(dir: &Path, text: &str, field: &str, value: &str) {
    let f = impact_file(dir, "s.toml", text);
    refused(&["scene", &f], field, value);
}

#[test]
fn scene_rows_with_degenerate_values_are_refused_at_load() {
    // spacing NaN or 0 and push 0 used to give NaN or inf with exit 0;
    // mass -1 failed in the middle of the run
    let d = temp_dir("scene-row");
    let row = |s: &str, p: &str| ROW_SCENE.replace("SPACING", s).replace("PUSH", p);
    scene_refused(
        &d,
        &row("nan", "1.0"),
        "row.spacing = NaN",
        "0 < row.spacing < 1",
    );
    scene_refused(
        &d,
        &row("0.0", "1.0"),
        "row.spacing = 0",
        "0 < row.spacing < 1",
    );
    scene_refused(&d, &row("0.3", "0.0"), "row.push = 0", "0 < row.push");
    scene_refused(
        &d,
        &(row("0.3", "1.0") + "mass = -1.0\n"),
        "row.mass = -1",
        "0 < row.mass",
    );
    scene_refused(
        &d,
        &(row("0.3", "1.0") + "e1 = 2.0\n"),
        "row.e1 = 2",
        "row.e1 ≤ 1",
    );
    scene_refused(
        &d,
        &ROW_SCENE
            .replace("SPACING", "0.3")
            .replace("PUSH", "1.0")
            .replace("n = 10", "n = 1"),
        "row.n = 1",
        "2 ≤ row.n",
    );
    std::fs::remove_dir_all(&d).unwrap();
}

const BALLS: &str = r#"duration = 0.01
gravity = [0.0, 0.0]
[[materials]]
name = "steel"
stiffness = 2.3e10
[[bodies]]
shape = "ball"
radius = R1
position = [0.0, 0.0]
velocity = [1.0, 0.0]
mass = M1
material = "steel"
[[bodies]]
shape = "ball"
radius = 0.05
position = [X2, 0.0]
mass = 1.0
material = "steel"
"#;

fn balls(r1: &str, m1: &str, x2: &str) -> String {
    BALLS.replace("R1", r1).replace("M1", m1).replace("X2", x2)
}

#[test]
fn scene_bodies_degenerate_or_overlapping_are_refused() {
    // overlapping bodies used to be pushed apart silently
    let d = temp_dir("scene-bodies");
    scene_refused(
        &d,
        &balls("-0.05", "1.0", "0.1"),
        "bodies[0].radius = -0.05",
        "1e-6 ≤",
    );
    scene_refused(
        &d,
        &balls("0.0", "1.0", "0.1"),
        "bodies[0].radius = 0",
        "1e-6 ≤",
    );
    scene_refused(
        &d,
        &balls("0.05", "-1.0", "0.1"),
        "bodies[0].mass = -1",
        "0 < bodies[0].mass",
    );
    scene_refused(
        &d,
        &balls("0.05", "1.0", "0.08"),
        "bodies[0] and bodies[1]",
        "overlapping by 0.02",
    );
    // touching (the cradle) is fine: no error from the checks
    let f = impact_file(&d, "ok.toml", &balls("0.05", "1.0", "0.1"));
    let (code, _, stderr) = topple(&["scene", &f]);
    assert_eq!(code, 0, "{stderr}");
    // a box reaching into the ground
    let boxed = r#"duration = 0.1
[[materials]]
name = "m"
stiffness = 1e9
[ground]
material = "m"
[[bodies]]
shape = "box"
size = [0.2, 0.1]
position = [0.0, 0.03]
angle = 0.0
material = "m"
"#;
    scene_refused(&d, boxed, "bodies[0]", "below the ground");
    // a rotated box clear of a ball by 1 cm is fine, at 45° it reaches in
    let two = |angle: &str| {
        format!(
            "duration = 0.01\ngravity = [0.0, 0.0]\n[[materials]]\nname = \"m\"\nstiffness = 1e9\n\
             [[bodies]]\nshape = \"box\"\nsize = [0.2, 0.2]\nposition = [0.0, 0.0]\nangle = {angle}\nmaterial = \"m\"\n\
             [[bodies]]\nshape = \"ball\"\nradius = 0.05\nposition = [0.16, 0.0]\nmaterial = \"m\"\n"
        )
    };
    let ok = impact_file(&d, "ok2.toml", &two("0.0"));
    assert_eq!(topple(&["scene", &ok]).0, 0);
    scene_refused(
        &d,
        &two("0.7853981633974483"),
        "bodies[0] and bodies[1]",
        "overlapping",
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn toml_errors_name_the_line_and_column_on_one_line() {
    // the caret used to land under the wrong column once joined into one line
    let d = temp_dir("toml");
    let text = "duration = 1.0\n[[bodies]]\nshape = \"ball\"\nradius = 0.05\nposition = [0.0, \"a\"]\nmaterial = \"x\"\n";
    let f = impact_file(&d, "s.toml", text);
    // "a" starts at line 5, column 18
    refused(&["scene", &f], "s.toml:5:18:", "invalid type");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn every_shipped_scene_passes_the_checks() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes");
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let scene: topple::rapier::scene::Scene =
            topple::validate::parse_toml(&text, &path.display().to_string()).unwrap();
        topple::rapier::scene::check_scene(&scene)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}
