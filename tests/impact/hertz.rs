//! e = 1, no friction: the LZB resolver against the compliant model F = k δ^α
//! integrated in time (docs/model.md).

use crate::common::hertz::Chain;
use topple::impact::{Body, Contact, ContactMaterial, ImpactSettings, ImpactSolver};

/// The same chain as resolver input: balls of radius 0.1 m on the x axis.
fn resolver_input(chain: &Chain) -> (Vec<Body>, Vec<Contact>) {
    let n = chain.masses.len();
    let bodies = (0..n)
        .map(|i| {
            Body::new(chain.masses[i], 0.4 * chain.masses[i] * 0.01)
                .with_position([0.2 * i as f64, 0.0])
                .with_velocity([chain.velocities[i], 0.0])
        })
        .collect();
    let contacts = (0..chain.contacts())
        .map(|j| {
            let second = if j + 1 < n { Some(j + 1) } else { None };
            let mat = ContactMaterial::hertz(chain.stiffness[j]).with_exponent(chain.exponent);
            Contact::new(
                [Some(j), second],
                [0.2 * j as f64 + 0.1, 0.0],
                [1.0, 0.0],
                mat,
            )
        })
        .collect();
    (bodies, contacts)
}

fn chains() -> Vec<(&'static str, Chain)> {
    let mut out = Vec::new();
    for &alpha in &[1.0, 1.5] {
        for &n in &[3usize, 5, 10] {
            let mut v = vec![0.0; n];
            v[0] = 1.0;
            out.push((
                "equal",
                Chain {
                    masses: vec![1.0; n],
                    velocities: v.clone(),
                    stiffness: vec![1e5; n],
                    exponent: alpha,
                    wall: false,
                },
            ));
            // unequal masses and stiffnesses
            let masses: Vec<f64> = (0..n).map(|i| 1.0 + 0.37 * ((i * 7 % 5) as f64)).collect();
            let stiffness: Vec<f64> = (0..n)
                .map(|i| 1e5 * (1.0 + 0.8 * ((i * 3 % 4) as f64)))
                .collect();
            out.push((
                "unequal",
                Chain {
                    masses: masses.clone(),
                    velocities: v.clone(),
                    stiffness: stiffness.clone(),
                    exponent: alpha,
                    wall: false,
                },
            ));
            // the last ball pressed against a wall
            out.push((
                "wall",
                Chain {
                    masses,
                    velocities: v,
                    stiffness,
                    exponent: alpha,
                    wall: true,
                },
            ));
        }
    }
    out
}

fn worst_error(settings: &ImpactSettings) -> f64 {
    let mut solver = ImpactSolver::new();
    let mut worst: f64 = 0.0;
    for (name, chain) in chains() {
        let expected = chain.integrate(chain.time_step(4000.0));
        let (bodies, contacts) = resolver_input(&chain);
        let out = solver.solve(&bodies, &contacts, settings).unwrap();
        let err = out
            .bodies
            .iter()
            .zip(&expected)
            .map(|(b, e)| (b.velocity[0] - e).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{name:8} n={:2} α={} steps={:7} error={err:.2e} lzb={:?} ode={:?}",
            chain.masses.len(),
            chain.exponent,
            out.steps,
            out.bodies
                .iter()
                .map(|b| (b.velocity[0] * 1e4).round() / 1e4)
                .collect::<Vec<_>>(),
            expected
                .iter()
                .map(|e| (e * 1e4).round() / 1e4)
                .collect::<Vec<_>>()
        );
        worst = worst.max(err);
    }
    worst
}

/// The default (the time-domain solver) within 10⁻⁴ of the striking speed.
#[test]
fn default_matches_hertz_chain_to_1e_4() {
    let err = worst_error(&ImpactSettings::default());
    assert!(
        err < 1e-4,
        "worst velocity error {err:.3e} (striking speed 1 m/s)"
    );
}

#[test]
fn small_step_matches_hertz_chain_to_1e_4() {
    let err = worst_error(&ImpactSettings::fixed(1e-5));
    assert!(err < 1e-4, "worst velocity error {err:.3e}");
}

/// The adaptive step's tolerance bounds the local error of each step
/// (relative to the striking speed); over the thousands of steps of these
/// chains, 10⁻⁸ brings the result within 10⁻⁴.
#[test]
fn adaptive_matches_hertz_chain_to_1e_4() {
    let err = worst_error(&ImpactSettings::adaptive(1e-8));
    assert!(err < 1e-4, "worst velocity error {err:.3e}");
}

#[test]
fn adaptive_error_falls_with_the_tolerance() {
    let errors: Vec<f64> = [1e-4, 1e-6, 1e-8]
        .iter()
        .map(|&t| worst_error(&ImpactSettings::adaptive(t)))
        .collect();
    assert!(
        errors[0] > 3.0 * errors[1] && errors[1] > 3.0 * errors[2],
        "worst errors at tolerances 1e-4, 1e-6, 1e-8: {errors:?}"
    );
}
