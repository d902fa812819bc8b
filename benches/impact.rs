//! Work-precision of the LZB resolver: run time, steps and error
//! against an independent compliant-model ODE, for the paper's fixed impulse
//! step and for adaptive stepping.
//!
//! Cases:
//! - `chain10`: ten equal balls in a row, the first striking at 1 m/s,
//!   Hertz contacts (α = 1.5, e = 1): error against the Hertz chain ODE.
//! - `leaning20`: twenty blocks of a fallen domino train (Domino T size) with
//!   ground contacts, the last one pushed, e = 1 and no friction: error against
//!   the compliant model with frozen geometry.
//! - `domino20`: the same train with the domino's e = 0 and friction (no ODE
//!   exists for it): error against the resolver at ΔP = 10⁻⁶ P₀.
//!
//! `cargo bench --bench impact` prints the table first (one run per setting),
//! then criterion times each setting.

#[path = "../tests/common/compliant.rs"]
mod compliant;
#[path = "../tests/common/hertz.rs"]
#[allow(dead_code)]
mod hertz;
#[path = "../tests/common/leaning.rs"]
mod leaning;

use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use topple::impact::{Body, Contact, ContactMaterial, ImpactSettings, ImpactSolver};

struct Case {
    name: &'static str,
    bodies: Vec<Body>,
    contacts: Vec<Contact>,
    /// Reference velocities [vx, vy, ω] and the speed scale errors are divided by.
    reference: Vec<[f64; 3]>,
    speed: f64,
    /// Lever that turns ω errors into velocity errors (m).
    lever: f64,
}

fn chain10() -> Case {
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
    Case {
        name: "chain10",
        bodies,
        contacts,
        reference: expected.iter().map(|&vx| [vx, 0.0, 0.0]).collect(),
        speed: 1.0,
        lever: 0.0,
    }
}

fn leaning(elastic: bool) -> Case {
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
    let (bodies, contacts) = group.build();
    let reference = if elastic {
        compliant::integrate(&bodies, &contacts, 400.0)
    } else {
        let out = ImpactSolver::new()
            .solve(&bodies, &contacts, &ImpactSettings::fixed(1e-6))
            .unwrap();
        out.bodies
            .iter()
            .map(|b| [b.velocity[0], b.velocity[1], b.angular_velocity])
            .collect()
    };
    Case {
        name: if elastic { "leaning20" } else { "domino20" },
        bodies,
        contacts,
        reference,
        speed: 5.0 * 0.08,
        lever: 0.04,
    }
}

fn settings() -> Vec<(String, ImpactSettings)> {
    let mut list = Vec::new();
    for step in [1e-3, 1e-4, 1e-5] {
        list.push((format!("fixed ΔP={step:e}·P₀"), ImpactSettings::fixed(step)));
    }
    for tol in [1e-4, 1e-6, 1e-8] {
        list.push((
            format!("adaptive tol={tol:e}"),
            ImpactSettings::adaptive(tol),
        ));
    }
    list
}

fn error(case: &Case, solver: &mut ImpactSolver, s: &ImpactSettings) -> (f64, usize) {
    let out = solver.solve(&case.bodies, &case.contacts, s).unwrap();
    let worst = out
        .bodies
        .iter()
        .zip(&case.reference)
        .map(|(b, r)| {
            (b.velocity[0] - r[0])
                .abs()
                .max((b.velocity[1] - r[1]).abs())
                .max((b.angular_velocity - r[2]).abs() * case.lever)
        })
        .fold(0.0, f64::max);
    (worst / case.speed, out.steps)
}

fn bench(c: &mut Criterion) {
    let cases = [chain10(), leaning(true), leaning(false)];
    let mut solver = ImpactSolver::new();
    println!("\n| case | step control | steps | error / speed | time (one run) |");
    println!("| --- | --- | ---: | ---: | ---: |");
    for case in &cases {
        for (label, s) in settings() {
            let start = Instant::now();
            let (err, steps) = error(case, &mut solver, &s);
            let time = start.elapsed();
            println!(
                "| {} | {label} | {steps} | {err:.1e} | {time:.1?} |",
                case.name
            );
        }
    }
    for case in &cases {
        let mut group = c.benchmark_group(case.name);
        group.sample_size(10);
        for (label, s) in settings() {
            group.bench_function(label, |b| {
                b.iter(|| solver.solve(&case.bodies, &case.contacts, &s).unwrap())
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
