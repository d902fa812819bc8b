//! What a scene run needs that does not depend on the Rapier build: the
//! engine choice, the settings and materials built from a scene, the output.

use crate::coupling::{FallbackPolicy, ImpactReport, PairMaterial, PatchRule, ToppleSettings};
use crate::impact::{ContactMaterial, ImpactSettings};
use crate::rapier::ImpactResponse;
use crate::rapier::{Precision, ToppleStats};

use super::format::{PairLaw, RowOverrides, RowSection, Scene, SolverSpec};
use crate::domino::{ChainReport, RowSpec as DominoRow};

/// The material of a pair rule (the adapters use it; without a Rapier build
/// nothing does).
#[cfg_attr(not(any(feature = "f32", feature = "f64")), allow(dead_code))]
pub(crate) fn pair_material(l: &PairLaw) -> PairMaterial {
    if l.no_slip {
        return PairMaterial {
            impact: ContactMaterial::hertz(l.stiffness)
                .with_exponent(l.exponent)
                .with_restitution(l.restitution)
                .no_slip(),
            smooth_friction: super::NO_SLIP_FRICTION,
        };
    }
    PairMaterial::from_table(
        ContactMaterial {
            stiffness: l.stiffness,
            exponent: l.exponent,
            restitution: l.restitution,
            friction: l.friction,
            stick_friction: l.stick_friction,
        },
        l.friction,
        l.stick_friction,
        l.restitution,
        l.impact_friction_factor,
    )
}

/// topple's settings from a scene's solver section and the world's length
/// unit (m). A scene gives its values in SI units; topple's
/// settings are per length unit ([`crate::rapier`], "Units"), so lengths and
/// speeds are divided by it here. The impact threshold is the scene's
/// `min_approach_speed`, by default 10⁻³ m/s, and never below 2|g|Δt of the
/// world's gravity and step (the adapter's floor). The work budget of a
/// step is the scene's `max_work`, by default a game's bounded step
/// ([`super::WorkBudget`]); `max_work = "none"` runs every impact to its end.
///
/// ```
/// use topple::coupling::ToppleSettings;
/// use topple::rapier::scene::{topple_settings, SolverSpec, WorkBudget};
/// let s = topple_settings(&SolverSpec::default(), 0.08);
/// assert!((s.min_approach_speed * 0.08 - 1e-3).abs() < 1e-15);
/// assert_eq!(s.fallback.max_work, Some(ToppleSettings::DEFAULT_STEP_WORK));
/// let exact = SolverSpec { max_work: WorkBudget::Unbounded, ..SolverSpec::default() };
/// assert_eq!(topple_settings(&exact, 0.08).fallback.max_work, None);
/// ```
pub fn topple_settings(s: &SolverSpec, length_unit: f64) -> ToppleSettings {
    let l = if length_unit.is_finite() && length_unit > 0.0 {
        length_unit
    } else {
        1.0
    };
    let patch = PatchRule::default();
    ToppleSettings {
        impact: match (s.tolerance, s.impulse_step) {
            (Some(t), _) => ImpactSettings::adaptive(t),
            (None, Some(step)) => ImpactSettings::fixed(step),
            (None, None) => ToppleSettings::default().impact,
        },
        patch: PatchRule {
            closed_tolerance: s.closed_tolerance / l,
            lambda: s.lambda,
            min_patch_length: patch.min_patch_length / l,
            flat_tolerance: patch.flat_tolerance / l,
        },
        min_approach_speed: s.min_approach_speed.unwrap_or(1e-3) / l,
        max_group_hops: s
            .max_group_hops
            .or(ToppleSettings::default().max_group_hops),
        fallback: FallbackPolicy {
            max_work: s.max_work.max_work(),
            ..FallbackPolicy::default()
        },
        max_splits: s.max_splits.unwrap_or(ToppleSettings::default().max_splits),
        max_substep: match s.max_substep {
            None => ToppleSettings::default().max_substep,
            Some(h) => (h > 0.0).then_some(h),
        },
        rest_fraction: s
            .rest_fraction
            .unwrap_or(ToppleSettings::DEFAULT_REST_FRACTION),
    }
}

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
    pub engine: ImpactResponse,
    /// Rapier build used.
    pub precision: Precision,
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
    /// For a scene with a row: the same report as `topple chain` (hit
    /// times, v̂_i, v̂_na and its spread).
    pub row: Option<ChainReport>,
}

/// Options of [`run_scene`](super::run_scene).
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Stop a row scene once its last block has been hit.
    pub stop_after_last_hit: bool,
    /// Write the first impact group that needed the fallback policy (held,
    /// plastic or rejected) here, as input for `topple impact`.
    pub dump_fallback_impact: Option<std::path::PathBuf>,
}

/// Reads and parses a scene file.
#[cfg(feature = "scene-files")]
pub fn load_scene(path: &std::path::Path) -> super::SceneResult<Scene> {
    let text = std::fs::read_to_string(path).map_err(|source| super::SceneError::Io {
        path: path.into(),
        source,
    })?;
    crate::validate::parse_toml(&text, &path.display().to_string()).map_err(|e| {
        super::SceneError::Parse {
            path: path.into(),
            message: e.to_string(),
        }
    })
}

/// The scene of a domino row of [`crate::domino`]: the row's every parameter
/// as an override of the scene's row generator, Rapier's `solver` settings
/// (its λ taken from the row), `max_time` (s) as the duration.
pub fn row_scene(row: &DominoRow, solver: SolverSpec, max_time: f64) -> Scene {
    let p = &row.params;
    Scene {
        description: String::new(),
        duration: max_time,
        gravity: [0.0, -p.gravity],
        solver: SolverSpec {
            lambda: p.lambda_points,
            ..solver
        },
        materials: Vec::new(),
        pairs: Vec::new(),
        ground: None,
        bodies: Vec::new(),
        row: Some(RowSection {
            preset: "T".into(), // every value is overridden below
            n: row.n,
            spacing: row.spacing_ratio(),
            push: row.push,
            ideal: false,
            density: 1000.0,
            mass: Some(p.block.mass),
            ground: p.ground,
            overrides: RowOverrides {
                height: Some(p.block.height),
                thickness: Some(p.block.thickness),
                mu1: Some(p.mu1),
                mu1_stick: Some(p.mu1_stick),
                e1: Some(p.e1),
                k1: Some(p.k1),
                mu2: Some(p.mu2),
                mu2_stick: Some(p.mu2_stick),
                e2: Some(p.e2),
                k2: Some(p.k2),
                alpha: Some(p.alpha),
                impact_friction_factor: Some(p.impact_friction_factor),
            },
        }),
    }
}
