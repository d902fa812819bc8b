//! A group of 20 leaning blocks with ground contacts: with e = 1 and
//! no friction, the resolver against the compliant model integrated in time
//! with frozen geometry (tests/common/compliant.rs); with the domino's e = 0
//! and friction, the conservation checks and agreement of the two step
//! controls.

use crate::common::{compliant, leaning::Leaning};
use topple::impact::{ContactMaterial, ImpactSettings, ImpactSolver};

fn elastic_group() -> Leaning {
    Leaning {
        count: 20,
        height: 0.08,
        thickness: 0.0096,
        spacing: 0.028,
        push: 5.0,
        between: ContactMaterial::hertz(2.3e8),
        ground: ContactMaterial::hertz(6.9e8),
    }
}

#[test]
fn elastic_leaning_group_matches_the_compliant_model() {
    let (bodies, contacts) = elastic_group().build();
    let expected = compliant::integrate(&bodies, &contacts, 400.0);
    let speed = 5.0 * 0.08; // tip speed of the pushed block (m/s)
                            // Energy: the fixed step books it exactly (to rounding); the adaptive
                            // step's energy error is its tolerance times its number of steps.
    for (settings, energy_tolerance) in [
        (ImpactSettings::default(), 1e-6),
        (ImpactSettings::adaptive(1e-8), 1e-4),
    ] {
        let out = ImpactSolver::new()
            .solve(&bodies, &contacts, &settings)
            .unwrap();
        let mut worst: f64 = 0.0;
        for (b, e) in out.bodies.iter().zip(&expected) {
            worst = worst
                .max((b.velocity[0] - e[0]).abs())
                .max((b.velocity[1] - e[1]).abs())
                .max((b.angular_velocity - e[2]).abs() * 0.04);
        }
        assert!(
            worst < 1e-3 * speed,
            "{settings:?}: worst velocity error {worst:.2e} m/s ({} steps)",
            out.steps
        );
        let ke = (out.kinetic_energy_after - out.kinetic_energy_before).abs();
        assert!(
            ke < energy_tolerance * out.kinetic_energy_before,
            "e = 1 keeps the energy: {ke:e}"
        );
    }
}

#[test]
fn domino_group_dissipates_and_both_step_controls_agree() {
    let group = Leaning {
        between: ContactMaterial::hertz(2.3e8)
            .with_restitution(0.0)
            .with_friction(0.075, 0.1),
        ground: ContactMaterial::hertz(6.9e8)
            .with_restitution(0.0)
            .with_friction(0.45, 0.9),
        ..elastic_group()
    };
    let (bodies, contacts) = group.build();
    let fixed = ImpactSolver::new()
        .solve(&bodies, &contacts, &ImpactSettings::default())
        .unwrap();
    let fine = ImpactSolver::new()
        .solve(&bodies, &contacts, &ImpactSettings::fixed(1e-5))
        .unwrap();
    // Event-heavy (e = 0 and stick/slip): the adaptive mode needs a tight
    // tolerance here (`cargo bench --bench impact` prints the work-precision table).
    let adaptive = ImpactSolver::new()
        .solve(&bodies, &contacts, &ImpactSettings::adaptive(1e-8))
        .unwrap();
    assert!(fixed.kinetic_energy_after < fixed.kinetic_energy_before);
    for out in [&fixed, &adaptive] {
        for (a, b) in out.bodies.iter().zip(&fine.bodies) {
            assert!((a.velocity[0] - b.velocity[0]).abs() < 1e-3 * 0.4);
            assert!((a.velocity[1] - b.velocity[1]).abs() < 1e-3 * 0.4);
        }
    }
    for c in &fixed.contacts {
        assert!(c.normal_impulse >= 0.0);
    }
}

/// Bodies and contacts of an impact dumped as `topple impact` input.
fn load(text: &str) -> (Vec<topple::impact::Body>, Vec<topple::impact::Contact>) {
    let input: serde_json::Value = serde_json::from_str(text).unwrap();
    let bodies = input["bodies"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| serde_json::from_value(b.clone()).unwrap())
        .collect();
    let contacts = input["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            let m = ContactMaterial {
                stiffness: c["stiffness"].as_f64().unwrap(),
                exponent: c["exponent"].as_f64().unwrap(),
                restitution: c["restitution"].as_f64().unwrap(),
                friction: c["friction"].as_f64().unwrap(),
                stick_friction: c["stick_friction"].as_f64().unwrap(),
            };
            let side = |k: usize| c["bodies"][k].as_u64().map(|i| i as usize);
            let v = |key: &str, k: usize| c[key][k].as_f64().unwrap();
            topple::impact::Contact::new(
                [side(0), side(1)],
                [v("point", 0), v("point", 1)],
                [v("normal", 0), v("normal", 1)],
                m,
            )
        })
        .collect();
    (bodies, contacts)
}

/// A standing Domino X block on nine λ points (e2 = 0.5, friction) struck at
/// its top by the falling block (e1 = 0.85), dumped from a Rapier scene: the
/// impact must end well within the step limit, without creating energy, and
/// the struck block must come away rotating forward (clockwise).
#[test]
fn domino_first_hit_ends_and_dissipates() {
    let (bodies, contacts) = load(include_str!("../data/domino-x-first-hit.json"));
    for settings in [
        ImpactSettings {
            max_steps: 200_000,
            ..ImpactSettings::default()
        },
        ImpactSettings {
            max_steps: 200_000,
            ..ImpactSettings::adaptive(1e-8)
        },
    ] {
        let out = ImpactSolver::new()
            .solve(&bodies, &contacts, &settings)
            .unwrap();
        assert!(out.kinetic_energy_after < out.kinetic_energy_before);
        assert!(
            out.bodies[0].angular_velocity < 0.0,
            "struck block turns forward"
        );
    }
}

/// A wedged group from the reference engine (ideal Domino T, s/h 0.45: 15
/// leaning blocks, e = 0 everywhere, ground friction 0.45/0.9): its e = 0
/// contacts release and reload many times under the paper's law. The
/// adaptive step must finish it in a few thousand steps, with the paper's
/// law (no held contacts), and agree with the fixed step at ΔP = 10⁻⁵ P₀.
#[test]
fn wedged_e0_group_ends_with_the_adaptive_step() {
    let (bodies, contacts) = load(include_str!("../data/ideal-t-wedged-group.json"));
    let fine = ImpactSolver::new()
        .solve(&bodies, &contacts, &ImpactSettings::fixed(1e-5))
        .unwrap();
    let speed = bodies
        .iter()
        .map(|b| b.velocity[0].hypot(b.velocity[1]) + 0.04 * b.angular_velocity.abs())
        .fold(0.0, f64::max);
    for (tolerance, allowed) in [(1e-4, 1e-3), (1e-6, 1e-5)] {
        let settings = ImpactSettings {
            max_steps: 5_000,
            ..ImpactSettings::adaptive(tolerance)
        };
        let out = ImpactSolver::new()
            .solve(&bodies, &contacts, &settings)
            .unwrap();
        let worst = out
            .bodies
            .iter()
            .zip(&fine.bodies)
            .map(|(a, b)| {
                (a.velocity[0] - b.velocity[0])
                    .abs()
                    .max((a.velocity[1] - b.velocity[1]).abs())
                    .max(0.04 * (a.angular_velocity - b.angular_velocity).abs())
            })
            .fold(0.0, f64::max);
        assert!(
            worst < allowed * speed,
            "tolerance {tolerance}: error {:.2e} of the speed",
            worst / speed
        );
    }
}

/// Fifteen Domino X blocks lying nearly flat on one another after the wave
/// has passed (a Rapier row at Δt = 2·10⁻⁴ s), struck again: 45 contacts,
/// two-point patches between faces, many of them touching without load. The
/// time-domain resolver once went 200,000 steps here without time moving on
/// (stuck and sliding patches switching back and forth at one instant). It
/// must end in a few hundred steps, create no energy and agree with the
/// impulse stepping at 10⁻⁷ (itself within 6·10⁻⁵ of 10⁻⁶), to about ten
/// times its tolerance.
#[test]
fn flat_lying_pile_impact_ends_and_matches_the_impulse_stepping() {
    let (bodies, contacts) = load(include_str!("../data/domino-x-flat-pile.json"));
    let fine = ImpactSolver::new()
        .solve(
            &bodies,
            &contacts,
            &ImpactSettings {
                max_steps: 1_000_000,
                ..ImpactSettings::adaptive_impulse(1e-7)
            },
        )
        .unwrap();
    let speed = bodies
        .iter()
        .map(|b| b.velocity[0].hypot(b.velocity[1]))
        .fold(0.0, f64::max);
    let rho = (bodies[0].inertia / bodies[0].mass).sqrt();
    for (settings, allowed) in [
        (ImpactSettings::default(), 2e-4),
        (ImpactSettings::adaptive(1e-4), 2e-3),
    ] {
        let settings = ImpactSettings {
            max_steps: 5_000,
            ..settings
        };
        let out = ImpactSolver::new()
            .solve(&bodies, &contacts, &settings)
            .unwrap();
        assert!(out.kinetic_energy_after <= out.kinetic_energy_before);
        let worst = crate::common::velocity_distance(&out.bodies, &fine.bodies, rho);
        assert!(
            worst < allowed * speed,
            "{settings:?}: error {:.2e} of the speed",
            worst / speed
        );
    }
}
