//! Running a scene to its end and collecting what the command prints.

use rapier2d_f64::parry::query;
use rapier2d_f64::prelude::{ColliderHandle, ColliderSet};

use crate::rapier::{ImpactReport, ToppleStats};

use super::build::{build, Engine, SceneWorld};
use super::format::Scene;
use super::row::RowMeasures;

/// A body's state at the end.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BodyState {
    /// Name.
    pub name: String,
    /// Centre of mass (m).
    pub position: [f64; 2],
    /// Angle (rad).
    pub angle: f64,
    /// Velocity (m/s).
    pub velocity: [f64; 2],
    /// Angular velocity (rad/s).
    pub angular_velocity: f64,
}

/// An impact with the time it was resolved.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TimedImpact {
    /// Time (s).
    pub time: f64,
    /// What it did.
    #[serde(flatten)]
    pub report: ImpactReport,
}

/// What a scene run returns.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SceneOutput {
    /// Engine used.
    pub engine: Engine,
    /// Simulated time (s).
    pub time: f64,
    /// Steps taken.
    pub steps: usize,
    /// Final body states.
    pub bodies: Vec<BodyState>,
    /// Kinetic energy at the start and at the end (J per unit depth).
    pub kinetic_energy: [f64; 2],
    /// Impacts resolved by topple (none for the native engine).
    pub impacts: Vec<TimedImpact>,
    /// topple's counters.
    pub stats: ToppleStats,
    /// Wave measures, for a scene with a row.
    pub row: Option<RowMeasures>,
}

/// Options of [`run_scene`].
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Stop a row scene once its last block has been hit.
    pub stop_after_last_hit: bool,
    /// If the resolver fails, write the failing group here as input for
    /// `topple impact`.
    pub dump_failed_impact: Option<std::path::PathBuf>,
}

/// The group solved last by topple in the `topple impact` input format.
pub fn impact_input_json(sw: &SceneWorld) -> serde_json::Value {
    let (bodies, contacts) = sw.topple.impact_groups().last_group();
    let settings = sw.topple.settings().impact;
    let (impulse_step, tolerance) = match settings.step_control {
        crate::impact::StepControl::Fixed { impulse_step } => (impulse_step, None),
        crate::impact::StepControl::Adaptive { tolerance } => (1e-4, Some(tolerance)),
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

/// Signed gap between two colliders (m): negative when penetrating.
pub fn signed_gap(colliders: &ColliderSet, a: ColliderHandle, b: ColliderHandle) -> f64 {
    let (ca, cb) = (&colliders[a], &colliders[b]);
    match query::contact(ca.position(), ca.shape(), cb.position(), cb.shape(), 0.0) {
        Ok(Some(c)) => c.dist,
        _ => query::distance(ca.position(), ca.shape(), cb.position(), cb.shape())
            .unwrap_or(f64::INFINITY),
    }
}

/// Tracks when block k hits block k + 1 along a row.
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

    /// Checks the front pair after a step ending at `time` of length `dt`.
    pub fn update(&mut self, sw: &SceneWorld, time: f64, dt: f64) {
        let Some(row) = &sw.row else { return };
        loop {
            let k = self.hit_times.len(); // next pair: blocks k and k + 1 (1-based)
            if k >= row.colliders.len() {
                return;
            }
            let gap = signed_gap(&sw.world.colliders, row.colliders[k - 1], row.colliders[k]);
            if gap > HIT_GAP {
                self.prev_gap = Some(gap);
                return;
            }
            let t = match self.prev_gap {
                Some(g0) if g0 > gap => time - dt + dt * (g0 - HIT_GAP) / (g0 - gap),
                _ => time,
            };
            self.hit_times.push(t);
            self.prev_gap = None;
        }
    }
}

/// Runs a scene with an engine.
///
/// ```
/// use topple::rapier::scene::{run_scene, Engine, RunOptions, Scene};
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
/// let out = run_scene(&scene, Engine::Rapier, RunOptions::default()).unwrap();
/// assert_eq!(out.impacts.len(), 1);
/// assert!((out.bodies[1].velocity[0] - 1.0).abs() < 1e-3);
/// ```
pub fn run_scene(
    scene: &Scene,
    engine: Engine,
    options: RunOptions,
) -> anyhow::Result<SceneOutput> {
    let mut sw = build(scene, engine)?;
    let dt = sw.world.integration_parameters.dt;
    let steps = (scene.duration / dt).round() as usize;
    let ke0 = sw.kinetic_energy();
    let mut impacts = Vec::new();
    let mut hits = HitTracker::new();
    let mut taken = 0;
    for _ in 0..steps {
        let time = sw.time + dt;
        let reports = match sw.step() {
            Ok(r) => r,
            Err(e) => {
                if let Some(path) = &options.dump_failed_impact {
                    let json = serde_json::to_string_pretty(&impact_input_json(&sw))?;
                    std::fs::write(path, json)?;
                }
                return Err(e.context(format!("at t = {time:.6} s")));
            }
        };
        impacts.extend(reports.iter().map(|&report| TimedImpact { time, report }));
        taken += 1;
        if let Some(row) = &sw.row {
            hits.update(&sw, time, dt);
            if options.stop_after_last_hit && hits.hit_times.len() == row.colliders.len() {
                break;
            }
        }
    }
    let row = sw.row.as_ref().map(|r| {
        let g = scene.gravity[0].hypot(scene.gravity[1]);
        RowMeasures::from_hit_times(
            hits.hit_times.clone(),
            r.colliders.len(),
            r.spacing,
            r.preset.thickness,
            r.preset.height,
            g,
        )
    });
    let bodies = sw
        .bodies
        .iter()
        .map(|(name, h, _)| {
            let rb = &sw.world.bodies[*h];
            let c = rb.center_of_mass();
            BodyState {
                name: name.clone(),
                position: [c.x, c.y],
                angle: rb.rotation().angle(),
                velocity: [rb.linvel().x, rb.linvel().y],
                angular_velocity: rb.angvel(),
            }
        })
        .collect();
    Ok(SceneOutput {
        engine,
        time: sw.time,
        steps: taken,
        bodies,
        kinetic_energy: [ke0, sw.kinetic_energy()],
        impacts,
        stats: sw.topple.stats(),
        row,
    })
}

/// Reads and parses a scene file.
pub fn load_scene(path: &std::path::Path) -> anyhow::Result<Scene> {
    use anyhow::Context;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    toml::from_str(&text).with_context(|| format!("parsing {}", path.display()))
}
