//! The LZB resolver per scene class: impulse steps per impact, time per
//! impact and error against the converged answer, for the paper's fixed
//! impulse step, the adaptive impulse stepping (the resolver's default
//! before the time-domain solver) and the time-domain solver (the default),
//! side by side in one run.
//!
//! Classes:
//! - `chain10`: ten equal balls in a row, the first striking at 1 m/s,
//!   Hertz contacts (α = 1.5, e = 1): error against the Hertz chain ODE
//!   integrated in tests/common/hertz.rs.
//! - `leaning20`: twenty blocks of a fallen domino train (Domino T size) with
//!   ground contacts, the last one pushed, e = 1 and no friction: error against
//!   the compliant model with frozen geometry (tests/common/compliant.rs).
//! - `domino20`: the same train with the domino's e = 0 and friction (a
//!   leaning e = 0 train).
//! - captured impacts (benches/data/, recorded with `topple::impact::capture`
//!   from runs of the Rapier adapter at 1/60 s): `x-row` (Domino X, Table 1,
//!   s/h 0.3: chatter of e = 0 contacts), `t-row` (ideal Domino T, s/h 0.45),
//!   `box-on-stack` (a box landing flat on a stack, assets/scenes/box-drop-flat),
//!   `pile` (24 impacts of assets/scenes/pile-boxes.toml, 1 to 47 contacts),
//!   `cradle-5` (assets/scenes/cradle-5.toml).
//!
//! Without an ODE, the converged answer is the time-domain solver at
//! tolerance 10⁻¹⁰ with every fast cycle followed (`fast_cycle = 0`); the
//! `check` column gives its distance from the adaptive impulse stepping at
//! 10⁻⁶, a second way to the same answer (its own error is of that order). Errors are the largest velocity
//! difference of any body (ω through its radius of gyration) over the
//! impact's largest body speed, the worst over the class.
//!
//! `cargo bench --bench impact` prints the table first (one run per setting),
//! then criterion times each setting on each class.

#[path = "../tests/common/compliant.rs"]
mod compliant;
#[path = "../tests/common/hertz.rs"]
#[allow(dead_code)]
mod hertz;
#[path = "../tests/common/leaning.rs"]
mod leaning;

use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use topple::impact::capture::CapturedImpact;
use topple::impact::{Body, BodyVelocity, Contact, ContactMaterial, ImpactSettings, ImpactSolver};

/// One impact and its converged answer ([vx, vy, ω] per body; empty when
/// neither converged run finished within its step limit).
struct Impact {
    bodies: Vec<Body>,
    contacts: Vec<Contact>,
    reference: Vec<[f64; 3]>,
}

/// A scene class: its impacts, and the distance between two converged
/// answers (NaN where the reference is an ODE).
struct Class {
    name: &'static str,
    impacts: Vec<Impact>,
    check: f64,
}

fn velocities(bodies: &[BodyVelocity]) -> Vec<[f64; 3]> {
    bodies
        .iter()
        .map(|b| [b.velocity[0], b.velocity[1], b.angular_velocity])
        .collect()
}

fn chain10() -> Class {
    let n = 10;
    let mut v = vec![0.0; n];
    v[0] = 1.0;
    let chain = hertz::Chain {
        masses: vec![1.0; n],
        velocities: v,
        stiffness: vec![1e5; n],
        exponent: 1.5,
        wall: false,
    };
    let expected = chain.integrate(chain.time_step(4000.0));
    let bodies = (0..n)
        .map(|i| {
            Body::new(1.0, 0.004)
                .with_position([0.2 * i as f64, 0.0])
                .with_velocity([chain.velocities[i], 0.0])
        })
        .collect();
    let contacts = (0..n - 1)
        .map(|j| {
            Contact::new(
                [Some(j), Some(j + 1)],
                [0.2 * j as f64 + 0.1, 0.0],
                [1.0, 0.0],
                ContactMaterial::hertz(1e5),
            )
        })
        .collect();
    Class {
        name: "chain10",
        impacts: vec![Impact {
            bodies,
            contacts,
            reference: expected.iter().map(|&vx| [vx, 0.0, 0.0]).collect(),
        }],
        check: f64::NAN,
    }
}

/// The leaning train's bodies and contacts (e = 1 without friction, or the
/// domino's e = 0 with friction).
fn leaning_group(elastic: bool) -> (Vec<Body>, Vec<Contact>) {
    let (between, ground) = if elastic {
        (ContactMaterial::hertz(2.3e8), ContactMaterial::hertz(6.9e8))
    } else {
        (
            ContactMaterial::hertz(2.3e8)
                .with_restitution(0.0)
                .with_friction(0.075, 0.1),
            ContactMaterial::hertz(6.9e8)
                .with_restitution(0.0)
                .with_friction(0.45, 0.9),
        )
    };
    let group = leaning::Leaning {
        count: 20,
        height: 0.08,
        thickness: 0.0096,
        spacing: 0.028,
        push: 5.0,
        between,
        ground,
    };
    group.build()
}

fn leaning(elastic: bool) -> Class {
    let (bodies, contacts) = leaning_group(elastic);
    if elastic {
        let reference = compliant::integrate(&bodies, &contacts, 400.0);
        Class {
            name: "leaning20",
            impacts: vec![Impact {
                bodies,
                contacts,
                reference,
            }],
            check: f64::NAN,
        }
    } else {
        converged("domino20", vec![(bodies, contacts)])
    }
}

/// A class whose reference is the converged solver (see the module notes).
fn converged(name: &'static str, list: Vec<(Vec<Body>, Contacts)>) -> Class {
    let tight = ImpactSettings {
        fast_cycle: 0.0,
        max_steps: 1_000_000,
        ..ImpactSettings::adaptive(1e-10)
    };
    let second = ImpactSettings {
        max_steps: 1_000_000,
        ..ImpactSettings::adaptive_impulse(1e-6)
    };
    eprintln!("converging {name} ...");
    let mut solver = ImpactSolver::new();
    let mut check = 0.0f64;
    let impacts = list
        .into_iter()
        .map(|(bodies, contacts)| {
            let first = solver.solve(&bodies, &contacts, &tight).ok();
            let other = solver.solve(&bodies, &contacts, &second).ok();
            let reference = match (&first, &other) {
                (Some(out), _) | (None, Some(out)) => velocities(&out.bodies),
                (None, None) => Vec::new(),
            };
            let impact = Impact {
                bodies,
                contacts,
                reference,
            };
            if let (Some(_), Some(other)) = (&first, &other) {
                check = check.max(error(&impact, &velocities(&other.bodies)));
            }
            impact
        })
        .collect();
    Class {
        name,
        impacts,
        check,
    }
}

type Contacts = Vec<Contact>;

/// A class of captured impacts from benches/data/`file`.
fn captured(name: &'static str, file: &str) -> Class {
    let path = format!("{}/benches/data/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let list = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let c: CapturedImpact = serde_json::from_str(l).unwrap();
            (c.bodies, c.contacts)
        })
        .collect();
    converged(name, list)
}

/// Largest velocity error of any body (ω through its radius of gyration)
/// over the impact's largest body speed.
fn error(impact: &Impact, got: &[[f64; 3]]) -> f64 {
    let speed = impact
        .bodies
        .iter()
        .filter(|b| !b.fixed)
        .map(|b| b.velocity[0].hypot(b.velocity[1]))
        .fold(0.0, f64::max)
        .max(1e-300);
    let worst = impact
        .bodies
        .iter()
        .zip(got.iter().zip(&impact.reference))
        .filter(|(b, _)| !b.fixed)
        .map(|(b, (g, r))| {
            let rho = (b.inertia / b.mass).sqrt();
            (g[0] - r[0])
                .abs()
                .max((g[1] - r[1]).abs())
                .max((g[2] - r[2]).abs() * rho)
        })
        .fold(0.0, f64::max);
    worst / speed
}

/// The step controls compared, each with a step limit of 10⁶.
fn settings() -> Vec<(&'static str, ImpactSettings)> {
    let limited = |s: ImpactSettings| ImpactSettings {
        max_steps: 1_000_000,
        ..s
    };
    // the plugins' impact settings, which the label below names
    let plugin_default = topple::coupling::ToppleSettings::default().impact;
    assert_eq!(plugin_default, ImpactSettings::adaptive(1e-6));
    // the plugins' rest speed at 1/60 s under 9.81 m/s²: a fraction of the
    // impact threshold 2|g|Δt (docs/model.md §9)
    let rest = |fraction: f64, s: ImpactSettings| {
        limited(ImpactSettings {
            rest_speed: fraction * THRESHOLD_1_60,
            ..s
        })
    };
    let plugin = topple::coupling::ToppleSettings::DEFAULT_REST_FRACTION;
    assert_eq!(
        plugin, 0.01,
        "the labels below name the plugins' rest fraction"
    );
    vec![
        (
            "paper: fixed ΔP = 10⁻⁴ P₀",
            limited(ImpactSettings::fixed(1e-4)),
        ),
        (
            "adaptive impulse 10⁻⁴",
            limited(ImpactSettings::adaptive_impulse(1e-4)),
        ),
        ("in time 10⁻⁴", limited(ImpactSettings::adaptive(1e-4))),
        (
            "in time 2·10⁻⁶ (default)",
            limited(ImpactSettings::default()),
        ),
        (
            "adaptive impulse 10⁻⁴, rest speed 3.3·10⁻³ m/s (plugin default before)",
            rest(plugin, ImpactSettings::adaptive_impulse(1e-4)),
        ),
        (
            "in time 2·10⁻⁶, rest speed 3.3·10⁻³ m/s",
            rest(plugin, ImpactSettings::default()),
        ),
        // the plugins' tolerance before, measured against the present one
        // (docs/impact.md, "Steps per impact, round ten")
        (
            "in time 2·10⁻⁷, rest speed 3.3·10⁻³ m/s (plugin default before)",
            rest(plugin, ImpactSettings::adaptive(2e-7)),
        ),
        (
            "in time 10⁻⁶, rest speed 3.3·10⁻³ m/s (plugin default)",
            rest(plugin, plugin_default),
        ),
        // larger rest fractions (docs/impact.md, "Steps per impact, round ten")
        (
            "in time 10⁻⁶, rest speed 9.8·10⁻³ m/s (0.03 of the threshold)",
            rest(0.03, plugin_default),
        ),
        (
            "in time 10⁻⁶, rest speed 3.3·10⁻² m/s (0.1 of the threshold)",
            rest(0.1, plugin_default),
        ),
    ]
}

/// The impact threshold of the plugins at 1/60 s under 9.81 m/s² (m/s):
/// 2|g|Δt, the approach a resting contact picks up in one step.
const THRESHOLD_1_60: f64 = 2.0 * 9.81 / 60.0;

/// What one step control does on a class.
struct Measured {
    median: usize,
    mean: f64,
    worst: f64,
    /// Impacts that ended in an error (the step limit).
    failed: usize,
}

/// Solves every impact of a class.
fn measure(class: &Class, solver: &mut ImpactSolver, s: &ImpactSettings) -> Measured {
    let mut steps = Vec::new();
    let (mut worst, mut failed) = (0.0f64, 0);
    for impact in &class.impacts {
        match solver.solve(&impact.bodies, &impact.contacts, s) {
            Ok(out) => {
                steps.push(out.steps);
                if !impact.reference.is_empty() {
                    worst = worst.max(error(impact, &velocities(&out.bodies)));
                }
            }
            Err(_) => failed += 1,
        }
    }
    let mean = steps.iter().sum::<usize>() as f64 / steps.len().max(1) as f64;
    steps.sort_unstable();
    Measured {
        median: steps.get(steps.len() / 2).copied().unwrap_or(0),
        mean,
        worst,
        failed,
    }
}

/// A profiling run (`IMPACT_PROFILE=class`): the class's impacts
/// at the plugins' default (or at `IMPACT_TOLERANCE` and
/// `IMPACT_REST_FRACTION` of the impact threshold at 1/60 s, when set),
/// `IMPACT_REPEAT` times (1 unless set), without
/// the converged runs, the table or criterion, so that `valgrind
/// --tool=callgrind` on the bench binary counts the resolver alone (the
/// leaning trains, `leaning20` and `domino20`, are built rather than
/// read). Prints the class's accepted and rejected steps, its settling
/// evaluations and a hash of the outcomes' bits.
fn profile(name: &str) {
    let file = match name {
        "leaning20" | "domino20" => "",
        "x-row" => "x-row-1-60.jsonl",
        "t-row" => "t-row-1-60.jsonl",
        "box-on-stack" => "box-on-stack.jsonl",
        "pile" => "pile.jsonl",
        "cradle-5" => "cradle-5.jsonl",
        _ => panic!("IMPACT_PROFILE: no class {name}"),
    };
    let impacts: Vec<(Vec<Body>, Vec<Contact>)> = if file.is_empty() {
        vec![leaning_group(name == "leaning20")]
    } else {
        let path = format!("{}/benches/data/{file}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        text.lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| {
                let c: CapturedImpact = serde_json::from_str(l).unwrap();
                (c.bodies, c.contacts)
            })
            .collect()
    };
    let repeat: usize = std::env::var("IMPACT_REPEAT")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(1);
    let var = |name: &str| std::env::var(name).ok().and_then(|v| v.parse::<f64>().ok());
    let fraction = var("IMPACT_REST_FRACTION")
        .unwrap_or(topple::coupling::ToppleSettings::DEFAULT_REST_FRACTION);
    let base = var("IMPACT_TOLERANCE").map_or(
        topple::coupling::ToppleSettings::default().impact,
        ImpactSettings::adaptive,
    );
    let s = ImpactSettings {
        rest_speed: fraction * THRESHOLD_1_60,
        max_steps: 1_000_000,
        ..base
    };
    let mut solver = ImpactSolver::new();
    let (mut steps, mut rejected, mut settling) = (0, 0, 0);
    let mut bits = Fnv::default();
    for _ in 0..repeat {
        for (bodies, contacts) in &impacts {
            match solver.solve(bodies, contacts, &s) {
                Ok(out) => {
                    steps += out.steps;
                    rejected += out.rejected_steps;
                    settling += out.settling_evaluations;
                    bits.outcome(&out);
                }
                Err(e) => bits.word(format!("{e:?}").len() as u64),
            }
        }
    }
    println!(
        "{name}: {} impacts x {repeat}, {steps} steps, {rejected} rejected, \
         {settling} settling evaluations, outcome bits {:016x}",
        impacts.len(),
        bits.0
    );
}

/// FNV-1a over the outcomes' bits (velocities, impulses, steps), so that
/// a change meant to keep every result to the bit can be checked with
/// `IMPACT_PROFILE` on the builds before and after.
struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    fn word(&mut self, w: u64) {
        for byte in w.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    }

    fn outcome(&mut self, out: &topple::impact::ImpactOutcome) {
        for b in &out.bodies {
            for v in [b.velocity[0], b.velocity[1], b.angular_velocity] {
                self.word(v.to_bits());
            }
        }
        for c in &out.contacts {
            self.word(c.normal_impulse.to_bits());
            self.word(c.tangent_impulse.to_bits());
        }
        self.word(out.steps as u64);
        self.word(out.rejected_steps as u64);
        self.word(out.settling_evaluations as u64);
    }
}

fn bench(c: &mut Criterion) {
    if let Ok(name) = std::env::var("IMPACT_PROFILE") {
        profile(&name);
        return;
    }
    let classes = [
        chain10(),
        leaning(true),
        leaning(false),
        captured("x-row", "x-row-1-60.jsonl"),
        captured("t-row", "t-row-1-60.jsonl"),
        captured("box-on-stack", "box-on-stack.jsonl"),
        captured("pile", "pile.jsonl"),
        captured("cradle-5", "cradle-5.jsonl"),
    ];
    let mut solver = ImpactSolver::new();
    println!(
        "\n| class | impacts | step control | steps (median) | steps (mean) | time per impact | error / speed | failed | check |"
    );
    println!("| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    for class in &classes {
        for (label, s) in settings() {
            let start = Instant::now();
            let m = measure(class, &mut solver, &s);
            let time = start.elapsed() / class.impacts.len() as u32;
            println!(
                "| {} | {} | {label} | {} | {:.0} | {time:.1?} | {:.1e} | {} | {:.0e} |",
                class.name,
                class.impacts.len(),
                m.median,
                m.mean,
                m.worst,
                m.failed,
                class.check
            );
        }
    }
    for class in &classes {
        let mut group = c.benchmark_group(class.name);
        group.sample_size(10);
        for (label, s) in settings() {
            group.bench_function(label, |b| {
                b.iter(|| {
                    for impact in &class.impacts {
                        let _ = solver.solve(&impact.bodies, &impact.contacts, &s);
                    }
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
