//! Settings of the impact pass an engine runs at impact events.

use crate::impact::ImpactSettings;

use super::fallback::FallbackPolicy;
use super::patch::PatchRule;

/// Settings of the impact pass.
///
/// The default resolves impacts with the time-domain resolver
/// ([`ImpactSettings::adaptive`], docs/model.md §7) at a relative tolerance
/// of 10⁻⁶: the domino rows of docs/game-rate.md at 1/60 s read their wave
/// speed within 0.05 % of a run at 10⁻¹⁰ (means over nearby starts), an
/// elastic cradle keeps its energy to 10⁻⁶ in one step, and impacts take
/// up to a quarter fewer steps than at 2·10⁻⁷, the default before
/// (docs/impact.md, "Steps per impact, round ten"); set `impact` to
/// [`ImpactSettings::fixed`] for the paper's scheme.
///
/// ```
/// use topple::coupling::ToppleSettings;
/// use topple::impact::ImpactSettings;
/// let s = ToppleSettings::default();
/// assert_eq!(s.patch.lambda, 9);
/// assert_eq!(s.impact, ImpactSettings::adaptive(1e-6));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToppleSettings {
    /// Settings handed to the LZB resolver (default: the time-domain
    /// resolver at 10⁻⁶; [`ImpactSettings::adaptive_impulse`] and
    /// [`ImpactSettings::fixed`] give the impulse stepping).
    pub impact: ImpactSettings,
    /// Which manifold points are closed and how flat patches are subdivided.
    pub patch: PatchRule,
    /// A new closed contact starts an impact when it approaches faster than
    /// this (m/s). Slower approaches are left to the engine's contact solver.
    /// Keep it above about 2|g|Δt, the approach a resting contact picks up in
    /// one step. (The Rapier adapter reads this and the patch's lengths per
    /// length unit and never goes below 2|g|Δt: `crate::rapier`, "Units".)
    pub min_approach_speed: f64,
    /// The window of an impact: only free bodies within this many closed
    /// contacts of the bodies that started it take part, and contacts with
    /// bodies beyond are left out (like the paper's active window κ). `None`:
    /// the whole connected group. Default [`ToppleSettings::DEFAULT_WINDOW`].
    pub max_group_hops: Option<usize>,
    /// What happens to an impact the LZB law cannot finish. Its `max_work`
    /// is the Rapier adapter's budget for one step, shared by the step's
    /// impacts (default [`ToppleSettings::DEFAULT_STEP_WORK`]).
    pub fallback: FallbackPolicy,
    /// An engine adapter splits its step at the predicted instant of an
    /// impact, at most this many times per step (0: never), so that the
    /// smooth forces after the impact act on the post-impact velocities.
    pub max_splits: usize,
    /// An engine adapter takes a step longer than this (s) as equal
    /// sub-steps no longer than it, each split at its impacts as above;
    /// `None`: one step as given. At a game's 1/60 s the engine's smooth
    /// phase is otherwise the larger error (a domino topples onto its
    /// neighbour in about three such steps): with four sub-steps per 1/60 s
    /// frame the ideal Domino T row at s/h 0.45 goes from −3.8 % to −1.1 %
    /// against the reference engine, at the same cost per frame, because
    /// the impacts dominate the cost and the impact threshold stays the
    /// frame's (docs/game-rate.md). Default 1/240 s.
    pub max_substep: Option<f64>,
    /// What is left of an impact once everything in it is slower than this
    /// fraction of the impact threshold (`min_approach_speed`, in the
    /// world's units) is the engine's: the resolver ends there
    /// ([`ImpactSettings::rest_speed`] = `rest_fraction` ·
    /// `min_approach_speed`; docs/model.md §9). Contacts that approach
    /// slower than the threshold are the engine's resting contacts at the
    /// start of a step; the impact's tail is left to them at a hundredth of
    /// that speed. 0: every impact runs to its end under the paper's law
    /// (a box landing on a resting pile then sloshes for seconds of the
    /// impact's own time). Default [`ToppleSettings::DEFAULT_REST_FRACTION`].
    pub rest_fraction: f64,
}

impl ToppleSettings {
    /// The default impact window (closed contacts from the bodies that start
    /// an impact): a cradle of five bodies is whole, and the leaning train
    /// behind a domino front takes part with its three nearest blocks (on
    /// the ideal Domino T row, s/h 0.45, at 1/60 s: v̂_na 1.685, 1.711,
    /// 1.714, 1.705 for windows 1 to 4, at cost 1 : 0.9 : 1.1 : 1.4;
    /// docs/game-rate.md).
    pub const DEFAULT_WINDOW: usize = 3;

    /// The default work budget of one engine step (LZB impulse steps times
    /// contact points, [`FallbackPolicy::max_work`]), measured in
    /// docs/bevy.md ("Bounded frames").
    pub const DEFAULT_STEP_WORK: u64 = 50_000;

    /// The default [`ToppleSettings::rest_fraction`].
    pub const DEFAULT_REST_FRACTION: f64 = 0.01;

    /// How many equal sub-steps an engine adapter takes a step of `dt` (s)
    /// in ([`ToppleSettings::max_substep`]): ⌈dt / max_substep⌉, at most
    /// 1,000, and 1 without a sub-step or when the step is no longer. The
    /// quotient is taken with a relative allowance of 10⁻⁶, above the
    /// rounding of Δt in an f32 build (1/60 s as f32 over 1/240 s is
    /// 4.0000002), so that 1/60 over 1/240 is 4, not 5, in both builds.
    ///
    /// ```
    /// use topple::coupling::ToppleSettings;
    /// let s = ToppleSettings::default(); // 1/240 s
    /// assert_eq!(s.substeps(1.0 / 60.0), 4);
    /// assert_eq!(s.substeps(f64::from(1.0f32 / 60.0)), 4);
    /// assert_eq!(s.substeps(1.0 / 100.0), 3);
    /// assert_eq!(s.substeps(1.0 / 300.0), 1);
    /// ```
    pub fn substeps(&self, dt: f64) -> usize {
        match self.max_substep {
            Some(h) if h > 0.0 && dt > h => ((dt / h) * (1.0 - 1e-6)).ceil().min(1e3) as usize,
            _ => 1,
        }
    }

    /// The resolver's settings for an impact under these settings: `impact`
    /// with its rest speed raised to `rest_fraction · min_approach_speed`.
    ///
    /// ```
    /// use topple::coupling::ToppleSettings;
    /// let s = ToppleSettings { min_approach_speed: 0.3, ..ToppleSettings::default() };
    /// assert_eq!(s.impact_settings().rest_speed, 0.3 * ToppleSettings::DEFAULT_REST_FRACTION);
    /// let exact = ToppleSettings { rest_fraction: 0.0, ..s };
    /// assert_eq!(exact.impact_settings().rest_speed, 0.0);
    /// ```
    pub fn impact_settings(&self) -> ImpactSettings {
        let floor = self.rest_fraction * self.min_approach_speed;
        ImpactSettings {
            rest_speed: if floor > 0.0 && floor.is_finite() {
                self.impact.rest_speed.max(floor)
            } else {
                self.impact.rest_speed
            },
            ..self.impact
        }
    }
}

impl Default for ToppleSettings {
    fn default() -> Self {
        ToppleSettings {
            impact: ImpactSettings::adaptive(1e-6),
            patch: PatchRule::default(),
            min_approach_speed: 1e-3,
            max_group_hops: Some(Self::DEFAULT_WINDOW),
            fallback: FallbackPolicy {
                max_work: Some(Self::DEFAULT_STEP_WORK),
                ..FallbackPolicy::default()
            },
            max_splits: 4,
            max_substep: Some(1.0 / 240.0),
            rest_fraction: Self::DEFAULT_REST_FRACTION,
        }
    }
}
