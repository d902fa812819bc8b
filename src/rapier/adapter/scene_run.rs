//! Running a scene to its end and collecting what the command prints.

use super::backend::parry::query;
use super::backend::prelude::{ColliderHandle, ColliderSet, RigidBodySet};
use crate::domino::ChainReport;

use super::scene_build::{build, SceneWorld};
use crate::coupling::Resolution;
use crate::rapier::scene::{
    BodyState, ImpactResponse, RunOptions, Scene, SceneError, SceneOutput, SceneResult, TimedImpact,
};

/// The group solved last by topple in the `topple impact` input format.
pub fn impact_input_json(sw: &SceneWorld) -> serde_json::Value {
    let (bodies, contacts) = sw.topple.impact_groups().last_group();
    let settings = sw.topple.settings().impact;
    let (impulse_step, tolerance) = match settings.step_control {
        crate::impact::StepControl::Fixed { impulse_step } => (impulse_step, None),
        // the input format names a tolerance only: the time-domain solver's
        crate::impact::StepControl::Adaptive { tolerance }
        | crate::impact::StepControl::AdaptiveImpulse { tolerance } => (1e-4, Some(tolerance)),
    };
    let contacts: Vec<serde_json::Value> = contacts
        .iter()
        .map(|c| {
            serde_json::json!({
                "bodies": c.bodies, "point": c.point, "normal": c.normal,
                "stiffness": c.material.stiffness, "exponent": c.material.exponent,
                "restitution": c.material.restitution, "friction": c.material.friction,
                "stick_friction": c.material.stick_friction,
            })
        })
        .collect();
    serde_json::json!({
        "bodies": bodies, "contacts": contacts,
        "impulse_step": impulse_step, "tolerance": tolerance,
    })
}

/// Signed gap between two colliders (m): negative when penetrating. The
/// colliders are placed by their parent bodies' poses, which are current even
/// between a write into the bodies and Rapier's next step.
pub fn signed_gap(
    bodies: &RigidBodySet,
    colliders: &ColliderSet,
    a: ColliderHandle,
    b: ColliderHandle,
) -> f64 {
    let pose = |c: ColliderHandle| {
        let co = &colliders[c];
        match (
            co.parent().and_then(|h| bodies.get(h)),
            co.position_wrt_parent(),
        ) {
            (Some(rb), Some(offset)) => *rb.position() * *offset,
            _ => *co.position(),
        }
    };
    let (ca, cb) = (&colliders[a], &colliders[b]);
    let (pa, pb) = (pose(a), pose(b));
    match query::contact(&pa, ca.shape(), &pb, cb.shape(), 0.0) {
        Ok(Some(c)) => f64::from(c.dist),
        _ => query::distance(&pa, ca.shape(), &pb, cb.shape()).map_or(f64::INFINITY, f64::from),
    }
}

/// Tracks when block k hits block k + 1 along a row: at the instant of
/// topple's impact between them when there is one, else where the gap between
/// them, taken as linear in time over the step, falls to `HIT_GAP`.
#[derive(Clone, Debug, Default)]
pub struct HitTracker {
    /// T_i (s), T_1 = 0.
    pub hit_times: Vec<f64>,
    prev_gap: Option<f64>,
}

/// A block counts as hitting its successor when their gap falls to this (m);
/// the time is interpolated linearly between the two steps around it.
const HIT_GAP: f64 = 1e-6;

impl HitTracker {
    /// Starts with block 1 pushed at t = 0.
    pub fn new() -> Self {
        HitTracker {
            hit_times: vec![0.0],
            prev_gap: None,
        }
    }

    /// Checks the front pair after a step ending at `time` of length `dt` (s).
    pub fn update(&mut self, sw: &SceneWorld, time: f64, dt: f64) {
        let Some(row) = &sw.row else { return };
        let w = &sw.world;
        let c = &row.colliders;
        self.update_with(c.len(), time, dt, |k| {
            let gap = signed_gap(&w.bodies, &w.colliders, c[k - 1], c[k]);
            (gap, first_impact(sw, c[k - 1], c[k]))
        });
    }

    /// The same for any engine: `probe(k)` gives the signed gap (m) between
    /// blocks k and k + 1 (1-based; colliders `k − 1` and `k`) at the end of
    /// the step and, when the engine knows it, the instant (s into the step)
    /// of an impact between them; `n` is the number of blocks.
    pub fn update_with(
        &mut self,
        n: usize,
        time: f64,
        dt: f64,
        mut probe: impl FnMut(usize) -> (f64, Option<f64>),
    ) {
        loop {
            let k = self.hit_times.len(); // next pair: blocks k and k + 1 (1-based)
            if k >= n {
                return;
            }
            let (gap, struck) = probe(k);
            if gap > HIT_GAP && struck.is_none() {
                self.prev_gap = Some(gap);
                return;
            }
            // topple knows the instant of the impact; otherwise the gap is
            // taken as linear in time over the step
            let t = match (struck, self.prev_gap) {
                (Some(in_step), _) => time - dt + in_step,
                (None, Some(g0)) if g0 > gap => time - dt + dt * (g0 - HIT_GAP) / (g0 - gap),
                (None, _) => time,
            };
            self.hit_times.push(t);
            self.prev_gap = None;
        }
    }
}

/// The instant (s into the last step) of the first impact of the last step
/// with a contact between the bodies of colliders `a` and `b`.
fn first_impact(sw: &SceneWorld, a: ColliderHandle, b: ColliderHandle) -> Option<f64> {
    let body = |c: ColliderHandle| sw.world.colliders.get(c).and_then(|co| co.parent());
    let (ba, bb) = (body(a)?, body(b)?);
    sw.topple
        .last_events()
        .iter()
        .filter(|ev| {
            sw.topple
                .event_contacts(ev)
                .iter()
                .any(|c| c.bodies == [Some(ba), Some(bb)] || c.bodies == [Some(bb), Some(ba)])
        })
        .map(|ev| ev.time_in_step)
        .min_by(f64::total_cmp)
}

/// Runs a scene with an engine on this Rapier build (see
/// [`crate::rapier::scene::run_scene`] for either build).
///
/// ```
/// use topple::rapier::f64::run_scene;
/// use topple::rapier::scene::{ImpactResponse, RunOptions, Scene};
/// let scene: Scene = toml::from_str(r#"
///     duration = 0.01
///     gravity = [0.0, 0.0]
///     [[materials]]
///     name = "steel"
///     stiffness = 1e10
///     [[bodies]]
///     shape = "ball"
///     radius = 0.05
///     position = [0.0, 0.0]
///     velocity = [1.0, 0.0]
///     mass = 1.0
///     material = "steel"
///     [[bodies]]
///     shape = "ball"
///     radius = 0.05
///     position = [0.1, 0.0]
///     mass = 1.0
///     material = "steel"
/// "#).unwrap();
/// let out = run_scene(&scene, ImpactResponse::Topple, RunOptions::default()).unwrap();
/// assert_eq!(out.impacts.len(), 1);
/// assert!((out.bodies[1].velocity[0] - 1.0).abs() < 1e-3);
/// ```
pub fn run_scene(
    scene: &Scene,
    engine: ImpactResponse,
    options: RunOptions,
) -> SceneResult<SceneOutput> {
    let mut sw = build(scene, engine)?;
    let dt = f64::from(sw.world.integration_parameters.dt);
    let steps = (scene.duration / dt).round() as usize;
    let ke0 = sw.kinetic_energy();
    let mut impacts = Vec::new();
    let mut hits = HitTracker::new();
    let mut taken = 0;
    let mut dump = options.dump_fallback_impact.as_ref();
    for _ in 0..steps {
        let time = sw.time + dt;
        let reports = sw.step();
        let fallback = reports.iter().any(|r| r.resolution != Resolution::Lzb);
        impacts.extend(reports.iter().map(|&report| TimedImpact { time, report }));
        if fallback && let Some(path) = dump.take() {
            let json = serde_json::to_string_pretty(&impact_input_json(&sw))
                .expect("a JSON value always serialises");
            std::fs::write(path, json).map_err(|source| SceneError::Io {
                path: path.clone(),
                source,
            })?;
        }
        taken += 1;
        if let Some(row) = &sw.row {
            hits.update(&sw, time, dt);
            if options.stop_after_last_hit && hits.hit_times.len() == row.colliders.len() {
                break;
            }
        }
    }
    let row = sw.row.as_ref().map(|r| {
        let mut report = ChainReport::new(engine.name(), &r.spec, hits.hit_times.clone());
        report.simulated_time = sw.time;
        report
    });
    let bodies = sw
        .bodies
        .iter()
        .map(|(name, h, _)| {
            let rb = &sw.world.bodies[*h];
            let (c, v) = (rb.center_of_mass(), rb.linvel());
            BodyState {
                name: name.clone(),
                position: [f64::from(c.x), f64::from(c.y)],
                angle: f64::from(rb.rotation().angle()),
                velocity: [f64::from(v.x), f64::from(v.y)],
                angular_velocity: f64::from(rb.angvel()),
            }
        })
        .collect();
    Ok(SceneOutput {
        engine,
        precision: super::PRECISION,
        time: sw.time,
        steps: taken,
        bodies,
        kinetic_energy: [ke0, sw.kinetic_energy()],
        impacts,
        stats: sw.topple.stats(),
        row,
    })
}
