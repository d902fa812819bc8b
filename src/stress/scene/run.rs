//! One scene through its engine, watched frame by frame: the drawn scenes
//! of the sweep (run twice, for their bits) and the soak (a scene that
//! resets itself, for hours of frames).

use std::time::Instant;

use super::draw::SceneCombo;
use crate::impact::audit::{self, AuditSummary};
use crate::rapier::scene::{ImpactResponse, Scene};
use crate::rapier::Precision;

/// What one scene run shows, measured from the bodies' states and the
/// adapter's impact reports, independently of the engine's own counters.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneObservation {
    /// A pose or velocity became NaN or infinite.
    pub non_finite: bool,
    /// Largest overlap of two bodies, or of a body and the ground or a
    /// wall, over the smaller body's least width.
    pub penetration: f64,
    /// Where and when the largest overlap was.
    pub penetration_at: String,
    /// Largest overlap beyond one step's closing, over the smaller body's
    /// least width: (depth − Δt (ŝ_a + ŝ_b)) / w, where ŝ is the fastest a
    /// body has moved so far (|v| + |ω| R, R its bounding radius) and a
    /// body against the ground or a wall counts alone. What the scene
    /// family checks ([`super::tolerance::PENETRATION`]).
    pub penetration_excess: f64,
    /// Where and when the largest excess was.
    pub penetration_excess_at: String,
    /// A body whose centre went below the ground's top face although one
    /// step's closing Δt ŝ could not take it there (ŝ Δt at most half its
    /// least width): "bN at t".
    pub through_ground: Option<String>,
    /// Bodies whose centre went below the ground when one step's closing
    /// could take it there (tunnelling without continuous collision
    /// detection; reported, not counted).
    pub tunnelled: usize,
    /// The same scene with native Rapier (a topple scene only): its largest
    /// overlap over the least width (`penetration`, without allowance: the
    /// allowance follows each run's own speeds) and whether the centre of a
    /// body went below the ground (also without allowance: counted or
    /// tunnelled).
    pub native: Option<(f64, bool)>,
    /// The same scene from nearby initial conditions, run only when this
    /// topple run is deeper than native's beyond the overlap tolerance
    /// ([`NearbyRuns`]); `None` otherwise.
    pub nearby: Option<NearbyRuns>,
    /// Largest impact work of one frame: Σ over the frame's impact attempts
    /// of impulse steps (accepted and rejected) × contact points, the unit
    /// of the adapter's budget (`FallbackPolicy::max_work`): the adapter's
    /// count, and at least the LZB steps the impact reports show.
    pub worst_frame_work: u64,
    /// Frames taken.
    pub frames: usize,
    /// Impacts topple resolved.
    pub impacts: usize,
    /// Impacts the fallback policy finished (held or plastic).
    pub fallbacks: usize,
    /// Hash of every body state of every frame (bits), first run.
    pub hash: u64,
    /// The same, second run; equal unless the run is not deterministic.
    pub repeat_hash: Option<u64>,
    /// A run did not end within its budget of CPU time.
    pub over_budget: bool,
    /// Wall-clock time of both runs (s), reported.
    pub wall: f64,
    /// CPU time of both runs (s), the thread that ran them.
    pub cpu: f64,
    /// Longest frame, wall clock (s); reported, not checked.
    pub worst_frame_seconds: f64,
    /// The impacts, checked independently ([`crate::impact::audit`]).
    pub audit: AuditSummary,
    /// The scene could not be built.
    pub error: Option<String>,
}

/// A scene run again from nearby initial conditions, by topple and by
/// native Rapier: every body's x velocity changed by `k` · [`NEARBY_STEP`]
/// metres per second (in the scene's units), k = 1 ..= [`NEARBY_RUNS`].
/// A stack or pyramid struck by bodies whose impacts decide where they land
/// is chaotic: one run of topple against one of native compares two draws
/// of motions that differ from the first impact on. The scene check then
/// counts a topple overlap only when it is deeper than native's from every
/// start tried: topple's shallowest depth against native's deepest
/// (docs/stress.md, "Chaotic scenes").
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NearbyRuns {
    /// topple's deepest overlap over the least width, one per nearby start.
    pub topple: Vec<f64>,
    /// Native Rapier's, one per nearby start (a start it cannot run is left
    /// out).
    pub native: Vec<f64>,
}

// How many nearby starts a chaotic-looking scene is run from: the same
// count as a row's, defined with the row's observations.
pub use crate::stress::observe::NEARBY_RUNS;

/// The velocity step between nearby starts (m/s, scaled by the scene's
/// units per metre): far below anything a game resolves, far above
/// round-off of the speeds (10⁻¹⁶ of 1 m/s in f64, 10⁻⁷ in f32: the f32
/// build then rounds it to a step of its own).
pub const NEARBY_STEP: f64 = 1e-6;

impl SceneObservation {
    /// topple's depth as the scene check reads it: the run's own, or the
    /// shallowest of it and its nearby runs when the scene was run again.
    pub fn topple_depth(&self) -> f64 {
        self.nearby.as_ref().map_or(self.penetration, |n| {
            n.topple.iter().fold(self.penetration, |a, &b| a.min(b))
        })
    }

    /// Native Rapier's depth as the scene check reads it: its run's, or the
    /// deepest of it and its nearby runs; `None` without a native run.
    pub fn native_depth(&self) -> Option<f64> {
        let (pen, _) = self.native?;
        Some(
            self.nearby
                .as_ref()
                .map_or(pen, |n| n.native.iter().fold(pen, |a, &b| a.max(b))),
        )
    }
}

/// FNV-1a over 64-bit words.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fnv(pub u64);

impl Fnv {
    pub(crate) fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    pub(crate) fn add(&mut self, x: f64) {
        for b in x.to_bits().to_le_bytes() {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
}

/// Runs `c` twice, the first time with every impact checked and every
/// frame watched; `budget` is the budget of CPU time of each run (s, the
/// thread that runs it: a loaded machine stretches the wall time, not this).
pub fn run_scene_combo(c: &SceneCombo, budget: f64) -> SceneObservation {
    let start = Instant::now();
    let cpu = crate::clock::CpuWatch::start();
    let run = |watch: bool| run_whole(&c.scene, c.rapier_engine(), c.precision, watch, budget);
    audit::start();
    let mut seen = run(true);
    seen.audit = audit::finish();
    if seen.error.is_none() && !seen.over_budget {
        let again = run(false);
        seen.over_budget |= again.over_budget;
        seen.repeat_hash = (!again.over_budget).then_some(again.hash);
    }
    seen.wall = start.elapsed().as_secs_f64();
    seen.cpu = cpu.seconds();
    if c.rapier_engine() != ImpactResponse::Native {
        // the baseline on the same scene (its wall time is not the run's)
        let native = run_whole(&c.scene, ImpactResponse::Native, c.precision, true, budget);
        // native's depth and its bodies below the ground without its
        // allowance: a centre below the ground counts whatever its speed
        // (topple's run gets the allowance, the baseline does not excuse its
        // own: both are native Rapier's behaviour on this scene)
        let below = native.through_ground.is_some() || native.tunnelled > 0;
        seen.native = (native.error.is_none()).then_some((native.penetration, below));
        let deeper = seen.native.is_some_and(|(pen, _)| seen.penetration > pen);
        if deeper && seen.penetration_excess > super::tolerance::PENETRATION && !seen.over_budget {
            seen.nearby = Some(nearby_runs(c, budget));
        }
    }
    seen
}

/// `c`'s scene from [`NEARBY_RUNS`] nearby starts, by its topple engine and
/// by native Rapier (overlaps watched, each run within `budget`).
fn nearby_runs(c: &SceneCombo, budget: f64) -> NearbyRuns {
    let mut out = NearbyRuns::default();
    for k in 1..=NEARBY_RUNS {
        let mut scene = c.scene.clone();
        let dv = k as f64 * NEARBY_STEP * c.unit;
        for b in &mut scene.bodies {
            b.velocity[0] += dv;
        }
        for (engine, depths) in [
            (c.rapier_engine(), &mut out.topple),
            (ImpactResponse::Native, &mut out.native),
        ] {
            let o = run_whole(&scene, engine, c.precision, true, budget);
            if o.error.is_none() && !o.over_budget {
                depths.push(o.penetration);
            }
        }
    }
    out
}

/// `scene` run for its whole duration with `engine` on `precision`'s build,
/// its overlaps watched every frame if `watch`, within `budget` (s of CPU
/// time of the thread that runs it).
fn run_whole(
    scene: &Scene,
    engine: ImpactResponse,
    precision: Precision,
    watch: bool,
    budget: f64,
) -> SceneObservation {
    let mut hooks = Hooks {
        watch,
        budget,
        frames: (scene.duration / scene.solver.dt).round() as usize,
        ..Hooks::default()
    };
    match precision {
        Precision::F64 => on_f64::run(scene, engine, &mut hooks),
        Precision::F32 => on_f32::run(scene, engine, &mut hooks),
    }
}

/// What a run does besides stepping: how many frames, whether it watches
/// overlaps, and (for the soak) when it puts the scene back.
#[derive(Default)]
pub(crate) struct Hooks<'a> {
    /// Measure overlaps every frame (else only the hash and the state).
    pub watch: bool,
    /// Budget of the run (s of CPU time of the thread that runs it).
    pub budget: f64,
    /// Frames to take.
    pub frames: usize,
    /// Called after every frame with the frame's index and the kinetic
    /// energy of the scene (J); returns true to put every body back where
    /// and as fast as the scene starts it.
    pub reset: Option<&'a mut dyn FnMut(usize, f64) -> bool>,
}

/// One watcher per Rapier build: the scene built by the adapter, stepped
/// frame by frame, every body checked.
macro_rules! watcher_for {
    ($m:ident, $adapter:ident, $backend:ident) => {
        pub(crate) mod $m {
            use std::time::Instant;

            use super::{Fnv, Hooks, SceneObservation};
            use crate::rapier::scene::{ImpactResponse, Scene};
            use crate::rapier::$adapter::{build, signed_gap, SceneWorld};
            use crate::$backend::parry::bounding_volume::BoundingVolume;
            use crate::$backend::prelude::{ColliderHandle, RigidBodyHandle};

            /// The least width of a collider: its local box's smaller side
            /// (a box's thickness, a ball's diameter).
            fn least_width(sw: &SceneWorld, c: ColliderHandle) -> f64 {
                let aabb = sw.world.colliders[c].shape().compute_local_aabb();
                let e = aabb.extents();
                f64::from(e.x.min(e.y))
            }

            /// A bound on the distance of a collider's points from its
            /// centre: its local box's half diagonal.
            fn bounding_radius(sw: &SceneWorld, c: ColliderHandle) -> f64 {
                let aabb = sw.world.colliders[c].shape().compute_local_aabb();
                let e = aabb.extents();
                0.5 * f64::from(e.x).hypot(f64::from(e.y))
            }

            /// Runs `scene` with `engine` as `hooks` say.
            pub(crate) fn run(
                scene: &Scene,
                engine: ImpactResponse,
                hooks: &mut Hooks,
            ) -> SceneObservation {
                let mut seen = SceneObservation::default();
                let mut sw = match build(scene, engine) {
                    Ok(sw) => sw,
                    Err(e) => {
                        seen.error = Some(e.to_string());
                        return seen;
                    }
                };
                let handles: Vec<(RigidBodyHandle, ColliderHandle)> =
                    sw.bodies.iter().map(|b| (b.1, b.2)).collect();
                let sizes: Vec<f64> = handles.iter().map(|h| least_width(&sw, h.1)).collect();
                let radii: Vec<f64> =
                    handles.iter().map(|h| bounding_radius(&sw, h.1)).collect();
                // the fastest each body has moved (|v| + |ω| R), from its start
                let mut fastest = vec![0.0f64; handles.len()];
                let dt = scene.solver.dt;
                let ground_y = scene.ground.as_ref().map_or(f64::NEG_INFINITY, |g| g.y);
                // the ground's collider: the one no scene body owns
                let ground = sw
                    .world
                    .colliders
                    .iter()
                    .map(|(h, _)| h)
                    .find(|h| handles.iter().all(|b| b.1 != *h));
                // the start of every body, to put the scene back
                let initial: Vec<_> = handles
                    .iter()
                    .map(|(h, _)| {
                        let rb = &sw.world.bodies[*h];
                        (*rb.position(), rb.linvel(), rb.angvel())
                    })
                    .collect();
                let cpu = crate::clock::CpuWatch::start();
                let mut hash = Fnv::new();
                for frame in 0..hooks.frames {
                    let t0 = Instant::now();
                    let counted = sw.topple.stats().work;
                    let (work, impacts, fallbacks) = {
                        let reports = sw.step();
                        // a bound from below, from the reports alone: the
                        // impulse steps of the attempt each LZB or held
                        // impact ended with (a plastic one reports sweeps)
                        let work: u64 = reports
                            .iter()
                            .filter(|r| {
                                matches!(
                                    r.resolution,
                                    crate::coupling::Resolution::Lzb
                                        | crate::coupling::Resolution::Held
                                )
                            })
                            .map(|r| r.steps as u64 * r.contacts as u64)
                            .sum();
                        let fallbacks = reports
                            .iter()
                            .filter(|r| r.resolution != crate::coupling::Resolution::Lzb)
                            .count();
                        (work, reports.len(), fallbacks)
                    };
                    seen.worst_frame_seconds =
                        seen.worst_frame_seconds.max(t0.elapsed().as_secs_f64());
                    seen.frames = frame + 1;
                    // the adapter's count of every attempt's steps
                    // (accepted and rejected) × contacts, the budget's unit
                    let work = work.max(sw.topple.stats().work - counted);
                    seen.worst_frame_work = seen.worst_frame_work.max(work);
                    seen.impacts += impacts;
                    seen.fallbacks += fallbacks;
                    let time = sw.time;
                    for (k, (h, _)) in handles.iter().enumerate() {
                        let rb = &sw.world.bodies[*h];
                        let p = rb.position();
                        let state = [
                            f64::from(p.translation.x),
                            f64::from(p.translation.y),
                            f64::from(p.rotation.angle()),
                            f64::from(rb.linvel().x),
                            f64::from(rb.linvel().y),
                            f64::from(rb.angvel()),
                        ];
                        if state.iter().any(|v| !v.is_finite()) {
                            seen.non_finite = true;
                        }
                        for v in state {
                            hash.add(v);
                        }
                        let speed = state[3].hypot(state[4]) + state[5].abs() * radii[k];
                        if frame == 0 {
                            let (v, w) = (initial[k].1, initial[k].2);
                            let start = f64::from(v.x).hypot(f64::from(v.y))
                                + f64::from(w).abs() * radii[k];
                            fastest[k] = fastest[k].max(start);
                        }
                        fastest[k] = fastest[k].max(speed);
                        if hooks.watch && state[1] < ground_y {
                            if dt * fastest[k] > 0.5 * sizes[k] {
                                seen.tunnelled += 1;
                            } else if seen.through_ground.is_none() {
                                seen.through_ground =
                                    Some(format!("b{} at t = {time:.3} s", k + 1));
                            }
                        }
                    }
                    if seen.non_finite {
                        break;
                    }
                    if hooks.watch {
                        let bodies = Bodies {
                            handles: &handles,
                            sizes: &sizes,
                            closing: &fastest,
                            dt,
                        };
                        overlaps(&sw, &bodies, ground, time, &mut seen);
                    }
                    if cpu.seconds() > hooks.budget {
                        seen.over_budget = true;
                        break;
                    }
                    if let Some(reset) = hooks.reset.as_mut() {
                        if reset(frame, sw.kinetic_energy()) {
                            for ((h, _), (pose, v, w)) in handles.iter().zip(&initial) {
                                let rb = &mut sw.world.bodies[*h];
                                rb.set_position(*pose, true);
                                rb.set_linvel(*v, true);
                                rb.set_angvel(*w, true);
                            }
                        }
                    }
                }
                seen.hash = hash.0;
                seen
            }

            /// The scene's bodies as the overlap check needs them.
            struct Bodies<'a> {
                handles: &'a [(RigidBodyHandle, ColliderHandle)],
                /// Least widths.
                sizes: &'a [f64],
                /// The fastest each body has moved so far (|v| + |ω| R).
                closing: &'a [f64],
                /// Time step (s).
                dt: f64,
            }

            /// Every pair of bodies whose boxes meet, and every body against
            /// the ground: the deepest overlap over the smaller least width,
            /// and the deepest beyond one step's closing.
            fn overlaps(
                sw: &SceneWorld,
                b: &Bodies,
                ground: Option<ColliderHandle>,
                time: f64,
                seen: &mut SceneObservation,
            ) {
                let (handles, sizes) = (b.handles, b.sizes);
                let w = &sw.world;
                let aabbs: Vec<_> = handles
                    .iter()
                    .map(|(_, col)| w.colliders[*col].compute_aabb())
                    .collect();
                let mut note = |depth: f64, size: f64, closing: f64, what: String| {
                    let d = depth / size;
                    if d > seen.penetration {
                        seen.penetration = d;
                        seen.penetration_at = format!("{what} at t = {time:.3} s");
                    }
                    let excess = (depth - b.dt * closing) / size;
                    if excess > seen.penetration_excess {
                        seen.penetration_excess = excess;
                        seen.penetration_excess_at = format!(
                            "{what} at t = {time:.3} s, {d:.3} deep, one step's closing {:.3}",
                            b.dt * closing / size
                        );
                    }
                };
                for i in 0..handles.len() {
                    for j in i + 1..handles.len() {
                        if !aabbs[i].intersects(&aabbs[j]) {
                            continue;
                        }
                        let gap = signed_gap(&w.bodies, &w.colliders, handles[i].1, handles[j].1);
                        if gap < 0.0 {
                            note(
                                -gap,
                                sizes[i].min(sizes[j]),
                                b.closing[i] + b.closing[j],
                                format!("b{}/b{}", i + 1, j + 1),
                            );
                        }
                    }
                    if let Some(gr) = ground {
                        let gap = signed_gap(&w.bodies, &w.colliders, gr, handles[i].1);
                        if gap < 0.0 {
                            note(-gap, sizes[i], b.closing[i], format!("b{}/ground", i + 1));
                        }
                    }
                }
            }
        }
    };
}

watcher_for!(on_f64, f64, rapier2d_f64);
watcher_for!(on_f32, f32, rapier2d);

/// Runs `scene` with `engine` on `precision`'s build as `hooks` say, every
/// impact checked.
pub(crate) fn run_with(
    scene: &Scene,
    engine: ImpactResponse,
    precision: Precision,
    hooks: &mut Hooks,
) -> SceneObservation {
    audit::start();
    let mut seen = match precision {
        Precision::F64 => on_f64::run(scene, engine, hooks),
        Precision::F32 => on_f32::run(scene, engine, hooks),
    };
    seen.audit = audit::finish();
    seen
}
