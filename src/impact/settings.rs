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
    /// The paper's scheme with the impulse step chosen per step (see
    /// `impact::solver`): each accepted step keeps its estimated local
    /// error below `tolerance`, velocity errors relative to the largest
    /// approach speed at the start of the impact. The step lands on every
    /// switch (compression ends, energy runs out, gaps close, slip stops), so
    /// a lone contact takes a few steps, and e = 0 contacts that reload after
    /// their compression ended follow the paper's law without a step limit
    /// in practice. The error of the result falls with the tolerance
    /// (about 10⁻⁴ × the approach speed at `tolerance` 10⁻⁴ on domino
    /// impacts, see `docs/reference-performance.md`).
    Adaptive {
        /// Local error per step relative to the approach speed,
        /// dimensionless (e.g. 10⁻⁴ … 10⁻⁸).
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
    /// e = 0 contacts. `false` (default, the paper's law):
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
