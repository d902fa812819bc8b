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

/// The default budget's cap on large groups
/// (`FallbackPolicy::large_group`): in the pile, every impact of more free
/// bodies than the cap's size that the law finished stayed within the cap's
/// work (accepted steps times contact points, plus the last step and two
/// settlings of the modes the resolver may take past it), the others ended
/// plastic without creating energy (checked by `step_work` for every
/// impact), and large groups did end plastic.
#[test]
fn large_groups_of_a_pile_end_plastic_within_their_cap() {
    let mut sw = build(&pile(), ImpactResponse::Topple).unwrap();
    let policy = sw.topple.settings().fallback;
    let large = policy.large_group.expect("the default caps large groups");
    assert!(policy.max_work.is_some());
    let (mut capped, mut lzb) = (0, 0);
    for _ in 0..(2.0 / sw.world.integration_parameters.dt).round() as usize {
        for r in sw.step() {
            if !r.large_group {
                continue;
            }
            assert!(r.bodies > large.bodies, "{r:?}");
            match r.resolution {
                Resolution::Lzb => {
                    let c = r.contacts as u64;
                    let settle = (4 + 4 * c) / 6 + 1;
                    let work = r.steps as u64 * c;
                    assert!(
                        work <= large.work + (1 + 2 * settle) * c,
                        "a large group's law spent {work}: {r:?}"
                    );
                    lzb += 1;
                }
                Resolution::Plastic => capped += 1,
                _ => {}
            }
        }
    }
    assert!(capped > 0, "no large group ended plastic (law: {lzb})");
}

/// The twelve rows of docs/game-rate.md (six rows, both builds; 100 blocks
/// at 1/60 s) under the default work budget and its cap on large groups end
/// with the same bits as the unbounded accuracy runs of `topple chain
/// --engine rapier`: no row step spends the budget, and no row impact is a
/// large group.
#[test]
fn the_budget_and_its_large_group_cap_leave_the_rows_untouched() {
    use topple::domino::{Preset, RowSpec};
    use topple::engines::{RapierRow, RowEngine};
    use topple::rapier::scene::SolverSpec;
    use topple::rapier::Precision;
    let rows = [
        (Preset::T.params().ideal(), 0.25),
        (Preset::T.params().ideal(), 0.45),
        (Preset::X.params(), 0.3),
        (Preset::X.params(), 0.52),
        (Preset::T.params(), 0.3),
        (Preset::P.params(), 0.3),
    ];
    for (p, s) in rows {
        let row = RowSpec::new(p, s * p.block.height, 100, 1.0);
        for precision in [Precision::F64, Precision::F32] {
            let run = |max_work| {
                let engine = RapierRow {
                    precision,
                    solver: SolverSpec {
                        dt: 1.0 / 60.0,
                        max_group_hops: Some(ToppleSettings::DEFAULT_WINDOW),
                        max_work,
                        ..SolverSpec::default()
                    },
                    ..RapierRow::new(ImpactResponse::Topple, 1.0 / 60.0)
                };
                engine.run(&row, &mut |_| {}).unwrap()
            };
            let (exact, game) = (run(WorkBudget::Unbounded), run(WorkBudget::default()));
            let what = format!("s/h {s}, {precision:?}");
            assert!(exact.natural_speed.is_some(), "{what}: no wave");
            assert_eq!(exact.natural_speed, game.natural_speed, "{what}");
            assert_eq!(exact.hit_times, game.hit_times, "{what}");
            assert_eq!(
                (exact.impacts, exact.impact_fallbacks),
                (game.impacts, game.impact_fallbacks),
                "{what}"
            );
        }
    }
}
