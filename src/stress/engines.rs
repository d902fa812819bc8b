//! One combination through its engine, observed step by step.

use std::time::Instant;

use super::combo::{Combo, SplitMix64, StressEngine};
use super::observe::{NativeRockBack, Observation, RowWatch, NEARBY_RUNS, ROW_NEARBY_PUSH};
use crate::clock::CpuWatch;
use crate::coupling::{FallbackPolicy, GroupSolver};
use crate::impact::{audit, Body, Contact, ContactMaterial, ImpactOutcome, ImpactSettings};
use crate::rapier::scene::{row_scene, ImpactResponse, SolverSpec};
use crate::reference::{Integrator, Settings};

/// Simulated time (s) a row gets: 4 t̄ per block and 2 s, far beyond the
/// slowest wave the sweep draws (about 1.2 t̄ per block at push 0.5).
fn sim_time(c: &Combo) -> f64 {
    2.0 + 4.0 * c.row.n as f64 * c.row.params.time_scale()
}

/// Runs `c` with every impact checked; `budget` is the budget of CPU time
/// (s) of the thread that runs it (a loaded machine stretches the wall
/// time, not this).
pub fn run_combo(c: &Combo, budget: f64) -> Observation {
    audit::start();
    let start = Instant::now();
    let cpu = CpuWatch::start();
    let mut seen = match c.engine {
        StressEngine::Reference => reference(c, budget),
        StressEngine::RapierF64 => rapier_f64(c, ImpactResponse::Topple, budget),
        StressEngine::RapierF32 => rapier_f32(c, ImpactResponse::Topple, budget),
        StressEngine::Native => rapier_f64(c, ImpactResponse::Native, budget),
        StressEngine::Impact => free_impact(c),
    };
    seen.wall = start.elapsed().as_secs_f64();
    seen.cpu = cpu.seconds();
    seen.over_budget |= seen.cpu > budget;
    seen.audit = audit::finish();
    // A block can stand back up past the fallen tilt by physics: one that
    // first meets its neighbour near π/4 (s/h near 0.6) rebounds off it, a
    // leaning train at small spacing rocks about its rest angle near π/4.
    // The same row in the reference engine decides (after the audit: its
    // impacts are not this run's): a drop it shows too, or a rock-back
    // across π/4 no larger than one of its own fallen blocks makes, is
    // physics (the Rapier rows are perturbed, the reference's is not; near
    // π/4 that decides which side of it a rebound ends). It runs up to the
    // last hit, so a drop after it stays counted.
    if seen.fallen_drop > 0 && c.engine != StressEngine::Reference {
        let oracle = reference(c, budget);
        let ran = oracle.error.is_none() && !oracle.over_budget;
        seen.reference_fallen_drop = ran.then_some(oracle.fallen_drop);
        seen.reference_rock_back = ran.then_some(oracle.fallen_rock_back);
        // The reference runs up to the last hit only. A drop it does not
        // explain is held against native Rapier of the same build on the
        // same row, perturbation and step: Rapier's own contacts at that
        // step (a train settling back once the last block slides out from
        // under it) are the baseline, as for penetrations. Whether a block
        // that rocks back ends on one side of π/4 or the other turns on
        // fine details, so both engines run from nearby starts too, and the
        // measure is how far a fallen block rocks back (as against the
        // reference above), not whether it crosses π/4.
        if !explained_by_reference(&seen) {
            seen.native_rock_back = native_rock_back(c, &seen, budget);
        }
    }
    seen
}

/// [`NativeRockBack`] of `c` (a Rapier engine of topple's) whose run
/// `seen` stood blocks up: `c` from [`NEARBY_RUNS`] nearby starts in its
/// engine, and `c` and its nearby starts in native Rapier of its build.
/// `None` for other engines, or if a native run failed or ran over budget.
fn native_rock_back(c: &Combo, seen: &Observation, budget: f64) -> Option<NativeRockBack> {
    let run = |c: &Combo, response| match c.engine {
        StressEngine::RapierF64 => Some(rapier_f64(c, response, budget)),
        StressEngine::RapierF32 => Some(rapier_f32(c, response, budget)),
        _ => None,
    };
    let mut r = NativeRockBack {
        topple_least: seen.stood_up_rock_back,
        ..NativeRockBack::default()
    };
    for k in 0..=NEARBY_RUNS {
        let mut near = c.clone();
        near.row.push = c.row.push + k as f64 * ROW_NEARBY_PUSH;
        if k > 0 {
            // a nearby run of topple's that failed or ran over its budget
            // says nothing of its rock-back: it cannot excuse the drop
            let t = run(&near, ImpactResponse::Topple)?;
            if t.error.is_none() && !t.over_budget {
                r.topple_least = r.topple_least.min(t.stood_up_rock_back);
            }
        }
        let n =
            run(&near, ImpactResponse::Native).filter(|n| n.error.is_none() && !n.over_budget)?;
        r.native_most = r.native_most.max(n.fallen_rock_back);
        r.native_drop = r.native_drop.max(n.fallen_drop);
    }
    Some(r)
}

/// Whether the reference engine on the same row shows the drop too, or a
/// rock-back across π/4 at least as large ([`run_combo`]).
pub(crate) fn explained_by_reference(o: &Observation) -> bool {
    o.reference_fallen_drop.is_some_and(|d| d > 0)
        || o.reference_rock_back
            .is_some_and(|r| o.stood_up_rock_back <= r)
}

/// Whether native Rapier, at the same step and from the same nearby
/// starts, rocks a fallen block back at least as far as topple stands one
/// up from the start where it does so least ([`run_combo`]): the drop is
/// then the size of Rapier's own rock-back at that step, not topple's.
pub(crate) fn explained_by_native(o: &Observation) -> bool {
    o.native_rock_back
        .is_some_and(|r| r.topple_least <= r.native_most)
}

/// The reference engine with heel contacts (no overlap where blocks slide
/// back, `Settings::heel_contacts`), observed through snapshots every 2 ms,
/// up to the last block's hit: the wave it is run for. (Its contacts are
/// every corner of a block against every face of any block it reaches and
/// of the ground, `docs/stress.md`.)
fn reference(c: &Combo, budget: f64) -> Observation {
    let settings = reference_settings(c, budget);
    let b = c.row.params.block;
    let mut watch = RowWatch::new(b.height, b.thickness);
    match crate::reference::run(&c.row, &settings) {
        Ok(out) => {
            for s in &out.snapshots {
                // the reference's y is the centre height; φ counter-clockwise
                watch.look(s.time, &s.blocks);
            }
            let r = &out.report;
            watch.seen.hits = r.hit_times.len();
            watch.seen.over_budget = r.stopped_early;
            let energy_finite = r.energy.is_none_or(|e| {
                [e.initial, e.kinetic, e.potential, e.impacts, e.friction]
                    .iter()
                    .all(|v| v.is_finite())
            });
            if !energy_finite || r.hit_times.iter().any(|t| !t.is_finite()) {
                watch.seen.non_finite = true;
            }
        }
        Err(e) => watch.seen.error = Some(e.to_string()),
    }
    watch.seen
}

/// The sweep's reference settings for `c`: the paper's integrator at the
/// combination's step, heel contacts, up to the last hit, snapshots every
/// 2 ms, `budget` s of CPU time.
fn reference_settings(c: &Combo, budget: f64) -> Settings {
    let t_end = sim_time(c);
    Settings {
        integrator: Integrator::Paper { dt: c.dt },
        heel_contacts: true,
        stop_at_last_hit: true,
        cpu_time_limit: Some(budget),
        t_max: Some(t_end),
        snapshot_times: (1..)
            .map(|k| k as f64 * 2e-3)
            .take_while(|t| *t < t_end)
            .collect(),
        ..Settings::default()
    }
}

macro_rules! rapier_runner {
    ($name:ident, $adapter:ident, $backend:ident) => {
        /// A Rapier build of the row, its blocks perturbed, observed after
        /// every step.
        fn $name(c: &Combo, engine: ImpactResponse, budget: f64) -> Observation {
            use crate::rapier::$adapter as adapter;
            use crate::$backend::math::{Pose, Real, Vector};
            let t_end = sim_time(c);
            let solver = SolverSpec {
                dt: c.dt,
                ..SolverSpec::default()
            };
            let scene = row_scene(&c.row, solver, t_end);
            let b = c.row.params.block;
            let mut watch = RowWatch::new(b.height, b.thickness);
            let mut sw = match adapter::build(&scene, engine) {
                Ok(sw) => sw,
                Err(e) => {
                    watch.seen.error = Some(format!("{e:#}"));
                    return watch.seen;
                }
            };
            let Some(row) = sw.row.clone() else {
                watch.seen.error = Some("the scene has no row".into());
                return watch.seen;
            };
            let handles: Vec<_> = row
                .colliders
                .iter()
                .filter_map(|c| sw.world.colliders[*c].parent())
                .collect();
            // perturb blocks 2..n: shift in x, tilt forward about the front
            // bottom edge (the back corner lifts: no overlap with the ground)
            for (k, h) in handles.iter().enumerate().skip(1) {
                let (dx, tilt) = c.perturbation[k];
                let rb = &mut sw.world.bodies[*h];
                let p = rb.position();
                let (x, y) = (f64::from(p.translation.x), f64::from(p.translation.y));
                let pivot = [x + 0.5 * b.thickness, y - 0.5 * b.height];
                let r = [x - pivot[0], y - pivot[1]];
                let (s, co) = (-tilt).sin_cos();
                let centre = [
                    pivot[0] + co * r[0] - s * r[1] + dx,
                    pivot[1] + s * r[0] + co * r[1],
                ];
                let pose = Pose::new(
                    Vector::new(centre[0] as Real, centre[1] as Real),
                    (-tilt) as Real,
                );
                rb.set_position(pose, true);
            }
            let cpu = CpuWatch::start();
            let dt = f64::from(sw.world.integration_parameters.dt);
            let mut hits = adapter::HitTracker::new();
            let mut blocks = vec![[0.0; 3]; handles.len()];
            while sw.time < t_end {
                sw.step();
                hits.update(&sw, sw.time, dt);
                for (k, h) in handles.iter().enumerate() {
                    let p = sw.world.bodies[*h].position();
                    blocks[k] = [
                        f64::from(p.translation.x),
                        f64::from(p.translation.y),
                        f64::from(p.rotation.angle()),
                    ];
                }
                watch.look(sw.time, &blocks);
                if watch.seen.non_finite {
                    break;
                }
                if cpu.seconds() > budget {
                    watch.seen.over_budget = true;
                    break;
                }
                let quiet = sw.time - hits.hit_times.last().copied().unwrap_or(0.0) > 2.0;
                if hits.hit_times.len() >= c.row.n && quiet {
                    break;
                }
                if quiet && sw.kinetic_energy() < 1e-12 {
                    break;
                }
            }
            watch.seen.hits = hits.hit_times.len();
            watch.seen
        }
    };
}

rapier_runner!(rapier_f64, f64, rapier2d_f64);
rapier_runner!(rapier_f32, f32, rapier2d);

/// A free-body impact: a chain of 2 to 6 balls or boxes in a line, touching,
/// struck at one end, every contact elastic (e = 1) and frictionless in half
/// the draws; through the resolver with the engines' fallback policy.
fn free_impact(c: &Combo) -> Observation {
    let mut g = SplitMix64::new(c.impact_seed);
    let n = 2 + (g.next_u64() % 5) as usize;
    let elastic = g.unit() < 0.5;
    let mut bodies = Vec::with_capacity(n);
    let mut contacts = Vec::with_capacity(n);
    let mut x = 0.0;
    let dir = g.range(0.0, std::f64::consts::TAU);
    let axis = [dir.cos(), dir.sin()];
    for k in 0..n {
        let r = g.range(0.02, 0.1);
        let m = g.range(0.1, 10.0);
        let i = 0.4 * m * r * r * g.range(0.5, 2.0);
        if k > 0 {
            x += r;
        }
        let mut b = Body::new(m, i).with_position([x * axis[0], x * axis[1]]);
        if k == 0 {
            let speed = 10f64.powf(g.range(-3.0, 2.0));
            b = b.with_velocity([
                speed * (axis[0] + g.range(-0.2, 0.2)),
                speed * (axis[1] + g.range(-0.2, 0.2)),
            ]);
            b.angular_velocity = g.range(-1.0, 1.0) * speed / r;
        }
        bodies.push(b);
        if k + 1 < n {
            let mut mat = ContactMaterial::hertz(10f64.powf(g.range(6.0, 11.0)));
            if !elastic {
                mat = mat.with_restitution(g.pick(&[0.0, 0.5, 0.9]));
                mat.friction = g.range(0.0, 0.6);
                mat.stick_friction = mat.friction * g.range(1.0, 1.2);
            }
            let p = x + r;
            contacts.push(Contact::new(
                [Some(k), Some(k + 1)],
                [p * axis[0], p * axis[1]],
                axis,
                mat,
            ));
            x = p;
        }
    }
    let mut out = ImpactOutcome::default();
    let mut seen = Observation::default();
    let r = GroupSolver::default().solve_into(
        &bodies,
        &contacts,
        &ImpactSettings::default(),
        &FallbackPolicy::default(),
        &mut out,
    );
    if let Err(e) = r {
        seen.error = Some(e.to_string());
    }
    seen
}
