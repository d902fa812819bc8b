//! Independent impacts of a step solved side by side (docs/bevy.md,
//! "Independent impacts side by side"): several far-apart domino rows and
//! Newton's cradles in one world, as in the show, give the same bits with
//! batches as one instant at a time — every body's pose and velocity at
//! every step, every impact event with its bodies and contact impulses —
//! under the default work budget, under a budget small enough that the
//! sequential order's fallbacks show, and without a budget. The cradles
//! are checked against their closed form (momentum and energy of an
//! elastic cradle), and each row inside the shared world against the same
//! row alone in its own world.

use topple::rapier::f64::{build, SceneWorld};
use topple::rapier::scene::{expand_row, ImpactResponse, RowSection, Scene, WorkBudget};

/// `rows` Domino T rows of 10 blocks at s/h = 0.35, 1 m apart along x,
/// row r pushed at 1 + r/4 (so that their fronts hit at different
/// instants), at the game's 1/60 s.
fn rows(rows: usize, budget: WorkBudget) -> Scene {
    let mut scene: Scene = toml::from_str(
        r#"
duration = 1.0
[solver]
dt = 0.016666666666666666
length_unit = 0.01
"#,
    )
    .unwrap();
    scene.solver.max_work = budget;
    for r in 0..rows {
        let mut one = scene.clone();
        let row: RowSection = toml::from_str(&format!(
            "preset = \"T\"\nn = 10\nspacing = 0.35\npush = {}",
            1.0 + 0.25 * r as f64
        ))
        .unwrap();
        expand_row(&mut one, &row).unwrap();
        if r == 0 {
            scene.materials = one.materials.clone();
            scene.pairs = one.pairs.clone();
            scene.ground = one.ground.clone();
        }
        for mut b in one.bodies {
            b.position[0] += 1.0 * r as f64;
            b.name = b.name.map(|n| format!("row{r}-{n}"));
            scene.bodies.push(b);
        }
    }
    scene
}

/// `cradles` five-ball elastic cradles (r = 0.05 m, 1 kg, no gravity),
/// 1 m apart along y; cradle c's first ball starts 1 mm + 10c µm short of
/// the second at 1 m/s, so that the cradles hit 10 µs apart: the step is
/// split at the first closing, the others fall in the next piece.
fn cradles(cradles: usize) -> Scene {
    let mut scene: Scene = toml::from_str(
        r#"
duration = 0.2
gravity = [0.0, 0.0]
[solver]
dt = 0.016666666666666666
length_unit = 0.1
[[materials]]
name = "steel"
stiffness = 2.3e10
restitution = 1.0
"#,
    )
    .unwrap();
    for c in 0..cradles {
        for i in 0..5 {
            let gap = if i == 0 { 1e-3 + 1e-5 * c as f64 } else { 0.0 };
            let spec = format!(
                "name = \"c{c}b{i}\"\nshape = \"ball\"\nradius = 0.05\nposition = [{}, {}]\nvelocity = [{}, 0.0]\nmass = 1.0\nmaterial = \"steel\"",
                0.1 * i as f64 - gap,
                1.0 * c as f64,
                if i == 0 { 1.0 } else { 0.0 }
            );
            scene.bodies.push(toml::from_str(&spec).unwrap());
        }
    }
    scene
}

/// One step of a run: every body's pose and velocity (bits), then every
/// impact event of the step with its bodies and contacts.
type Trace = Vec<(Vec<[u64; 6]>, String)>;

/// Runs `scene` for `steps` steps with batches on or off; the trace and
/// the adapter's count of impacts solved in batches.
fn run(scene: &Scene, batches: bool, steps: usize) -> (Trace, u64, u64) {
    let mut sw = build(scene, ImpactResponse::Topple).unwrap();
    sw.topple.set_impact_batches(batches);
    let mut trace = Vec::with_capacity(steps);
    for _ in 0..steps {
        sw.step();
        trace.push((poses(&sw), events(&sw)));
    }
    let stats = sw.topple.stats();
    (trace, stats.batched_impacts, stats.batch_resolves)
}

fn poses(sw: &SceneWorld) -> Vec<[u64; 6]> {
    sw.bodies
        .iter()
        .map(|(_, h, _)| {
            let rb = &sw.world.bodies[*h];
            let (p, v) = (rb.translation(), rb.linvel());
            [
                p.x.to_bits(),
                p.y.to_bits(),
                rb.rotation().angle().to_bits(),
                v.x.to_bits(),
                v.y.to_bits(),
                rb.angvel().to_bits(),
            ]
        })
        .collect()
}

/// The step's events, their bodies and contacts, in full (Debug of f64
/// prints the shortest string that reads back to the same bits).
fn events(sw: &SceneWorld) -> String {
    sw.topple
        .last_events()
        .iter()
        .map(|e| {
            format!(
                "{e:?} {:?} {:?}\n",
                sw.topple.event_bodies(e),
                sw.topple.event_contacts(e)
            )
        })
        .collect()
}

/// Batches on and off give the same trace; returns the batched count.
fn same_bits(scene: &Scene, steps: usize) -> (u64, u64) {
    let (one, none, _) = run(scene, false, steps);
    let (batched, count, again) = run(scene, true, steps);
    assert_eq!(none, 0);
    for (k, (a, b)) in one.iter().zip(&batched).enumerate() {
        assert_eq!(a.1, b.1, "step {k}: the events differ");
        assert_eq!(a.0, b.0, "step {k}: the bodies differ");
    }
    (count, again)
}

#[test]
fn far_apart_rows_give_the_same_bits_in_batches_under_the_default_budget() {
    let (batched, _) = same_bits(&rows(6, WorkBudget::default()), 60);
    // the test exercises batches: impacts of several rows were solved side
    // by side
    assert!(batched > 0, "no impact was solved in a batch");
}

#[test]
fn far_apart_rows_give_the_same_bits_in_batches_without_a_budget() {
    let (batched, again) = same_bits(&rows(6, WorkBudget::Unbounded), 60);
    assert!(batched > 0, "no impact was solved in a batch");
    assert_eq!(again, 0, "without a budget nothing is solved again");
}

/// Budgets of one to a few impacts per step: the sequential order runs
/// them out part-way through a step's impacts, the later ones end plastic
/// on their closing pair, and an impact of a batch may have less left than
/// it was solved with; batches give the same bits, solving such an impact
/// again when its result may depend on it.
#[test]
fn small_budgets_give_the_sequential_fallbacks_in_batches() {
    let mut again = 0;
    for budget in [3_000, 8_000, 20_000] {
        let scene = rows(6, WorkBudget::Work(budget));
        let (batched, solved_again) = same_bits(&scene, 60);
        assert!(batched > 0, "{budget}: no impact was solved in a batch");
        again += solved_again;
        let mut sw = build(&scene, ImpactResponse::Topple).unwrap();
        for _ in 0..60 {
            sw.step();
        }
        let s = sw.topple.stats();
        assert!(
            s.plastic_fallbacks + s.held_impacts > 0 && s.budget_spent > 0,
            "{budget}: the budget never ran out: {s:?}"
        );
    }
    // some impacts of a batch were solved again with the budget the
    // sequential order left them (`ImpactGroups::same_under`)
    assert!(again > 0, "no impact was solved again");
}

/// The pile scene (boxes landing on one another, large groups capped and
/// ending plastic under the default budget): many impacts of a step are
/// not independent, those that are go in batches; the same bits.
#[test]
fn a_pile_gives_the_same_bits_in_batches() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/pile-boxes.toml");
    let scene = topple::rapier::scene::load_scene(&path).unwrap();
    let steps = (1.5 / scene.solver.dt).round() as usize;
    let (batched, _) = same_bits(&scene, steps);
    assert!(batched > 0, "no impact was solved in a batch");
}

#[test]
fn far_apart_cradles_give_the_same_bits_in_batches_and_their_closed_form() {
    let scene = cradles(6);
    let steps = 12;
    let (batched, _) = same_bits(&scene, steps);
    assert!(batched > 0, "no impact was solved in a batch");
    // each cradle: momentum 1 kg·m/s along x and energy 0.5 J kept (e = 1,
    // no gravity, no friction)
    let mut sw = build(&scene, ImpactResponse::Topple).unwrap();
    for _ in 0..steps {
        sw.step();
    }
    for c in 0..6 {
        let balls = &sw.bodies[5 * c..5 * c + 5];
        let v: Vec<_> = balls
            .iter()
            .map(|b| sw.world.bodies[b.1].linvel())
            .collect();
        let p: f64 = v.iter().map(|v| v.x).sum();
        let py: f64 = v.iter().map(|v| v.y).sum();
        let ke: f64 = v.iter().map(|v| 0.5 * v.length_squared()).sum();
        assert!(
            (p - 1.0).abs() < 1e-9 && py.abs() < 1e-9,
            "cradle {c}: p {p} {py}"
        );
        assert!((ke - 0.5).abs() < 1e-5, "cradle {c}: energy {ke}");
    }
}

/// Each row inside the shared world falls as the same row alone in its own
/// world (no budget, so that the rows do not share one): every block
/// tips (turns past 0.05 rad) at the same step, give or take one. Not the
/// same bits: the world's Rapier steps are chosen for all its bodies
/// together (sub-steps while any managed body moves in contact, splits at
/// the earliest predicted closing, the solver's iterations), so the
/// shared world takes other steps than a row alone.
#[test]
fn each_row_in_the_shared_world_falls_as_alone() {
    let steps = 60;
    let shared = rows(4, WorkBudget::Unbounded);
    let (together, batched, _) = run(&shared, true, steps);
    assert!(batched > 0, "no impact was solved in a batch");
    for r in 0..4 {
        let mut alone = rows(r + 1, WorkBudget::Unbounded);
        alone.bodies.drain(..10 * r);
        let (own, _, _) = run(&alone, true, steps);
        let a = tip_steps(&together, 10 * r..10 * r + 10);
        let b = tip_steps(&own, 0..10);
        assert!(a.iter().all(Option::is_some), "row {r} did not fall: {a:?}");
        for (i, (x, y)) in a.iter().zip(&b).enumerate() {
            let (x, y) = (x.unwrap(), y.expect("the row alone fell"));
            assert!(x.abs_diff(y) <= 1, "row {r}, block {i}: step {x} vs {y}");
        }
    }
}

/// The first step at which each of the bodies `range` has turned past
/// 0.05 rad.
fn tip_steps(trace: &Trace, range: std::ops::Range<usize>) -> Vec<Option<usize>> {
    range
        .map(|i| {
            trace
                .iter()
                .position(|(bodies, _)| f64::from_bits(bodies[i][2]).abs() > 0.05)
        })
        .collect()
}

/// The audit and the capture of impacts record on the stepping thread: while
/// either is on, the pass solves every impact there, one instant at a time,
/// so that none is missed. The far-apart rows, audited and captured with
/// batches left on, record every impact the same run records with batches
/// switched off, and solve none side by side.
#[test]
fn audited_and_captured_runs_miss_no_impact() {
    let scene = rows(6, WorkBudget::default());
    let (_, in_batches, _) = run(&scene, true, 60);
    assert!(in_batches > 0, "the run must have batches to miss");
    let recorded = |batches: bool| {
        let mut sw = build(&scene, ImpactResponse::Topple).unwrap();
        sw.topple.set_impact_batches(batches);
        topple::impact::audit::start();
        topple::impact::capture::start();
        for _ in 0..60 {
            sw.step();
        }
        let captured = topple::impact::capture::finish().len();
        let audited = topple::impact::audit::finish().impacts;
        (captured, audited, sw.topple.stats().batched_impacts)
    };
    let (captured, audited, batched) = recorded(true);
    let (captured_alone, audited_alone, _) = recorded(false);
    assert_eq!(batched, 0);
    assert!(audited > 0 && captured > 0);
    assert_eq!((captured, audited), (captured_alone, audited_alone));
}
