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
/// // impacts: the time-domain resolver; the paper's fixed step on request
/// assert_eq!(Settings::default().impact.step_control, topple::impact::StepControl::default());
/// let paper = Settings::paper_impacts();
/// assert_eq!(paper.impact.step_control, topple::impact::StepControl::Fixed { impulse_step: 1e-4 });
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Time integration of the smooth phase.
    pub integrator: Integrator,
    /// How the impacts are resolved (default: the resolver's default, the
    /// time-domain integration at [`crate::impact::StepControl::DEFAULT_TOLERANCE`],
    /// docs/model.md §7, at most 2·10⁵ steps; the paper's fixed impulse step
    /// ΔP = 10⁻⁴ P₀ with [`Settings::paper_impacts`]). On the rows of
    /// docs/reference-performance.md it gives v̂_na within 0.05 % of a run
    /// at 10⁻¹⁰ and runs 2–6 times faster than the adaptive impulse stepping
    /// at 10⁻⁴ that was the default before it (the wedged e = 0 trains of the
    /// ideal rows gain most). An impact that needs
    /// more than `held_retry_after` steps is solved again with
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
    /// an impact; a slower one is stopped by the projection onto the active
    /// contacts, as a separation slower than `velocity_tolerance` is (default
    /// [`Settings::APPROACH_TOLERANCE`] = 10⁻⁴). The time-domain resolver ends
    /// an impact at half this speed (its rest speed, docs/model.md §9), so
    /// this is also where each impact's tail is cut.
    pub approach_tolerance: f64,
    /// A block at the back of the moving window is frozen (taken out of the
    /// integration, its kinetic energy booked as `frozen`) when its speeds
    /// are below this fraction of √(gh) and its accelerations below this
    /// fraction of g (default [`Settings::FREEZE_TOLERANCE`] = 10⁻²). Rows whose
    /// blocks keep bouncing behind the wave (Table 1's e1, e2) never get below
    /// 10⁻³ and the window then grows with the row: Domino X, s/h 0.52,
    /// 100 blocks, took 90 s at 10⁻³ and 5.4 s at 10⁻², v̂_na within 0.2 %
    /// over 10⁻⁴ … 3·10⁻² (docs/reference-performance.md).
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
    /// Resolver steps after which an impact that has e = 0 contacts and is
    /// still running under the paper's release-and-reload law is solved again
    /// with those contacts held closed (the limit of those cycles; counted as
    /// `held_impacts`). Set it to `impact.max_steps` to give the paper's law
    /// every step. With the adaptive impulse stepping, the default before the
    /// time-domain resolver, 2·10⁴ changed v̂_na by 2·10⁻⁴ against waiting for
    /// the full step limit (ideal T, s/h 0.3, 60 blocks) and ran 4× faster;
    /// the time-domain resolver takes the fast cycles by their limit itself
    /// ([`crate::impact::ImpactSettings::fast_cycle`]) and rarely gets here.
    pub held_retry_after: usize,
    /// Stop as soon as the last block is struck (the wave measures are then
    /// complete), or [`Settings::after_last_hit`] later; otherwise run until
    /// every block is at rest (default true).
    pub stop_at_last_hit: bool,
    /// With `stop_at_last_hit`, run on this long (s) after the last block is
    /// struck: the last blocks fall and the row settles into its pile
    /// (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub after_last_hit: f64,
    /// Stop after this much wall-clock time (s), keeping what was measured
    /// (the report's `stopped_early` is then true); default: no limit.
    pub wall_time_limit: Option<f64>,
    /// Stop after this much CPU time (s) of the thread that runs it, keeping
    /// what was measured (`stopped_early` is then true): unlike
    /// [`Settings::wall_time_limit`], other programs on a loaded machine do
    /// not use it up; default: no limit. (CPU time where the system has a
    /// per-thread CPU clock, Unix; elsewhere wall-clock time.)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_time_limit: Option<f64>,
    /// Stop after this many accepted integration steps, keeping what was
    /// measured (`stopped_early` is then true): a bound on a run's work
    /// that, unlike [`Settings::wall_time_limit`], ends a run at the same
    /// point on an idle and a loaded machine; default: no limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<usize>,
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
            approach_tolerance: Self::APPROACH_TOLERANCE,
            freeze_tolerance: Self::FREEZE_TOLERANCE,
            event_time_tolerance: 1e-10,
            heel_contacts: false,
            held_retry_after: 20_000,
            stop_at_last_hit: true,
            after_last_hit: 0.0,
            wall_time_limit: None,
            cpu_time_limit: None,
            max_steps: None,
            t_max: None,
            series_blocks: Vec::new(),
            series_interval: 0.0,
            snapshot_times: Vec::new(),
        }
    }
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl Settings {
    /// The default freeze tolerance (see [`Settings::freeze_tolerance`]).
    pub const FREEZE_TOLERANCE: f64 = 1e-2;

    /// The default approach tolerance (see [`Settings::approach_tolerance`]),
    /// a fraction of √(gh).
    ///
    /// It was 10⁻⁶ (round-off level). The impacts of the Table 1 rows'
    /// leaning trains then ran until nothing in a group of 30–70 contact
    /// points approached faster than 5·10⁻⁷ √(gh): hundreds of resolver steps
    /// each, most of them in the slow tail of the wave running back and
    /// forth along the train. At 10⁻⁴ the rows of docs/reference-performance.md
    /// ("Round nine") run 1.1–3 times faster and their v̂_na stays within
    /// 2·10⁻⁴ (relative) of runs at 10⁻⁷ with the resolver at 10⁻⁸, below the
    /// 0.1 % the defaults are held to; an approach slower than 10⁻⁴ √(gh)
    /// is a tenth of the separations the engine already stops
    /// (`velocity_tolerance`, 10⁻³).
    ///
    /// ```
    /// use topple::reference::Settings;
    /// assert_eq!(Settings::default().approach_tolerance, Settings::APPROACH_TOLERANCE);
    /// ```
    pub const APPROACH_TOLERANCE: f64 = 1e-4;

    /// The defaults with the paper's fixed impulse step ΔP = 10⁻⁴ P₀
    /// (Sec. 3.1) in the impacts, named here rather than taken from the
    /// resolver's default so that it stays the paper's whatever that
    /// default becomes.
    pub fn paper_impacts() -> Self {
        let mut s = Self::default();
        s.impact.step_control = crate::impact::StepControl::paper();
        s
    }

    /// The accurate integration: adaptive Dormand–Prince at `tolerance` for
    /// the smooth phase; impacts as in the defaults.
    pub fn accurate(tolerance: f64) -> Self {
        Settings {
            integrator: Integrator::Adaptive { tolerance },
            ..Default::default()
        }
    }
}
