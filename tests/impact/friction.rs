//! Coulomb friction inside the impact (docs/model.md §4), against closed forms.
//!
//! A disk of radius r lands on the ground with velocity (u, −w) and spin ω.
//! The normal passes through the centre, so the normal and tangential problems
//! decouple: P_n = (1 + e) m w exactly, and
//! - if the contact slides throughout, P_t = −μ sgn(slip) P_n;
//! - if it sticks, the slip s = u − ω r (contact-point velocity) ends at 0,
//!   which needs P_t = −s / (1/m + r²/I), allowed while |P_t| ≤ μ_s P_n.

use topple::impact::{Body, Contact, ContactMaterial, ImpactSettings, ImpactSolver};

const M: f64 = 0.8;
const R: f64 = 0.05;
const I: f64 = 0.5 * M * R * R;

fn landing(u: f64, w: f64, spin: f64, e: f64, mu: f64, mu_s: f64) -> topple::impact::ImpactOutcome {
    let bodies = [Body::new(M, I)
        .with_position([0.0, R])
        .with_velocity([u, -w])
        .with_angular_velocity(spin)];
    let material = ContactMaterial::hertz(1e8)
        .with_restitution(e)
        .with_friction(mu, mu_s);
    // world first, normal up: the tangent t = (−1, 0)
    let contacts = [Contact::new(
        [None, Some(0)],
        [0.0, 0.0],
        [0.0, 1.0],
        material,
    )];
    ImpactSolver::new()
        .solve(&bodies, &contacts, &ImpactSettings::default())
        .unwrap()
}

#[test]
fn oblique_hit_slides_and_loses_tangential_speed() {
    let (u, w, e, mu) = (2.0, 1.0, 0.5, 0.2);
    let out = landing(u, w, 0.0, e, mu, mu);
    let pn = out.contacts[0].normal_impulse;
    let pt = out.contacts[0].tangent_impulse;
    assert!((pn - (1.0 + e) * M * w).abs() < 1e-6 * pn, "P_n {pn}");
    // Slides throughout: |P_t| = μ P_n, opposing the slip (slip along +x = −t).
    assert!(pt.abs() <= mu * pn * (1.0 + 1e-9));
    assert!((pt.abs() - mu * pn).abs() < 1e-6 * pn, "P_t {pt}");
    let v = out.bodies[0].velocity;
    assert!(v[0] < u, "tangential speed must drop: {}", v[0]);
    assert!((v[0] - (u - mu * pn / M)).abs() < 1e-6);
    assert!((v[1] - e * w).abs() < 1e-6);
    assert!(out.kinetic_energy_after < out.kinetic_energy_before);
}

#[test]
fn large_stick_friction_sticks() {
    let (u, w, e, spin) = (0.3, 1.0, 0.0, 2.0);
    let out = landing(u, w, spin, e, 0.5, 1.5);
    let v = out.bodies[0].velocity;
    let omega = out.bodies[0].angular_velocity;
    // contact point velocity along x: v + ω × (0, −r) = v_x + ω r
    let slip_after = v[0] + omega * R;
    assert!(slip_after.abs() < 1e-9, "slip after {slip_after}");
    let slip_before = u + spin * R;
    let pt_x = -slip_before / (1.0 / M + R * R / I); // impulse along +x
    let pt = out.contacts[0].tangent_impulse; // along t = (−1, 0)
    assert!(
        (-pt - pt_x).abs() < 1e-6 * pt_x.abs(),
        "P_t {pt} vs {}",
        -pt_x
    );
    assert!(pt.abs() <= 1.5 * out.contacts[0].normal_impulse);
}

#[test]
fn small_slip_stops_and_then_sticks() {
    // μ large enough to stop the slip within the impact, μ_s = μ: the contact
    // ends rolling, with the impulse of the sticking closed form.
    let (u, w) = (0.05, 1.0);
    let out = landing(u, w, 0.0, 0.0, 0.4, 0.4);
    let v = out.bodies[0].velocity;
    let slip_after = v[0] + out.bodies[0].angular_velocity * R;
    assert!(slip_after.abs() < 1e-9);
    assert!(out.contacts[0].tangent_impulse.abs() <= 0.4 * out.contacts[0].normal_impulse + 1e-12);
}

/// A block of an ideal Domino T row struck near its top while it stands on
/// the two corners of its foot (the first impact of the row in the Rapier
/// plugin, cut down to the two blocks): the foot's corner starts a rounding
/// into the ground (7·10⁻⁸ m) with its friction patch idle, then loads from
/// rest while it slides. Its friction must act from the first of its load:
/// the time-domain resolver converged (10⁻¹⁰) and the paper's impulse
/// stepping (adaptive, 10⁻⁷, a different integrator of the same law) give
/// the same answer to 10⁻⁶ of the speed. Before the onset of such a point
/// was a switch they were 7·10⁻⁴ apart: the corner took its first 1.7 % of
/// normal impulse without friction.
#[test]
fn friction_acts_from_the_first_load_of_a_point_that_starts_at_zero() {
    let bodies = [
        Body::new(1.0, 0.000_541_013_333_333_333_4)
            .with_position([0.242_183_460_192_645_83, 0.037_506_287_042_613_43])
            .with_velocity([0.550_895_333_742_177_4, -0.270_916_771_990_913_46])
            .with_angular_velocity(-22.883_503_958_458_288),
        Body::new(1.0, 0.000_541_013_333_333_333_4)
            .with_position([0.2736, 0.039_999_859_444_122_6]),
    ];
    let between = ContactMaterial {
        stiffness: 2.3e8,
        exponent: 1.5,
        restitution: 0.0,
        friction: 0.0,
        stick_friction: 0.0,
    };
    let ground = ContactMaterial {
        stiffness: 6.9e8,
        exponent: 1.5,
        restitution: 0.0,
        friction: 0.45,
        stick_friction: 0.9,
    };
    let contacts = [
        Contact::new(
            [Some(0), Some(1)],
            [0.2688, 0.067_748_638_725_312_87],
            [1.0, 0.0],
            between,
        ),
        Contact::new(
            [Some(1), None],
            [0.2688, -7.027_793_870_809_096e-8],
            [0.0, -1.0],
            ground,
        ),
        Contact::new(
            [Some(1), None],
            [0.2784, -7.027_793_869_421_317e-8],
            [0.0, -1.0],
            ground,
        ),
    ];
    let mut solver = ImpactSolver::new();
    let in_time = solver
        .solve(&bodies, &contacts, &ImpactSettings::adaptive(1e-10))
        .unwrap();
    let in_impulse = solver
        .solve(&bodies, &contacts, &ImpactSettings::adaptive_impulse(1e-7))
        .unwrap();
    let speed = bodies[0].velocity[0].hypot(bodies[0].velocity[1]);
    let rho = (bodies[1].inertia / bodies[1].mass).sqrt();
    let worst = crate::common::velocity_distance(&in_time.bodies, &in_impulse.bodies, rho);
    assert!(worst < 1e-6 * speed, "{:.2e} of the speed", worst / speed);
    // the corner that loads slides all through: P_t = μ P_n
    let corner = in_time.contacts[2];
    assert!(corner.normal_impulse > 0.0);
    let ratio = corner.tangent_impulse.abs() / corner.normal_impulse;
    assert!((ratio - 0.45).abs() < 1e-6, "P_t / P_n = {ratio}");
}
