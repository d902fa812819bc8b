//! The work budget of a step bounds a pile's frames by default: no step's
//! impacts together do more resolver work than the budget, counted from
//! the resolver's own step counts (deterministic, never wall time), while
//! the same pile without a budget has steps that need more. Impacts the
//! budget cut short are finished without creating energy.

use topple::coupling::{Resolution, ToppleSettings};
use topple::rapier::f64::build;
use topple::rapier::scene::{load_scene, ImpactResponse, Scene, WorkBudget};

fn pile() -> Scene {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/pile-boxes.toml");
    load_scene(&path).unwrap()
}

/// Per step of the first `seconds` of the scene: (work from the adapter's
/// running total, Σ steps × contact points of the step's impact reports).
/// Also checks every impact report against energy creation and every body
/// against NaN and the ground.
fn step_work(scene: &Scene, seconds: f64) -> (Vec<(u64, u64)>, u64) {
    let mut sw = build(scene, ImpactResponse::Topple).unwrap();
    let steps = (seconds / sw.world.integration_parameters.dt).round() as usize;
    let mut out = Vec::with_capacity(steps);
    for _ in 0..steps {
        let before = sw.topple.stats().work;
        let reports = sw.step().to_vec();
        // a plastic fallback reports its sweeps, which are not LZB work
        let from_reports: u64 = reports
            .iter()
            .filter(|r| matches!(r.resolution, Resolution::Lzb | Resolution::Held))
            .map(|r| (r.steps * r.contacts) as u64)
            .sum();
        out.push((sw.topple.stats().work - before, from_reports));
        for r in &reports {
            // 10⁻⁹ relative: the resolvers' round-off on the group's energy
            assert!(
                r.kinetic_energy_after <= r.kinetic_energy_before * (1.0 + 1e-9) + 1e-12,
                "an impact created energy: {r:?}"
            );
        }
        for (name, h, _) in &sw.bodies {
            let rb = &sw.world.bodies[*h];
            let p = rb.translation();
            assert!(p.x.is_finite() && p.y.is_finite(), "{name} is NaN");
            // box half-diagonal 0.141 m: a centre below 0.05 m is through the floor
            assert!(
                p.y > 0.05 || rb.is_fixed(),
                "{name} went through the floor: y {}",
                p.y
            );
        }
    }
    (out, sw.topple.stats().budget_spent)
}

#[test]
fn the_default_budget_bounds_every_step_of_a_pile() {
    let bounded = pile();
    // what a scene gets when it says nothing: a game's bounded step
    assert_eq!(bounded.solver.max_work, WorkBudget::default());
    let budget = ToppleSettings::DEFAULT_STEP_WORK;
    assert_eq!(bounded.solver.max_work.max_work(), Some(budget));
    let mut exact = bounded.clone();
    exact.solver.max_work = WorkBudget::Unbounded;
    let seconds = 2.0;
    let (free, _) = step_work(&exact, seconds);
    let (held, spent) = step_work(&bounded, seconds);
    let worst = |w: &[(u64, u64)]| w.iter().map(|s| s.0).max().unwrap_or(0);
    // the pile without a budget has steps that need more than it
    assert!(
        worst(&free) > budget,
        "the unbounded pile's worst step {} does not exceed {budget}: the test shows nothing",
        worst(&free)
    );
    for (k, &(work, from_reports)) in held.iter().enumerate() {
        assert!(work <= budget, "step {k}: work {work} > budget {budget}");
        // accepted steps only: at most the work that also counts rejected ones
        assert!(
            from_reports <= work,
            "step {k}: reports {from_reports} > work {work}"
        );
    }
    assert!(spent > 0, "no step ran out of its budget");
}
