//! How the resolver steps through an impact.

use serde::{Deserialize, Serialize};

/// How the impulse variable is stepped.
///
/// ```
/// use topple::impact::StepControl;
/// let paper = StepControl::default();
/// assert_eq!(paper, StepControl::Fixed { impulse_step: 1e-4 });
/// let adaptive = StepControl::Adaptive { tolerance: 1e-6 };
/// # let _ = adaptive;
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum StepControl {
    /// The paper's scheme (Sec. 3.1): the primary contact advances by
    /// ΔP = `impulse_step` · P₀ each step, P₀ being the magnitude of the linear
    /// momentum of the free bodies just before the impact (their kinetic-energy
    /// momentum scale when that is zero, see [`crate::impact::ImpactSolver`]).
    Fixed {
        /// ΔP / P₀, dimensionless; the paper uses 10⁻⁴.
        impulse_step: f64,
    },
    /// The same model integrated in the time of its contact law with an
    /// embedded Runge–Kutta pair (Bogacki–Shampine 3(2)), step-size control
    /// and landing on every mode change (see `impact::solver::timeline`).
    /// Each accepted step keeps its local error below `tolerance`: contact
    /// rates relative to the largest approach speed, compressions relative to
    /// that speed times the two-body contact duration.
    Adaptive {
        /// Relative local error per step, dimensionless (e.g. 10⁻⁸); the error
        /// of the result is about this times the number of steps.
        tolerance: f64,
    },
}

impl Default for StepControl {
    fn default() -> Self {
        StepControl::Fixed { impulse_step: 1e-4 }
    }
}

/// Settings of one impact resolution.
///
/// ```
/// use topple::impact::{ImpactSettings, StepControl};
/// let s = ImpactSettings::adaptive(1e-6);
/// assert_eq!(s.step_control, StepControl::Adaptive { tolerance: 1e-6 });
/// assert!(s.max_steps > 0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImpactSettings {
    /// Fixed or adaptive stepping.
    pub step_control: StepControl,
    /// A runaway impact stops with [`crate::impact::ImpactError::StepLimit`]
    /// after this many steps (default 10⁷).
    pub max_steps: usize,
    /// e = 0 contacts (fixed step only). `false` (default, the paper's law):
    /// the energy is lost when compression ends and a contact that is still
    /// pushed loads again from zero, cycle after cycle, each cycle dissipating
    /// what it stored. `true`: a contact whose compression has ended without
    /// separating is held closed by a non-negative impulse that does no work
    /// (a plastic unilateral constraint). Faster by orders of magnitude on
    /// wedged trains of blocks, and less dissipative: a different model, not
    /// a refinement of the default.
    #[serde(default)]
    pub e0_hold: bool,
}

impl Default for ImpactSettings {
    fn default() -> Self {
        ImpactSettings {
            step_control: StepControl::default(),
            max_steps: 10_000_000,
            e0_hold: false,
        }
    }
}

impl ImpactSettings {
    /// The paper's fixed step ΔP = `impulse_step` · P₀.
    pub fn fixed(impulse_step: f64) -> Self {
        ImpactSettings {
            step_control: StepControl::Fixed { impulse_step },
            ..Default::default()
        }
    }

    /// Adaptive stepping at the given relative tolerance.
    pub fn adaptive(tolerance: f64) -> Self {
        ImpactSettings {
            step_control: StepControl::Adaptive { tolerance },
            ..Default::default()
        }
    }
}
