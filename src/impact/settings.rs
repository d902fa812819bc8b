//! How the resolver steps through an impact.

use serde::{Deserialize, Serialize};

/// How the resolver steps through an impact.
///
/// ```
/// use topple::impact::StepControl;
/// assert_eq!(StepControl::default(), StepControl::Adaptive { tolerance: 2e-6 });
/// assert_eq!(StepControl::paper(), StepControl::Fixed { impulse_step: 1e-4 });
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum StepControl {
    /// The paper's scheme (Sec. 3.1): the primary contact advances by
    /// ΔP = `impulse_step` · P₀ each step, P₀ being the magnitude of the linear
    /// momentum of the free bodies just before the impact (their kinetic-energy
    /// momentum scale when that is zero, see [`crate::impact::ImpactSolver`]).
    /// Second order in ΔP; thousands of steps per impact at the paper's 10⁻⁴.
    Fixed {
        /// ΔP / P₀, dimensionless; the paper uses 10⁻⁴.
        impulse_step: f64,
    },
    /// The default: the same law written in the impact's own time, with the
    /// compressions as state (docs/model.md §7), integrated by an embedded
    /// Runge–Kutta pair of orders 5 and 4 whose step keeps the estimated local
    /// error below `tolerance`; every switch of the law (compression ends,
    /// energy runs out, a gap closes, stick and slip, a held contact lets go)
    /// is located on the step's interpolant and the step restarts there.
    /// Tens of steps per impact.
    Adaptive {
        /// Local error per step, dimensionless: velocities relative to the
        /// largest approach speed at the start of the impact, compressions
        /// relative to the compression that would store that approach's
        /// energy (e.g. 10⁻³ … 10⁻⁹).
        tolerance: f64,
    },
    /// The paper's impulse stepping with the step chosen per step from an
    /// estimate of its local error (topple's default before the time-domain
    /// solver; second order, so its steps shrink as √tolerance). Kept so that
    /// benchmarks can compare it side by side.
    AdaptiveImpulse {
        /// Local error per step relative to the approach speed,
        /// dimensionless.
        tolerance: f64,
    },
}

impl StepControl {
    /// The default tolerance of [`StepControl::Adaptive`].
    pub const DEFAULT_TOLERANCE: f64 = 2e-6;

    /// The paper's fixed impulse step ΔP = 10⁻⁴ P₀ (Sec. 3.1).
    pub const fn paper() -> Self {
        StepControl::Fixed { impulse_step: 1e-4 }
    }
}

impl Default for StepControl {
    fn default() -> Self {
        StepControl::Adaptive {
            tolerance: Self::DEFAULT_TOLERANCE,
        }
    }
}

/// Settings of one impact resolution.
///
/// ```
/// use topple::impact::{ImpactSettings, StepControl};
/// let s = ImpactSettings::adaptive(1e-6);
/// assert_eq!(s.step_control, StepControl::Adaptive { tolerance: 1e-6 });
/// assert_eq!(ImpactSettings::default().step_control, StepControl::default());
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
    /// e = 0 contacts under the paper's law, time-domain solver only: a
    /// contact that is pushed again after its compression ended goes
    /// through load cycles; once a cycle has changed its own normal rate by
    /// at most `fast_cycle` times the impact's velocity scale (W_ii ΔP ≤
    /// fast_cycle · v), its next cycles are taken by their limit — held
    /// closed by a non-negative force that keeps its rate — until that force
    /// would pull. The limit differs from the cycles by terms of the order
    /// of the cycle's swing W_ii ΔP (docs/model.md §8). e > 0 contacts that
    /// bounce again and again inside a pile are held the same way after a
    /// cycle within 0.03 of this bound, their small approach stopped as
    /// by a plastic impact (§8, "Fast bounces at e > 0"). With a
    /// [`rest_speed`](Self::rest_speed) v_r the e = 0 bound is at least
    /// 30 v_r (0.3 of the plugins' impact threshold at their rest
    /// fraction): a cycle that slow is left to its limit as the slow tail
    /// is left to the engine (§8). 0: every cycle is followed (the paper's
    /// law to the integration tolerance), whatever the rest speed.
    #[serde(default = "default_fast_cycle")]
    pub fast_cycle: f64,
    /// The speed (m/s, or the world's length unit per second) below which
    /// what is left of an impact belongs to the engine's resting contacts.
    /// The impact ends as soon as no contact point
    /// approaches faster than this and none stores the energy to rebound
    /// faster than this (√(2 e² E W_nn), docs/model.md §9): the stored
    /// energy left is dropped (dissipated, never created) and the slow
    /// approaches are left to the engine, which stops them as it stops a
    /// resting contact. Every integrator. 0 (default): the impact runs to its end as the
    /// paper's law defines it. A pile of resting boxes that one box lands
    /// on never ends under that law (the wave keeps sloshing between boxes
    /// held by the frozen positions, ever slower); an engine that steps at
    /// Δt sets this to a fraction of its impact threshold
    /// ([`crate::coupling::ToppleSettings::rest_fraction`]).
    #[serde(default)]
    pub rest_speed: f64,
}

fn default_fast_cycle() -> f64 {
    ImpactSettings::FAST_CYCLE
}

impl Default for ImpactSettings {
    fn default() -> Self {
        ImpactSettings {
            step_control: StepControl::default(),
            max_steps: 10_000_000,
            e0_hold: false,
            fast_cycle: Self::FAST_CYCLE,
            rest_speed: 0.0,
        }
    }
}

impl ImpactSettings {
    /// The default of [`ImpactSettings::fast_cycle`].
    pub const FAST_CYCLE: f64 = 0.01;

    /// The paper's fixed step ΔP = `impulse_step` · P₀.
    pub fn fixed(impulse_step: f64) -> Self {
        ImpactSettings {
            step_control: StepControl::Fixed { impulse_step },
            ..Default::default()
        }
    }

    /// The time-domain solver at the given relative tolerance
    /// ([`StepControl::Adaptive`]).
    pub fn adaptive(tolerance: f64) -> Self {
        ImpactSettings {
            step_control: StepControl::Adaptive { tolerance },
            ..Default::default()
        }
    }

    /// The impulse stepping with an error-controlled step
    /// ([`StepControl::AdaptiveImpulse`]).
    pub fn adaptive_impulse(tolerance: f64) -> Self {
        ImpactSettings {
            step_control: StepControl::AdaptiveImpulse { tolerance },
            ..Default::default()
        }
    }
}
