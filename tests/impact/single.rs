//! One contact: closed forms independent of the resolver.
//!
//! For a single frictionless contact the LZB model reduces to a two-body
//! collision with effective mass m_eff = 1/W (W = J M⁻¹ Jᵀ): the normal
//! relative velocity after is −e times the one before (energetic restitution
//! equals Newton's for one contact), and the peak stored energy is the
//! kinetic energy of the relative motion, ½ m_eff δ̇².

use topple::impact::{Body, Contact, ContactMaterial, ImpactSettings, ImpactSolver};

fn material(e: f64, alpha: f64) -> ContactMaterial {
    ContactMaterial::hertz(1e7)
        .with_exponent(alpha)
        .with_restitution(e)
}

#[test]
fn two_bodies_rebound_with_minus_e_and_peak_energy_is_half_meff_v2() {
    let mut solver = ImpactSolver::new();
    for &e in &[0.0, 0.3, 0.7, 1.0] {
        for &alpha in &[1.0, 1.5] {
            for &mass_ratio in &[1.0, 0.1, 7.0] {
                let (m1, m2) = (1.0, mass_ratio);
                let (v1, v2) = (1.3, -0.4);
                let bodies = [
                    Body::new(m1, 0.1).with_velocity([v1, 0.0]),
                    Body::new(m2, 0.1)
                        .with_position([1.0, 0.0])
                        .with_velocity([v2, 0.0]),
                ];
                // contact on the line of centres: no rotation
                let contacts = [Contact::new(
                    [Some(0), Some(1)],
                    [0.5, 0.0],
                    [1.0, 0.0],
                    material(e, alpha),
                )];
                let out = solver
                    .solve(&bodies, &contacts, &ImpactSettings::default())
                    .unwrap();
                let before = v2 - v1;
                let after = out.bodies[1].velocity[0] - out.bodies[0].velocity[0];
                assert!(
                    (after + e * before).abs() < 1e-6 * before.abs(),
                    "e={e} α={alpha} m2={m2}: after {after}, expected {}",
                    -e * before
                );
                let meff = m1 * m2 / (m1 + m2);
                let peak = 0.5 * meff * before * before;
                let got = out.contacts[0].peak_energy;
                assert!(
                    (got - peak).abs() < 1e-6 * peak,
                    "peak energy {got} vs {peak}"
                );
                // momentum
                // momentum, to rounding over the steps taken (N ε |p|)
                let p = m1 * out.bodies[0].velocity[0] + m2 * out.bodies[1].velocity[0];
                let drift = p - (m1 * v1 + m2 * v2);
                assert!(
                    drift.abs() < out.steps as f64 * 1e-15,
                    "momentum drift {drift:e}"
                );
            }
        }
    }
}

#[test]
fn eccentric_hit_on_a_rotating_body_uses_the_effective_mass() {
    // A rod (m = 2, I = 0.3) hit off-centre by a point-like ball against a
    // wall: W = 1/m_ball + 1/m + r²/I along the normal.
    let mut solver = ImpactSolver::new();
    for &e in &[0.0, 0.5, 1.0] {
        let bodies = [
            Body::new(0.5, 1e-3).with_velocity([2.0, 0.0]),
            Body::new(2.0, 0.3)
                .with_position([0.5, -0.4])
                .with_angular_velocity(0.7),
        ];
        let contacts = [Contact::new(
            [Some(0), Some(1)],
            [0.5, 0.0],
            [1.0, 0.0],
            material(e, 1.5),
        )];
        let out = solver
            .solve(&bodies, &contacts, &ImpactSettings::adaptive(1e-8))
            .unwrap();
        // normal rate at the point: n·(v + ω × r), r = (0, 0.4) from the rod
        let rate = |vb: [f64; 2], wb: f64, va: [f64; 2]| (vb[0] - wb * 0.4) - va[0];
        let before = rate([0.0, 0.0], 0.7, [2.0, 0.0]);
        let after = rate(
            out.bodies[1].velocity,
            out.bodies[1].angular_velocity,
            out.bodies[0].velocity,
        );
        assert!(
            (after + e * before).abs() < 1e-6,
            "e={e}: {after} vs {}",
            -e * before
        );
        let w = 1.0 / 0.5 + 1.0 / 2.0 + 0.4 * 0.4 / 0.3;
        let peak = 0.5 * before * before / w;
        assert!((out.contacts[0].peak_energy - peak).abs() < 1e-6 * peak);
        assert!(out.kinetic_energy_after <= out.kinetic_energy_before * (1.0 + 1e-12));
    }
}

#[test]
fn bodies_moving_apart_are_left_alone() {
    let bodies = [
        Body::new(1.0, 0.1).with_velocity([-1.0, 0.0]),
        Body::new(1.0, 0.1).with_position([1.0, 0.0]),
    ];
    let contacts = [Contact::new(
        [Some(0), Some(1)],
        [0.5, 0.0],
        [1.0, 0.0],
        material(1.0, 1.5),
    )];
    let out = ImpactSolver::new()
        .solve(&bodies, &contacts, &ImpactSettings::default())
        .unwrap();
    assert_eq!(out.bodies[0].velocity, [-1.0, 0.0]);
    assert_eq!(out.steps, 0);
    assert_eq!(out.contacts[0].normal_impulse, 0.0);
}

#[test]
fn invalid_input_is_an_error_not_a_panic() {
    let good = [Body::new(1.0, 0.1).with_velocity([1.0, 0.0])];
    let wall = |normal: [f64; 2], e: f64| {
        [Contact::new(
            [Some(0), None],
            [0.5, 0.0],
            normal,
            material(e, 1.5),
        )]
    };
    let mut solver = ImpactSolver::new();
    let s = ImpactSettings::default();
    assert!(solver
        .solve(&[Body::new(0.0, 0.1)], &wall([1.0, 0.0], 1.0), &s)
        .is_err());
    assert!(solver.solve(&good, &wall([0.0, 0.0], 1.0), &s).is_err());
    assert!(solver.solve(&good, &wall([1.0, 0.0], 1.5), &s).is_err());
    assert!(solver
        .solve(&good, &wall([f64::NAN, 0.0], 1.0), &s)
        .is_err());
    let bad_index = [Contact::new(
        [Some(0), Some(3)],
        [0.5, 0.0],
        [1.0, 0.0],
        material(1.0, 1.5),
    )];
    assert!(solver.solve(&good, &bad_index, &s).is_err());
    assert!(solver
        .solve(&good, &wall([1.0, 0.0], 1.0), &ImpactSettings::fixed(0.0))
        .is_err());
    // a step limit ends a long impact with an error (a lone contact takes a
    // few steps, so one is too few)
    let limited = ImpactSettings {
        max_steps: 1,
        ..ImpactSettings::default()
    };
    assert!(matches!(
        solver.solve(&good, &wall([1.0, 0.0], 1.0), &limited),
        Err(topple::impact::ImpactError::StepLimit { .. })
    ));
}

#[test]
fn results_are_deterministic() {
    let bodies = [
        Body::new(1.0, 0.1)
            .with_velocity([1.0, 0.2])
            .with_angular_velocity(0.3),
        Body::new(2.0, 0.3).with_position([1.0, 0.1]),
    ];
    let m = material(0.6, 1.5).with_friction(0.3, 0.4);
    let contacts = [
        Contact::new([Some(0), Some(1)], [0.5, 0.0], [1.0, 0.0], m),
        Contact::new([None, Some(0)], [0.0, -0.5], [0.0, 1.0], m),
    ];
    let a = ImpactSolver::new()
        .solve(&bodies, &contacts, &ImpactSettings::default())
        .unwrap();
    let b = ImpactSolver::new()
        .solve(&bodies, &contacts, &ImpactSettings::default())
        .unwrap();
    assert_eq!(a, b);
}

#[test]
fn held_e0_chain_moves_as_one_body() {
    // With e = 0 and `e0_hold`, every contact ends held closed: a row of
    // touching balls struck at one end ends moving together at the common
    // velocity momentum gives (perfectly plastic), v₁ m₁ / Σ m.
    for n in [2usize, 3, 5] {
        let masses: Vec<f64> = (0..n).map(|i| 1.0 + 0.5 * i as f64).collect();
        let bodies: Vec<Body> = (0..n)
            .map(|i| {
                Body::new(masses[i], 0.01)
                    .with_position([0.2 * i as f64, 0.0])
                    .with_velocity([if i == 0 { 2.0 } else { 0.0 }, 0.0])
            })
            .collect();
        let contacts: Vec<Contact> = (0..n - 1)
            .map(|j| {
                Contact::new(
                    [Some(j), Some(j + 1)],
                    [0.2 * j as f64 + 0.1, 0.0],
                    [1.0, 0.0],
                    material(0.0, 1.5),
                )
            })
            .collect();
        let settings = ImpactSettings {
            e0_hold: true,
            ..ImpactSettings::default()
        };
        let out = ImpactSolver::new()
            .solve(&bodies, &contacts, &settings)
            .unwrap();
        let common = 2.0 * masses[0] / masses.iter().sum::<f64>();
        for b in &out.bodies {
            assert!(
                (b.velocity[0] - common).abs() < 1e-6,
                "n = {n}: {} vs {common}",
                b.velocity[0]
            );
        }
    }
}
