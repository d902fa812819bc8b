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
