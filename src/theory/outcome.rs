//! What a theory model returns: a steady wave, or "no wave" with the reason;
//! and the errors (bad input, numerics that did not converge).

use serde::Serialize;

/// The steady (natural) wave of a model at one geometry, in the paper's scales:
/// speeds over √(gh), angular velocities over √(g/h), times over √(h/g).
///
/// ```
/// use topple::theory::{solve, Geometry, Model};
/// let wave = solve(&Model::Cooperative, &Geometry::new(0.12, 0.3).unwrap())
///     .unwrap()
///     .wave()
///     .cloned()
///     .unwrap();
/// // the speed is the pitch over the period
/// assert!((wave.natural_speed - 0.42 / wave.period).abs() < 1e-12);
/// assert!(wave.omega_before > wave.omega_after);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Wave {
    /// Natural speed v/√(gh) = (λ/h) / (T/√(h/g)).
    pub natural_speed: f64,
    /// Leader's angular velocity just after a collision (the struck block's), over √(g/h).
    pub omega_after: f64,
    /// Leader's angular velocity just before a collision, over √(g/h).
    pub omega_before: f64,
    /// Time between two collisions, over √(h/g).
    pub period: f64,
    /// Collision angle θ_c (rad), sin θ_c = s/h.
    pub theta_c: f64,
    /// Rest angle θ_∞ (rad) of the fallen train, cos θ_∞ = d/λ.
    pub theta_inf: f64,
    /// Largest number of blocks summed in the train (1 for the single collision model).
    pub train_blocks: usize,
    /// Degree of the Chebyshev interpolant in θ_0 that converged (0 when not used).
    pub nodes: usize,
}

/// Why a model has no steady wave at a geometry.
///
/// ```
/// use topple::theory::{solve, Geometry, Model, NoWave, Outcome};
/// let out = solve(&Model::Cooperative, &Geometry::new(0.12, 1.2).unwrap()).unwrap();
/// assert_eq!(out, Outcome::NoWave(NoWave::NoCollision));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum NoWave {
    /// s ≥ h: the falling block lands without reaching the next one.
    NoCollision,
    /// θ_c ≥ θ_∞: the leader would have to pass the angle at which the fallen
    /// train comes to rest (group models only).
    CollisionPastRest,
    /// Friction at the collision is so large (μ d ≥ h cos θ_c) that the impact
    /// cannot push the struck block forward.
    FrictionBlocksImpact,
    /// The leader (or the struck block) stops before reaching θ_c, at `angle` (rad):
    /// the wave dies out.
    LeaderStalls {
        /// Angle (rad) at which the angular velocity squared vanishes first.
        angle: f64,
    },
    /// Gravity does not give back over one cycle what the collision takes: the
    /// only fixed point of the cycle map is at rest.
    NoEnergyGain,
}

impl std::fmt::Display for NoWave {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NoWave::NoCollision => write!(f, "s >= h: a falling block never reaches the next one"),
            NoWave::CollisionPastRest => write!(
                f,
                "collision angle beyond the rest angle of the fallen train (theta_c >= theta_inf)"
            ),
            NoWave::FrictionBlocksImpact => write!(
                f,
                "friction at the collision is too large (mu d >= h cos theta_c) to push the next block"
            ),
            NoWave::LeaderStalls { angle } => write!(
                f,
                "the leader stalls at {angle:.6} rad before reaching the next block"
            ),
            NoWave::NoEnergyGain => write!(
                f,
                "gravity does not make up over a cycle for what the collision takes"
            ),
        }
    }
}

/// Result of a model at one geometry.
///
/// ```
/// use topple::theory::{solve, Geometry, Model, Outcome};
/// match solve(&Model::Cooperative, &Geometry::new(0.12, 0.5).unwrap()).unwrap() {
///     Outcome::Wave(w) => assert!(w.natural_speed > 1.0),
///     Outcome::NoWave(reason) => panic!("no wave: {reason}"),
/// }
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// A steady wave exists.
    Wave(Wave),
    /// No steady wave, and why.
    NoWave(NoWave),
}

impl Outcome {
    /// The wave, if there is one.
    pub fn wave(&self) -> Option<&Wave> {
        match self {
            Outcome::Wave(w) => Some(w),
            Outcome::NoWave(_) => None,
        }
    }

    /// The natural speed v/√(gh), if there is a wave.
    pub fn natural_speed(&self) -> Option<f64> {
        self.wave().map(|w| w.natural_speed)
    }
}

/// Errors of the theory layer.
///
/// ```
/// use topple::theory::{solve, Geometry, Model, TheoryError};
/// let err = solve(&Model::Single { mu: 0.1, e: 1.5 }, &Geometry::new(0.12, 0.3).unwrap());
/// assert!(matches!(err, Err(TheoryError::InvalidParameter(_))));
/// // very thick blocks with much friction: the train's friction weights do not decay
/// let err = solve(&Model::Extended { mu: 0.5 }, &Geometry::new(0.95, 0.847).unwrap());
/// assert!(matches!(err, Err(TheoryError::OutsideModel(_))));
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TheoryError {
    /// An argument is out of its range: the argument, its value and the
    /// allowed range.
    #[error("{0}")]
    InvalidParameter(#[from] crate::input::InputError),
    /// The parameters are valid but the model's assumptions break down there
    /// (the message says how), so it gives no answer.
    #[error("outside the model: {0}")]
    OutsideModel(String),
    /// A numerical procedure did not reach its tolerance (the message says
    /// which and how far it got).
    #[error("not converged: {0}")]
    NotConverged(String),
    /// [`min_spacing`](super::min_spacing) found no step from "no wave" to
    /// "wave" for s/h in (0, 1).
    #[error("{}", match .wave_at {
        Some(s) => format!("the {model} model has a wave already at s/h = {s}"),
        None => format!("the {model} model has no wave for s/h in (0, 1)"),
    })]
    NoThreshold {
        /// The model's name ([`Model::name`](super::Model::name)).
        model: &'static str,
        /// The smallest spacing ratio tried, if the wave runs there already;
        /// `None` if no spacing ratio gives a wave.
        wave_at: Option<f64>,
    },
    /// Writing a table or a plot failed.
    #[error("{}: {message}", .path.display())]
    Output {
        /// The file.
        path: std::path::PathBuf,
        /// What went wrong.
        message: String,
    },
}
