//! How the reference engine integrates a row.

use serde::{Deserialize, Serialize};

use crate::impact::ImpactSettings;

/// Time integration of the smooth phase.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Integrator {
    /// The paper's improved Euler (Heun) at a fixed step `dt` (s); the paper
    /// uses 10⁻⁴ s (Sec. 3.1). Events are still located inside a step.
    Paper {
        /// Time step (s).
        dt: f64,
    },
    /// Dormand–Prince 5(4) with step-size control: every accepted step keeps
    /// its local error below `tolerance` relative to the scales h (m), 1 (rad),
    /// √(gh) (m/s) and m g h (J); events are located by bisection. Steps are
    /// capped at 0.002 t̄: events are tested at step ends only, and a longer
    /// step can step over a short excursion (e.g. a brief lift-off).
    Adaptive {
        /// Relative local error tolerance, dimensionless.
        tolerance: f64,
    },
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator::Paper { dt: 1e-4 }
    }
}

/// Settings of a run of the reference engine.
///
/// ```
/// use topple::reference::{Integrator, Settings};
/// let s = Settings::accurate(1e-8);
/// assert_eq!(s.integrator, Integrator::Adaptive { tolerance: 1e-8 });
/// assert_eq!(Settings::default().integrator, Integrator::Paper { dt: 1e-4 });
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Time integration of the smooth phase.
    pub integrator: Integrator,
    /// Impulse stepping of the impacts (default: the paper's ΔP = 10⁻⁴ P₀,
    /// at most 2·10⁵ steps). An impact that needs more is solved again with
    /// its e = 0 contacts held closed (counted in
    /// [`crate::domino::ChainReport::held_impacts`]); if that fails too it is
    /// resolved as plastic ([`crate::domino::ChainReport::impact_fallbacks`]).
    pub impact: ImpactSettings,
    /// A contact is closed when its gap is below this fraction of h
    /// (default 10⁻⁶); also the penetration allowed before a closing event.
    pub gap_tolerance: f64,
    /// A closed contact separating slower than this fraction of √(gh) is made
    /// persistent (its δ̇ projected to 0), and tangential velocities below it
    /// count as sticking (default 10⁻³).
    pub velocity_tolerance: f64,
    /// A closed contact approaching faster than this fraction of √(gh) starts
    /// an impact (default 10⁻⁶, round-off level).
    pub approach_tolerance: f64,
    /// A block behind the wave is frozen when its speeds are below this
    /// fraction of √(gh) and its accelerations below this fraction of g
    /// (default 10⁻⁴).
    pub freeze_tolerance: f64,
    /// Events are located to this time (s) (default 10⁻¹⁰).
    pub event_time_tolerance: f64,
    /// The heel of block i+1 against the front face of block i as a contact
    /// for every pair, not only the last (default false). On, blocks that
    /// slide back under the one leaning on them no longer overlap (Domino X,
    /// Table 1, s/h 0.52, 20 blocks: largest penetration 0.067 mm instead of
    /// 3.8 mm), at about twice the run time. Ideal rows, whose pairs close
    /// face to face at the rest angle, run too (ideal T, s/h 0.45, 40 blocks:
    /// 12 s against 6 s, v̂_na −0.04 %); they stalled beyond about 20 blocks
    /// until impacts repeating at one instant switched the velocity
    /// projection to its unilateral form.
    #[serde(default)]
    pub heel_contacts: bool,
    /// Impulse steps after which an impact that has e = 0 contacts and is
    /// still running under the paper's release-and-reload law is solved again
    /// with those contacts held closed (the limit of those cycles; counted as
    /// `held_impacts`). 2·10⁴ changes v̂_na by 2·10⁻⁴ against waiting for the
    /// full `impact.max_steps` (ideal T, s/h 0.3, 60 blocks) and runs 4×
    /// faster; set it to `impact.max_steps` to give the paper's law every step.
    pub held_retry_after: usize,
    /// Stop as soon as the last block is struck (the wave measures are then
    /// complete); otherwise run until every block is at rest (default true).
    pub stop_at_last_hit: bool,
    /// Stop after this much wall-clock time (s), keeping what was measured
    /// (the report's `stopped_early` is then true); default: no limit.
    pub wall_time_limit: Option<f64>,
    /// Stop at this time (s); default: 40 t̄ per block.
    pub t_max: Option<f64>,
    /// Blocks (1-based) whose θ and θ̇ are recorded.
    pub series_blocks: Vec<usize>,
    /// Least interval (s) between two recorded samples (0: every step).
    pub series_interval: f64,
    /// Times (s) at which the whole row is recorded (snapshots).
    pub snapshot_times: Vec<f64>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            integrator: Integrator::default(),
            impact: ImpactSettings {
                max_steps: 200_000,
                ..ImpactSettings::default()
            },
            gap_tolerance: 1e-6,
            velocity_tolerance: 1e-3,
            approach_tolerance: 1e-6,
            freeze_tolerance: 1e-4,
            event_time_tolerance: 1e-10,
            heel_contacts: false,
            held_retry_after: 20_000,
            stop_at_last_hit: true,
            wall_time_limit: None,
            t_max: None,
            series_blocks: Vec::new(),
            series_interval: 0.0,
            snapshot_times: Vec::new(),
        }
    }
}

impl Settings {
    /// The accurate integration: adaptive Dormand–Prince at `tolerance` for
    /// the smooth phase; impacts keep the paper's fixed impulse step (the
    /// resolver's adaptive mode is not used here yet: with it some impacts of a
    /// long leaning group exceeded the step limit).
    pub fn accurate(tolerance: f64) -> Self {
        Settings {
            integrator: Integrator::Adaptive { tolerance },
            ..Default::default()
        }
    }
}
