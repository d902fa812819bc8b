//! Malformed and extreme input at scale: generated impact JSON (through the
//! `topple impact` binary) and scene TOML (through the library's loader,
//! checks and a short run) — wrong types, missing keys, NaN and infinities,
//! huge and tiny magnitudes, degenerate geometry, broken syntax. Each case
//! must give a result or a clean one-line error (exit 1 or 2), never a
//! panic, a signal or a hang.
//!
//! CI runs a few hundred cases per property; `TOPPLE_FUZZ_CASES` sets the
//! number, e.g. the documented run of tens of thousands:
//!
//! ```text
//! TOPPLE_FUZZ_CASES=20000 cargo test --release --test cli -- malformed_input::
//! ```

use std::io::Write;
use std::process::{Command, Stdio};

use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

use proptest::prelude::*;

/// Outcomes seen: impact exit 0, 1, 2; scene parse error, refused, run.
static SEEN: [AtomicUsize; 6] = [const { AtomicUsize::new(0) }; 6];
use proptest::test_runner::{Config, RngSeed, TestRunner};

fn cases(default: u32) -> u32 {
    std::env::var("TOPPLE_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn runner(default: u32, seed: u64) -> TestRunner {
    TestRunner::new(Config {
        cases: cases(default),
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        ..Config::default()
    })
}

const EXTREMES: [&str; 15] = [
    "0",
    "-0",
    "1e308",
    "-1e308",
    "1e-308",
    "5e-324",
    "1e200",
    "1e-300",
    "1e400",
    "-1e400",
    "123456789012345678901234567890",
    "0.1e-400",
    "-1",
    "-2.5",
    "1e7",
];
const WRONG: [&str; 15] = [
    "NaN",
    "Infinity",
    "-Infinity",
    "\"1.0\"",
    "true",
    "null",
    "[]",
    "{}",
    "[1.0]",
    "\"\"",
    "1.0.0",
    "--1",
    "+1",
    ".5",
    "0x10",
];

/// A sound value most of the time, else an extreme number or a value of
/// the wrong kind.
fn odd(good: impl Strategy<Value = String>) -> impl Strategy<Value = String> {
    prop_oneof![
        24 => good,
        1 => prop::sample::select(EXTREMES.to_vec()).prop_map(String::from),
        1 => prop::sample::select(WRONG.to_vec()).prop_map(String::from),
    ]
}

fn num(lo: f64, hi: f64) -> impl Strategy<Value = String> {
    odd((lo..hi).prop_map(|x| format!("{x}")))
}

/// A JSON pair `[a, b]` or something that is not one.
fn json_pair(lo: f64, hi: f64) -> impl Strategy<Value = String> {
    prop_oneof![
        24 => (num(lo, hi), num(lo, hi)).prop_map(|(a, b)| format!("[{a}, {b}]")),
        1 => prop::sample::select(vec!["[1.0]", "[1.0, 2.0, 3.0]", "null", "[]", "1.0", "\"x\""])
            .prop_map(String::from),
    ]
}

/// A unit normal most of the time (else zero, long or odd).
fn json_normal() -> impl Strategy<Value = String> {
    prop_oneof![
        12 => (0.0..std::f64::consts::TAU).prop_map(|a| format!("[{}, {}]", a.cos(), a.sin())),
        1 => json_pair(-1.0, 1.0),
        1 => Just("[0.0, 0.0]".to_string()),
    ]
}

/// A key-value entry, sometimes missing.
fn entry(key: &'static str, value: impl Strategy<Value = String>) -> impl Strategy<Value = String> {
    prop_oneof![
        40 => value.prop_map(move |v| format!("\"{key}\": {v}")),
        1 => Just(String::new()),
    ]
}

fn object(entries: Vec<String>) -> String {
    let kept: Vec<String> = entries.into_iter().filter(|e| !e.is_empty()).collect();
    format!("{{{}}}", kept.join(", "))
}

fn body() -> impl Strategy<Value = String> {
    (
        entry("mass", num(0.01, 10.0)),
        entry("inertia", num(0.001, 1.0)),
        entry("position", json_pair(-1.0, 1.0)),
        entry("angle", num(-3.0, 3.0)),
        entry("velocity", json_pair(-5.0, 5.0)),
        entry("angular_velocity", num(-5.0, 5.0)),
        entry(
            "fixed",
            prop_oneof![8 => Just("false"), 1 => Just("true"), 1 => Just("0")]
                .prop_map(String::from),
        ),
    )
        .prop_map(|(a, b, c, d, e, f, g)| object(vec![a, b, c, d, e, f, g]))
}

fn index() -> impl Strategy<Value = String> {
    prop_oneof![
        16 => prop::sample::select(vec!["0", "1", "null"]),
        1 => prop::sample::select(vec!["5", "-1", "1.5", "\"0\""]),
    ]
    .prop_map(String::from)
}

fn contact() -> impl Strategy<Value = String> {
    (
        entry(
            "bodies",
            (index(), index()).prop_map(|(a, b)| format!("[{a}, {b}]")),
        ),
        entry("point", json_pair(-1.0, 1.0)),
        entry("normal", json_normal()),
        entry("stiffness", num(1e3, 1e10)),
        entry("exponent", num(1.0, 2.0)),
        entry("restitution", num(0.0, 1.0)),
        entry("friction", num(0.0, 1.0)),
        entry("stick_friction", num(0.0, 1.0)),
    )
        .prop_map(|(a, b, c, d, e, f, g, h)| object(vec![a, b, c, d, e, f, g, h]))
}

/// Impact JSON: mostly well-formed with odd values; sometimes cut short or
/// with an unknown key.
fn impact_json() -> impl Strategy<Value = String> {
    let doc = (
        prop::collection::vec(body(), 0..4),
        prop::collection::vec(contact(), 0..4),
        entry("impulse_step", num(1e-4, 1e-2)),
        entry(
            "tolerance",
            prop_oneof![3 => Just("null".to_string()), 1 => num(1e-8, 1e-3)],
        ),
    )
        .prop_map(|(b, c, s, t)| {
            object(vec![
                format!("\"bodies\": [{}]", b.join(", ")),
                format!("\"contacts\": [{}]", c.join(", ")),
                s,
                t,
            ])
        });
    (doc, 0..20u8, any::<prop::sample::Index>()).prop_map(|(text, how, at)| match how {
        0 => text[..at.index(text.len() + 1)].to_string(),
        1 => text.replacen('{', "{\"extra\": 1, ", 1),
        _ => text,
    })
}

/// Runs `topple impact -` on `text`: exit 0 with JSON, or exit 1/2 with one
/// line on stderr; never a panic or a signal.
fn impact_case(text: &str) -> Result<(), TestCaseError> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_topple"))
        .args(["impact", "-", "--max-steps", "200000"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // a closed pipe (the command refused early) is fine
    let _ = child.stdin.take().unwrap().write_all(text.as_bytes());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let code = out.status.code();
    prop_assert!(code.is_some(), "killed by a signal on {text}");
    prop_assert!(!stderr.contains("panicked"), "panic on {text}: {stderr}");
    SEEN[(code.unwrap() as usize).min(2)].fetch_add(1, Relaxed);
    match code.unwrap() {
        0 => {
            let v: serde_json::Value = serde_json::from_slice(&out.stdout)
                .map_err(|e| TestCaseError::fail(format!("bad output JSON {e} on {text}")))?;
            prop_assert!(v.get("bodies").is_some());
        }
        1 | 2 => {
            prop_assert_eq!(
                stderr.trim_end().lines().count(),
                1,
                "on {}: {}",
                text,
                stderr
            );
            prop_assert!(stderr.starts_with("error: "), "{}", stderr);
        }
        c => prop_assert!(false, "exit {c} on {text}: {stderr}"),
    }
    Ok(())
}

#[test]
fn generated_impact_json_gives_a_result_or_a_clean_error() {
    runner(300, 0x15_0001)
        .run(&impact_json(), |text| impact_case(&text))
        .unwrap();
    let n = |k: usize| SEEN[k].load(Relaxed);
    eprintln!(
        "impact JSON: {} resolved, {} failed (1), {} refused (2)",
        n(0),
        n(1),
        n(2)
    );
    assert!(
        n(0) > 0 && n(2) > 0,
        "the generator must reach both results and refusals"
    );
}

const TOML_EXTREMES: [&str; 12] = [
    "0.0", "-0.0", "1e308", "-1e308", "1e-308", "1e200", "1e-300", "nan", "inf", "-inf", "-1.0",
    "-nan",
];
const TOML_WRONG: [&str; 8] = ["\"1.0\"", "true", "[1.0]", "{}", "1.0.0", "=", "", "0x10"];

/// A TOML number in [lo, hi) most of the time, else an extreme or a value
/// of the wrong kind.
fn tnum(lo: f64, hi: f64) -> impl Strategy<Value = String> {
    prop_oneof![
        30 => (lo..hi).prop_map(|x| format!("{x:?}")),
        1 => prop::sample::select(TOML_EXTREMES.to_vec()).prop_map(String::from),
        1 => prop::sample::select(TOML_WRONG.to_vec()).prop_map(String::from),
    ]
}

fn toml_line(
    key: &'static str,
    value: impl Strategy<Value = String>,
) -> impl Strategy<Value = String> {
    prop_oneof![
        40 => value.prop_map(move |v| format!("{key} = {v}\n")),
        1 => Just(String::new()),
    ]
}

fn toml_pair(lo: f64, hi: f64) -> impl Strategy<Value = String> {
    prop_oneof![
        30 => (tnum(lo, hi), tnum(lo, hi)).prop_map(|(a, b)| format!("[{a}, {b}]")),
        1 => prop::sample::select(vec!["[1.0]", "[]", "1.0", "[1.0, 2.0, 3.0]"]).prop_map(String::from),
    ]
}

fn toml_body() -> impl Strategy<Value = String> {
    (
        prop_oneof![10 => Just("\"ball\""), 10 => Just("\"box\""), 1 => Just("\"triangle\""), 1 => Just("1")],
        toml_line("radius", tnum(0.01, 0.1)),
        toml_line("size", toml_pair(0.01, 0.1)),
        toml_line("position", toml_pair(-10.0, 10.0)),
        toml_line("angle", tnum(-3.0, 3.0)),
        toml_line("velocity", toml_pair(-2.0, 2.0)),
        toml_line("mass", tnum(0.1, 2.0)),
        prop_oneof![10 => Just("\"m\""), 1 => Just("\"missing\"")],
    )
        .prop_map(|(shape, r, size, pos, angle, vel, mass, mat)| {
            format!("[[bodies]]\nshape = {shape}\n{r}{size}{pos}{angle}{vel}{mass}material = {mat}\n")
        })
}

fn toml_row() -> impl Strategy<Value = String> {
    (
        prop_oneof![10 => Just("\"X\""), 10 => Just("\"T\""), 10 => Just("\"p\""), 1 => Just("\"Q\""), 1 => Just("3")],
        toml_line(
            "n",
            prop_oneof![
                20 => (2..6usize).prop_map(|n| n.to_string()),
                1 => prop::sample::select(vec!["0", "1", "-3", "1000000000000", "2.5"]).prop_map(String::from),
            ],
        ),
        toml_line("spacing", tnum(0.1, 0.6)),
        toml_line("push", tnum(0.3, 2.0)),
        toml_line("mass", tnum(0.001, 0.1)),
        toml_line("e1", tnum(0.0, 1.0)),
        toml_line("mu2", tnum(0.1, 1.0)),
        toml_line("height", tnum(0.02, 0.1)),
    )
        .prop_map(|(preset, n, s, p, m, e1, mu2, h)| {
            format!("[row]\npreset = {preset}\n{n}{s}{p}{m}{e1}{mu2}{h}")
        })
}

/// A scene: top level, solver, one material, bodies and maybe a row;
/// sometimes cut short or with a stray character.
fn scene_toml() -> impl Strategy<Value = String> {
    let doc = (
        toml_line("duration", tnum(0.01, 1.0)),
        toml_line("gravity", toml_pair(-10.0, 0.0)),
        toml_line("dt", tnum(1e-4, 1.0 / 60.0)),
        toml_line("stiffness", tnum(1e6, 1e10)),
        toml_line("restitution", tnum(0.0, 1.0)),
        toml_line("friction", tnum(0.0, 1.0)),
        prop::collection::vec(toml_body(), 0..4),
        prop::option::of(toml_row()),
    )
        .prop_map(|(dur, g, dt, k, e, mu, bodies, row)| {
            format!(
                "{dur}{g}[solver]\n{dt}[[materials]]\nname = \"m\"\n{k}{e}{mu}{}{}",
                bodies.concat(),
                row.unwrap_or_default()
            )
        });
    (doc, 0..20u8, any::<prop::sample::Index>(), any::<char>()).prop_map(|(text, how, at, ch)| {
        let cut = (0..=text.len())
            .filter(|i| text.is_char_boundary(*i))
            .nth(at.index(text.len() + 1))
            .unwrap_or(text.len());
        match how {
            0 => text[..cut].to_string(),
            1 => format!("{}{ch}{}", &text[..cut], &text[cut..]),
            _ => text,
        }
    })
}

/// Loads, checks and (when valid) runs a scene for at most 20 steps: a
/// result or an error, never a panic.
fn scene_case(text: &str) -> Result<(), TestCaseError> {
    use topple::rapier::scene::{run_scene, ImpactResponse, RunOptions, Scene};
    let scene: Scene = match topple::validate::parse_toml(text, "s.toml") {
        Ok(s) => s,
        Err(e) => {
            if SEEN[3].fetch_add(1, Relaxed) < 3 && std::env::var("TOPPLE_FUZZ_SHOW").is_ok() {
                eprintln!("{e}");
            }
            let line = e.to_string();
            prop_assert!(
                line.starts_with("s.toml:") && !line.contains('\n'),
                "{line}"
            );
            return Ok(());
        }
    };
    if let Err(e) = topple::rapier::scene::check_scene(&scene) {
        SEEN[4].fetch_add(1, Relaxed);
        prop_assert!(!e.to_string().contains('\n'), "{e}");
        return Ok(());
    }
    SEEN[5].fetch_add(1, Relaxed);
    let mut short = scene.clone();
    short.duration = short.duration.min(20.0 * short.solver.dt);
    for engine in [ImpactResponse::Topple, ImpactResponse::Native] {
        // an error is allowed (e.g. an unknown material); a panic is not
        if let Ok(out) = run_scene(
            &short,
            engine,
            topple::rapier::Precision::F64,
            RunOptions::default(),
        ) {
            for b in &out.bodies {
                prop_assert!(b.position.iter().all(|v| v.is_finite()), "{text}");
            }
        }
    }
    Ok(())
}

#[test]
fn generated_scene_toml_gives_a_result_or_a_clean_error() {
    runner(300, 0x15_0002)
        .run(&scene_toml(), |text| scene_case(&text))
        .unwrap();
    let n = |k: usize| SEEN[k].load(Relaxed);
    eprintln!(
        "scene TOML: {} syntax errors, {} refused, {} run",
        n(3),
        n(4),
        n(5)
    );
    assert!(
        n(3) > 0 && n(4) > 0 && n(5) > 0,
        "the generator must reach every outcome"
    );
}
