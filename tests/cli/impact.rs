//! `topple impact`: JSON in, JSON out; bad input exits non-zero with one line
//! on stderr and nothing on stdout.

use std::io::Write;
use std::process::{Command, Stdio};

fn run(input: &str) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_topple"))
        .args(["impact", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

const GOOD: &str = r#"{"bodies": [{"mass": 2.0, "inertia": 0.1, "position": [0.0, 0.0], "angle": 0.0,
  "velocity": [1.5, 0.0], "angular_velocity": 0.0, "fixed": false}],
 "contacts": [{"bodies": [0, null], "point": [0.5, 0.0], "normal": [1.0, 0.0],
   "stiffness": 1e9, "exponent": 1.5, "restitution": 0.6,
   "friction": 0.0, "stick_friction": 0.0}],
 "impulse_step": 1e-4, "tolerance": null}"#;

#[test]
fn good_input_gives_json_with_the_documented_keys() {
    let (code, stdout, stderr) = run(GOOD);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    // ball of 2 kg on a wall at 1.5 m/s, e = 0.6: rebounds at −0.9 m/s
    let vx = v["bodies"][0]["velocity"][0].as_f64().unwrap();
    assert!((vx + 0.9).abs() < 1e-6, "{vx}");
    let pn = v["contacts"][0]["normal_impulse"].as_f64().unwrap();
    assert!((pn - 2.0 * 2.4).abs() < 1e-5);
    assert!((v["kinetic_energy_before"].as_f64().unwrap() - 2.25).abs() < 1e-12);
    assert!((v["kinetic_energy_after"].as_f64().unwrap() - 0.81).abs() < 1e-5);
    assert!(v["contacts"][0]["peak_energy"].as_f64().unwrap() > 0.0);
    assert!(v["contacts"][0]["tangent_impulse"].is_number());
    assert!(v["steps"].as_u64().unwrap() > 0);
}

#[test]
fn tolerance_selects_adaptive_mode() {
    let (code, stdout, _) = run(&GOOD.replace(r#""tolerance": null"#, r#""tolerance": 1e-6"#));
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let vx = v["bodies"][0]["velocity"][0].as_f64().unwrap();
    assert!((vx + 0.9).abs() < 1e-5);
    // far fewer steps than the fixed ΔP = 1e-4 P₀ (which needs about 1.6e4)
    assert!(v["steps"].as_u64().unwrap() < 2000);
}

#[test]
fn bad_input_is_one_line_on_stderr_and_nothing_on_stdout() {
    let cases = [
        ("not json", "not json at all".to_string()),
        ("missing key", GOOD.replace(r#""impulse_step": 1e-4, "#, "")),
        (
            "mass <= 0",
            GOOD.replace(r#""mass": 2.0"#, r#""mass": 0.0"#),
        ),
        (
            "e > 1",
            GOOD.replace(r#""restitution": 0.6"#, r#""restitution": 1.2"#),
        ),
        (
            "e < 0",
            GOOD.replace(r#""restitution": 0.6"#, r#""restitution": -0.1"#),
        ),
        (
            "mu < 0",
            GOOD.replace(r#""friction": 0.0"#, r#""friction": -0.5"#),
        ),
        (
            "zero normal",
            GOOD.replace(r#""normal": [1.0, 0.0]"#, r#""normal": [0.0, 0.0]"#),
        ),
        (
            "unknown body",
            GOOD.replace(r#""bodies": [0, null]"#, r#""bodies": [0, 4]"#),
        ),
        ("NaN", GOOD.replace(r#""angle": 0.0"#, r#""angle": NaN"#)),
        (
            "overflow",
            GOOD.replace(r#""stiffness": 1e9"#, r#""stiffness": 1e999"#),
        ),
        (
            "unknown key",
            GOOD.replace(r#""fixed": false"#, r#""fixed": false, "colour": 1"#),
        ),
    ];
    for (name, input) in cases {
        let (code, stdout, stderr) = run(&input);
        assert_ne!(code, 0, "{name}: exit code");
        assert!(stdout.is_empty(), "{name}: stdout {stdout:?}");
        assert_eq!(
            stderr.trim_end().lines().count(),
            1,
            "{name}: stderr {stderr:?}"
        );
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
    }
}

#[test]
fn missing_file_is_an_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_topple"))
        .args(["impact", "/nonexistent/impact.json"])
        .output()
        .unwrap();
    assert_ne!(out.status.code(), Some(0));
    assert!(out.stdout.is_empty());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/impact.json"));
}
