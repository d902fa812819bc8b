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
    /// Largest overlap beyond the soft contact's sag ([`SoftSag`]), over the
    /// smaller body's least width: (depth − S) / w, no allowance for speed.
    /// The measure topple's run and native Rapier's are compared by (both
    /// runs have the same bodies, so the same S).
    pub beyond_sag: f64,
    /// Where and when the largest overlap was.
    pub penetration_at: String,
    /// Largest overlap beyond one step's closing and the soft contact's sag,
    /// over the smaller body's least width: (depth − Δt (ŝ_a + ŝ_b) − S) / w,
    /// where ŝ is the fastest a body has moved so far (|v| + |ω| R, R its
    /// bounding radius), a body against the ground or a wall counts alone,
    /// and S is the depth at which Rapier's soft contact holds the heaviest
    /// load the pair can carry ([`SoftSag`]). What the scene family checks
    /// ([`super::tolerance::PENETRATION`]).
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
    /// overlap beyond the soft contact's sag over the least width
    /// (`beyond_sag`, without the allowance for speed: that follows each
    /// run's own speeds) and whether the centre of a
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
/// start tried: topple's shallowest depth against native's deepest, native's
/// including its runs as topple configures and steps it (docs/stress.md,
/// "Chaotic scenes" and "The scene family's baseline stepped as topple
/// steps it").
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NearbyRuns {
    /// topple's deepest overlap beyond the soft contact's sag over the least
    /// width (`beyond_sag`), one per nearby start.
    pub topple: Vec<f64>,
    /// Native Rapier's, one per nearby start (a start it cannot run is left
    /// out).
    pub native: Vec<f64>,
    /// Native Rapier configured and stepped as topple configures and steps
    /// it, without topple's impacts ([`native_as_topple`]), from the drawn
    /// start and every nearby one: one depth per run, as `native`.
    pub native_as_topple: Vec<f64>,
}

/// The scene as native Rapier runs it under topple, without topple's
/// impacts: what topple changes in Rapier besides its impacts, each
/// combination as one native scene. Restitution 0 on every material and
/// pair (topple leaves every contact it does not resolve to Rapier at
/// e = 0, docs/model.md §9: a topple run with no impacts is native Rapier
/// at e = 0, `tests/rapier/stress_checks.rs`,
/// `the_pair_hook_alone_is_native_rapier_with_restitution_zero`), and each
/// frame of Δt taken in topple's k pieces (k = ⌈Δt / max_substep⌉, the
/// adapter's sub-steps), solved in Rapier's N substeps per piece (the
/// bodies topple raises, which turn) or in max(1, round(N / k)) (the
/// others: Rapier's substep kept at the frame's). Rapier's soft-contact
/// depth on a settling stack moves with the step by up to half
/// (docs/stress.md, "The scene family's baseline stepped as topple steps
/// it"), so native Rapier at the frame's step alone is not the depth
/// Rapier gives topple's pieces.
pub fn native_as_topple(scene: &Scene) -> Vec<Scene> {
    let mut resting = scene.clone();
    for m in &mut resting.materials {
        m.restitution = 0.0;
    }
    for p in &mut resting.pairs {
        p.law.restitution = 0.0;
    }
    let dt = scene.solver.dt;
    let length_unit = scene.solver.length_unit.unwrap_or(1.0);
    let pieces = crate::rapier::scene::topple_settings(&scene.solver, length_unit).substeps(dt);
    let mut out = vec![resting.clone()];
    if pieces > 1 {
        let n = scene.solver.iterations;
        let kept = ((n as f64 / pieces as f64).round() as usize).max(1);
        for base in [scene, &resting] {
            for iterations in [n, kept] {
                let mut s = base.clone();
                s.solver.dt = dt / pieces as f64;
                s.solver.iterations = iterations;
                out.push(s);
            }
        }
    }
    out
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
        self.nearby.as_ref().map_or(self.beyond_sag, |n| {
            n.topple.iter().fold(self.beyond_sag, |a, &b| a.min(b))
        })
    }

    /// Native Rapier's depth as the scene check reads it: its run's, or the
    /// deepest of it, its nearby runs and its runs as topple configures and
    /// steps it; `None` without a native run.
    pub fn native_depth(&self) -> Option<f64> {
        let (pen, _) = self.native?;
        Some(self.nearby.as_ref().map_or(pen, |n| {
            n.native
                .iter()
                .chain(&n.native_as_topple)
                .fold(pen, |a, &b| a.max(b))
        }))
    }
}

/// The depth at which Rapier's soft contact holds a load: a contact of
/// projected mass m carrying a force F settles at F / (m ω²) whatever the
/// step length (ω = 2π f, f the contact's natural frequency; derived in
/// docs/stress.md, "Rapier's soft contact at a shorter step", and measured
/// against native Rapier in `tests/rapier/soft_contact.rs`). Between a lower
/// body l and an upper body u the load is at most the weight of every
/// dynamic body of the scene but l (l carries the rest; a fixed body
/// carries everything), and 1/m ≤ 1/m_l + 1/m_u (the translational part of
/// the projected mass). So
///
///   S = g (M − m_l) (1/m_l + 1/m_u) / ω²,
///
/// with a fixed body's 1/m = 0 and its share of M none, and ω the
/// contact's own (Rapier's `static_contact_softness` when one side is
/// fixed, `contact_softness` otherwise). Units: the scene's length unit (g
/// in units/s², S in units). It is the closed form of one contact under
/// the heaviest load it could carry. Balls follow it; boxes (two points a
/// contact) sink up to 14 % more under light loads and far less under heavy
/// ones (0.66 and 0.37 of it in the test), so it is an allowance from above
/// (`tests/rapier/stress_checks.rs`,
/// `the_soft_contacts_allowance_bounds_native_rapiers_depth_from_above`).
///
/// ```
/// use std::f64::consts::PI;
/// use topple::stress::scene::SoftSag;
/// // 1 kg on 3 kg on the ground, g = 9.81 m/s², 30 Hz between the bodies
/// let (w30, w60) = (2.0 * PI * 30.0, 2.0 * PI * 60.0);
/// let s = SoftSag::new(9.81, w30, w60, vec![Some(3.0), Some(1.0)]);
/// // the upper box's weight on the pair: 1 kg × g (1/3 + 1/1) / ω²
/// assert!((s.pair(0, 1) - 9.81 * (4.0 / 3.0) / (w30 * w30)).abs() < 1e-15);
/// // both boxes' weight on the ground, through the lower box
/// assert!((s.ground(0) - 9.81 * 4.0 / 3.0 / (w60 * w60)).abs() < 1e-15);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SoftSag {
    /// |g| (units/s²).
    g: f64,
    /// ω between two dynamic bodies (rad/s).
    omega: f64,
    /// ω against a fixed body (rad/s).
    omega_fixed: f64,
    /// Each body's mass (kg), `None` when it is fixed.
    masses: Vec<Option<f64>>,
    /// Σ of the dynamic masses (kg).
    total: f64,
}

impl SoftSag {
    /// The sag of a scene with gravity `g` (units/s²), contact angular
    /// frequencies `omega` (rad/s, two dynamic bodies) and `omega_fixed`
    /// (one side fixed), and its bodies' `masses` (`None`: fixed).
    pub fn new(g: f64, omega: f64, omega_fixed: f64, masses: Vec<Option<f64>>) -> Self {
        let total = masses.iter().flatten().sum();
        SoftSag {
            g,
            omega,
            omega_fixed,
            masses,
            total,
        }
    }

    /// Body `i`'s inverse mass and share of the load (a fixed body: 0, 0).
    fn body(&self, i: usize) -> (f64, f64) {
        self.masses[i].map_or((0.0, 0.0), |m| (1.0 / m, m))
    }

    /// S between body `lower` and body `upper` resting on it (units).
    pub fn pair(&self, lower: usize, upper: usize) -> f64 {
        let ((inv_l, m_l), (inv_u, _)) = (self.body(lower), self.body(upper));
        let fixed = self.masses[lower].is_none() || self.masses[upper].is_none();
        let omega = if fixed { self.omega_fixed } else { self.omega };
        self.g * (self.total - m_l) * (inv_l + inv_u) / (omega * omega)
    }

    /// S between body `i` and the fixed ground (units).
    pub fn ground(&self, i: usize) -> f64 {
        let (inv_i, _) = self.body(i);
        self.g * self.total * inv_i / (self.omega_fixed * self.omega_fixed)
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
        seen.native = (native.error.is_none()).then_some((native.beyond_sag, below));
        let deeper = seen.native.is_some_and(|(pen, _)| seen.beyond_sag > pen);
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
    let depth = |scene: &Scene, engine| {
        let o = run_whole(scene, engine, c.precision, true, budget);
        (o.error.is_none() && !o.over_budget).then_some(o.beyond_sag)
    };
    for k in 0..=NEARBY_RUNS {
        let mut scene = c.scene.clone();
        let dv = k as f64 * NEARBY_STEP * c.unit;
        for b in &mut scene.bodies {
            b.velocity[0] += dv;
        }
        if k > 0 {
            out.topple.extend(depth(&scene, c.rapier_engine()));
            out.native.extend(depth(&scene, ImpactResponse::Native));
        }
        for s in native_as_topple(&scene) {
            out.native_as_topple
                .extend(depth(&s, ImpactResponse::Native));
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
                let sag = {
                    let p = &sw.world.integration_parameters;
                    let omega = |f: f64| 2.0 * std::f64::consts::PI * f;
                    let masses = handles
                        .iter()
                        .map(|(h, _)| {
                            let rb = &sw.world.bodies[*h];
                            rb.is_dynamic().then(|| f64::from(rb.mass()))
                        })
                        .collect();
                    super::SoftSag::new(
                        f64::from(sw.world.gravity.length()),
                        omega(f64::from(p.contact_softness.natural_frequency)),
                        omega(f64::from(p.static_contact_softness.natural_frequency)),
                        masses,
                    )
                };
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
                            sag: &sag,
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
                /// The depth Rapier's soft contact holds each pair's load at.
                sag: &'a super::SoftSag,
                /// Time step (s).
                dt: f64,
            }

            /// Every pair of bodies whose boxes meet, and every body against
            /// the ground: the deepest overlap over the smaller least width,
            /// and the deepest beyond one step's closing and the soft
            /// contact's sag.
            fn overlaps(
                sw: &SceneWorld,
                b: &Bodies,
                ground: Option<ColliderHandle>,
                time: f64,
                seen: &mut SceneObservation,
            ) {
                let (handles, sizes) = (b.handles, b.sizes);
                let w = &sw.world;
                // each centre's height against gravity
                let up = -w.gravity.normalize_or_zero();
                let heights: Vec<f64> = handles
                    .iter()
                    .map(|(h, _)| f64::from(w.bodies[*h].translation().dot(up)))
                    .collect();
                let aabbs: Vec<_> = handles
                    .iter()
                    .map(|(_, col)| w.colliders[*col].compute_aabb())
                    .collect();
                let mut note = |depth: f64, size: f64, closing: f64, sag: f64, what: String| {
                    let d = depth / size;
                    if d > seen.penetration {
                        seen.penetration = d;
                        seen.penetration_at = format!("{what} at t = {time:.3} s");
                    }
                    seen.beyond_sag = seen.beyond_sag.max((depth - sag) / size);
                    let excess = (depth - b.dt * closing - sag) / size;
                    if excess > seen.penetration_excess {
                        seen.penetration_excess = excess;
                        seen.penetration_excess_at = format!(
                            "{what} at t = {time:.3} s, {d:.3} deep, one step's closing {:.3}, soft contact's sag {:.3}",
                            b.dt * closing / size,
                            sag / size
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
                            // the lower centre (against gravity) carries the other
                            let (lower, upper) = if heights[i] <= heights[j] { (i, j) } else { (j, i) };
                            note(
                                -gap,
                                sizes[i].min(sizes[j]),
                                b.closing[i] + b.closing[j],
                                b.sag.pair(lower, upper),
                                format!("b{}/b{}", i + 1, j + 1),
                            );
                        }
                    }
                    if let Some(gr) = ground {
                        let gap = signed_gap(&w.bodies, &w.colliders, gr, handles[i].1);
                        if gap < 0.0 {
                            note(
                                -gap,
                                sizes[i],
                                b.closing[i],
                                b.sag.ground(i),
                                format!("b{}/ground", i + 1),
                            );
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
