//! The end of an impact at a rest speed (`ImpactSettings::rest_speed`,
//! docs/model.md §9), and impacts whose modes cycle without progress.
//!
//! Both fixtures are impacts of the pile scene (`assets/scenes/pile-boxes.toml`,
//! 150 boxes of 0.2 m, e = 0.3, μ = 0.5, μ_s = 0.6) as the Rapier plugin
//! handed them to the resolver.

use topple::coupling::{FallbackPolicy, GroupSolver, Resolution};
use topple::impact::audit::{check, AuditSummary};
use topple::impact::{
    Body, Contact, ImpactError, ImpactOutcome, ImpactSettings, ImpactSolver, StepControl,
    StopReason,
};

fn load(text: &str) -> (Vec<Body>, Vec<Contact>) {
    let input: serde_json::Value = serde_json::from_str(text).unwrap();
    let bodies = serde_json::from_value(input["bodies"].clone()).unwrap();
    let contacts = serde_json::from_value(input["contacts"].clone()).unwrap();
    (bodies, contacts)
}

fn speed(bodies: &[Body]) -> f64 {
    bodies
        .iter()
        .map(|b| b.velocity[0].hypot(b.velocity[1]))
        .fold(0.0, f64::max)
}

/// Largest difference of two outcomes' velocities (ω times the radius of
/// gyration), m/s.
fn difference(bodies: &[Body], a: &ImpactOutcome, b: &ImpactOutcome) -> f64 {
    bodies
        .iter()
        .zip(a.bodies.iter().zip(&b.bodies))
        .map(|(body, (x, y))| {
            let rho = (body.inertia / body.mass).sqrt();
            (x.velocity[0] - y.velocity[0])
                .abs()
                .max((x.velocity[1] - y.velocity[1]).abs())
                .max(rho * (x.angular_velocity - y.angular_velocity).abs())
        })
        .fold(0.0, f64::max)
}

/// Approach speed −δ̇ of a contact after the impact, from the bodies'
/// velocities at its point (m/s; positive: closing).
fn approach(bodies: &[Body], out: &ImpactOutcome, c: &Contact) -> f64 {
    let point_velocity = |side: usize| match c.bodies[side] {
        Some(k) if !bodies[k].fixed => {
            let b = &bodies[k];
            let v = &out.bodies[k];
            let r = [c.point[0] - b.position[0], c.point[1] - b.position[1]];
            [
                v.velocity[0] - v.angular_velocity * r[1],
                v.velocity[1] + v.angular_velocity * r[0],
            ]
        }
        _ => [0.0, 0.0],
    };
    let (a, b) = (point_velocity(0), point_velocity(1));
    // the normal points from the first body to the second
    -((b[0] - a[0]) * c.normal[0] + (b[1] - a[1]) * c.normal[1])
}

/// A box landing at 1.1 m/s on 14 resting boxes (33 contact points): under
/// the paper's law the wave sloshes between the boxes, held by their frozen
/// positions, for 4 s of the impact's own time and about 10⁴ steps, its
/// speeds falling a decade every thousand steps. With a rest speed the
/// impact ends where everything left is slower: far fewer steps; every
/// point then approaches slower than the rest speed (checked here from the
/// bodies' velocities, not from the resolver's state); the velocities
/// follow from the impulses and no energy is created (`impact::audit`);
/// and as the rest speed falls the outcome tends to the law's own.
#[test]
fn a_pile_landing_ends_at_the_rest_speed_and_tends_to_the_law_as_it_falls() {
    let (bodies, contacts) = load(include_str!("../data/pile-landing-33-contacts.json"));
    // the time-domain solver under the paper's law (every fast bounce
    // followed: the default holds them, which shortens the tail the rest
    // speed cuts, see the next test) and the paper's impulse stepping
    for base in [
        ImpactSettings {
            fast_cycle: 0.0,
            ..ImpactSettings::default()
        },
        ImpactSettings::adaptive_impulse(1e-4),
    ] {
        ends_at_the_rest_speed(&bodies, &contacts, base);
    }
}

fn ends_at_the_rest_speed(bodies: &[Body], contacts: &[Contact], base: ImpactSettings) {
    let v = speed(bodies);
    let mut solver = ImpactSolver::new();
    let full = solver.solve(bodies, contacts, &base).unwrap();
    assert_eq!(full.stop_reason, Some(StopReason::Released));
    let mut previous = f64::INFINITY;
    for fraction in [1e-2, 1e-3, 1e-4, 1e-6] {
        let rest = fraction * v;
        let settings = ImpactSettings {
            rest_speed: rest,
            ..base
        };
        let out = solver.solve(bodies, contacts, &settings).unwrap();
        let case = format!("{:?} at {fraction}", base.step_control);
        assert_eq!(out.stop_reason, Some(StopReason::AtRest), "{case}");
        assert!(out.steps < full.steps, "{case}: {} steps", out.steps);
        let mut audit = AuditSummary::default();
        check(bodies, contacts, &out, &mut audit);
        assert!(audit.consistency < 1e-9, "{case}: {audit:?}");
        assert!(audit.energy_gain <= 0.0, "{case}: {audit:?}");
        for c in contacts {
            let closing = approach(bodies, &out, c);
            assert!(closing <= rest * (1.0 + 1e-6), "{case}: {closing} > {rest}");
        }
        let off = difference(bodies, &out, &full) / v;
        assert!(off < previous, "{case}: {off:.2e} after {previous:.2e}");
        // the time-domain solver's steps go to the tail, the impulse
        // stepping's mostly to the wave itself (11,903 → 8,530 there)
        if fraction == 1e-2 && matches!(base.step_control, StepControl::Adaptive { .. }) {
            assert!(
                out.steps * 3 < full.steps,
                "{case}: {} of {}",
                out.steps,
                full.steps
            );
        }
        previous = off;
    }
    // at 10⁻⁶ of the speed the outcome is the law's to its tolerance
    assert!(previous < 1e-4, "{previous:.2e}");
}

/// The same pile landing at the default, which holds the fast bounces of
/// its e = 0.3 points (docs/model.md §8, "Fast bounces at e > 0"), against
/// the paper's law converged (every cycle followed, tolerance 10⁻¹⁰): the
/// hold drops at most the rebound of approaches within its bound
/// (0.03 · fast_cycle · V = 3·10⁻⁴ V), so the outcome stays within 10⁻³ of
/// the speed, as close as the law itself at the default tolerance
/// (4.8·10⁻⁴); it creates no energy, its velocities follow from its
/// impulses, and the sloshing tail it shortens takes at most 60 % of the
/// law's steps (5,660 against 10,863 when this was written).
#[test]
fn fast_bounces_in_a_pile_are_held_within_their_bound_of_the_law() {
    let (bodies, contacts) = load(include_str!("../data/pile-landing-33-contacts.json"));
    let v = speed(&bodies);
    let mut solver = ImpactSolver::new();
    let law = ImpactSettings {
        fast_cycle: 0.0,
        ..ImpactSettings::default()
    };
    let converged = solver
        .solve(
            &bodies,
            &contacts,
            &ImpactSettings {
                step_control: StepControl::Adaptive { tolerance: 1e-10 },
                ..law
            },
        )
        .unwrap();
    let followed = solver.solve(&bodies, &contacts, &law).unwrap();
    let held = solver
        .solve(&bodies, &contacts, &ImpactSettings::default())
        .unwrap();
    let off = difference(&bodies, &held, &converged) / v;
    assert!(off < 1e-3, "{off:.2e} of the speed");
    let mut audit = AuditSummary::default();
    check(&bodies, &contacts, &held, &mut audit);
    assert!(audit.consistency < 1e-9, "{audit:?}");
    assert!(audit.energy_gain <= 0.0, "{audit:?}");
    assert!(
        held.steps * 10 < followed.steps * 6,
        "{} steps held, {} followed",
        held.steps,
        followed.steps
    );
}

/// A rest speed at or above every approach ends the impact before it
/// starts: nothing changes.
#[test]
fn a_rest_speed_above_the_approach_leaves_the_bodies_as_they_were() {
    let (bodies, contacts) = load(include_str!("../data/pile-landing-33-contacts.json"));
    let settings = ImpactSettings {
        rest_speed: 2.0 * speed(&bodies),
        ..ImpactSettings::default()
    };
    let out = ImpactSolver::new()
        .solve(&bodies, &contacts, &settings)
        .unwrap();
    assert_eq!(out.stop_reason, Some(StopReason::AtRest));
    for (b, a) in bodies.iter().zip(&out.bodies) {
        assert_eq!(a.velocity, b.velocity);
        assert_eq!(a.angular_velocity, b.angular_velocity);
    }
}

#[test]
fn a_negative_or_infinite_rest_speed_is_refused() {
    let (bodies, contacts) = load(include_str!("../data/pile-landing-33-contacts.json"));
    for rest in [-1.0, f64::INFINITY, f64::NAN] {
        let settings = ImpactSettings {
            rest_speed: rest,
            ..ImpactSettings::default()
        };
        let r = ImpactSolver::new().solve(&bodies, &contacts, &settings);
        assert!(
            matches!(r, Err(ImpactError::InvalidSettings(_))),
            "{rest}: {r:?}"
        );
    }
}

/// A box landing at 4 m/s on a stack of four (16 contact points). A stuck
/// patch reaches its bound μ_s N; broken loose, it slides with μ < μ_s and
/// the rows around it turn its slip back, so it sticks again at once: a
/// cycle that made the time-domain solver crawl by 10⁻⁷ of a step per
/// switch (200,000 steps, 55 s). Such a run of switches without progress
/// now ends the attempt within a few hundred steps, and the fallback policy
/// finishes the impact without creating energy.
#[test]
fn a_stick_slip_cycle_at_the_bound_ends_the_attempt_and_the_fallback_finishes() {
    let (bodies, contacts) = load(include_str!("../data/pile-stick-bound-stall.json"));
    let settings = ImpactSettings {
        max_steps: 100_000,
        ..ImpactSettings::default()
    };
    match ImpactSolver::new().solve(&bodies, &contacts, &settings) {
        Ok(out) => assert!(out.kinetic_energy_after <= out.kinetic_energy_before),
        Err(ImpactError::StepLimit { steps }) => assert!(steps < 5_000, "{steps} steps"),
        Err(e) => panic!("{e}"),
    }
    let mut out = ImpactOutcome::default();
    let how = GroupSolver::default()
        .solve_into(
            &bodies,
            &contacts,
            &settings,
            &FallbackPolicy::default(),
            &mut out,
        )
        .unwrap();
    assert_ne!(how, Resolution::Rejected);
    let mut audit = AuditSummary::default();
    check(&bodies, &contacts, &out, &mut audit);
    assert_eq!(audit.non_finite, 0);
    assert!(audit.energy_gain <= 1e-9, "{audit:?}");
    assert!(audit.consistency < 1e-9, "{audit:?}");
}

/// An impact of the pile in the Bevy frame bench (pixel units, 17 boxes, 47
/// points) whose stick/slip choices cycle at its switches: each settling of
/// the modes ran to its cap and the standstill guard ended the impact after
/// 256 steps (the fallback then finished it plastic). A settling now ends
/// where its passes come back to a state they left, and the law resolves
/// the impact, checked against the invariants of the audit (no energy
/// created, velocities consistent with the impulses the contacts took).
#[test]
fn a_settling_that_cycles_ends_and_the_law_resolves_the_impact() {
    let text = include_str!("../data/settling-cycle.json");
    let (bodies, contacts) = load(text);
    let input: serde_json::Value = serde_json::from_str(text).unwrap();
    let settings: ImpactSettings = serde_json::from_value(input["settings"].clone()).unwrap();
    let out = ImpactSolver::new()
        .solve(&bodies, &contacts, &settings)
        .expect("resolved by the law");
    // settling is a small part of the work, no longer most of it
    assert!(
        out.settling_evaluations < 6 * (out.steps + out.rejected_steps),
        "{out:?}"
    );
    let mut audit = AuditSummary::default();
    check(&bodies, &contacts, &out, &mut audit);
    assert_eq!(audit.non_finite, 0);
    assert!(audit.energy_gain <= 1e-9, "{audit:?}");
    assert!(audit.consistency < 1e-9, "{audit:?}");
}

/// With a rest speed v_r the e = 0 release–reload cycles are taken by
/// their limit once a cycle moves the point's rate by at most 30 v_r
/// (docs/model.md §8, "With a rest speed"). On the captured impacts of an
/// ideal Domino T row at 1/60 s (the bench's `t-row`, the plugins'
/// settings: tolerance 10⁻⁶, v_r = 0.01 · 2|g|Δt) each outcome stays
/// within the rest speed's own tail, 3 v_r (§9), of the paper's law
/// converged (every cycle followed, tolerance 10⁻¹⁰, no rest speed); no
/// energy is created and the velocities follow from the impulses.
#[test]
fn e0_cycles_slower_than_the_rest_speeds_are_held_within_its_tail_of_the_law() {
    let rest = 0.01 * 2.0 * 9.81 / 60.0;
    let plugin = ImpactSettings {
        rest_speed: rest,
        ..ImpactSettings::adaptive(1e-6)
    };
    let law = ImpactSettings {
        fast_cycle: 0.0,
        max_steps: 1_000_000,
        ..ImpactSettings::adaptive(1e-10)
    };
    let text = include_str!("../../benches/data/t-row-1-60.jsonl");
    let mut solver = ImpactSolver::new();
    let mut impacts = 0;
    for line in text.lines().filter(|l| !l.trim().is_empty()) {
        let c: topple::impact::capture::CapturedImpact = serde_json::from_str(line).unwrap();
        let (bodies, contacts) = (c.bodies, c.contacts);
        let converged = solver.solve(&bodies, &contacts, &law).unwrap();
        let out = solver.solve(&bodies, &contacts, &plugin).unwrap();
        let off = difference(&bodies, &out, &converged);
        assert!(off < 3.0 * rest, "{off:.2e} m/s against v_r = {rest:.2e}");
        let mut audit = AuditSummary::default();
        check(&bodies, &contacts, &out, &mut audit);
        assert!(audit.consistency < 1e-9, "{audit:?}");
        assert!(audit.energy_gain <= 0.0, "{audit:?}");
        impacts += 1;
    }
    assert_eq!(impacts, 6);
}
