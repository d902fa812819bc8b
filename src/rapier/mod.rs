//! The plugin for Rapier: LZB impacts and λ-point contact inside a Rapier
//! world. One adapter source, compiled for `rapier2d-f64` ([`f64`](mod@f64)) and for
//! `rapier2d` ([`f32`](mod@f32), what `bevy_rapier2d` uses), as Rapier builds its two
//! crates from one source.
//!
//! | item | role | precision |
//! | --- | --- | --- |
//! | [`f64::ToppleRapier`], [`f32::ToppleRapier`] | the adapter: Rapier step, impact pass, velocities back | per build |
//! | [`f64::ToppleHooks`], [`f32::ToppleHooks`] | physics hook: per-pair friction, Rapier's restitution off on managed pairs | per build |
//! | [`ImpactResponse`], [`ToppleStats`], [`Precision`], [`LeftToRapier`] | who resolves impacts, running totals, which build, why a collider's impacts are Rapier's | agnostic |
//! | [`scene`] | TOML scenes (boxes, balls, domino rows) run with or without topple, in either precision | agnostic front, per-build worlds |
//!
//! Materials, λ-point patches, impact groups and the fallback policy live in
//! [`crate::coupling`]; the adapter only reads Rapier's state into plain f64
//! data and writes velocities back.
//!
//! # Impacts at their instant
//!
//! A game steps Rapier at 1/60 s, and a falling domino's corner moves 2.5 cm
//! in such a step across a 3.6 cm gap; an impact found at the end of the
//! step would be resolved late and deep, at positions the bodies never had
//! together. The adapter resolves each impact at the instant its pair closes
//! and splits Rapier's step there:
//!
//! 1. before the step it records the awake poses and predicts the first
//!    closing of the pairs the fast bodies may reach (a swept box against
//!    Rapier's broad phase, the gap along straight paths at the present
//!    velocities);
//! 2. Rapier steps to that instant with topple's hook, which takes from
//!    Rapier's solver the contact points approaching faster than the impact
//!    threshold (unless they belong to a lasting contact) and notes their
//!    pairs;
//! 3. the pass after the step finds each candidate's first closing time τ on
//!    the straight paths between the two poses of the step, builds the group
//!    at the poses of τ, resolves it through [`crate::coupling`], moves the
//!    changed bodies on from τ with their new velocities, repeats, and writes
//!    velocities and poses back;
//! 4. Rapier steps on to the next predicted instant or the end of the step
//!    (at most [`crate::coupling::ToppleSettings::max_splits`] splits).
//!
//! The alternative, sub-stepping only the bodies of an impact while Rapier
//! steps the rest, would need a second contact solver for those bodies;
//! splitting keeps Rapier's smooth phase for everything and costs one more
//! Rapier step per impact. Why splitting matters as much as the instant:
//! after the impact the smooth forces (the blocks leaning on the struck one)
//! act on the post-impact velocities from τ on (ideal Domino T row, s/h 0.45,
//! 1/60 s, reference engine 1.78: at the end of the step v̂_na 1.03, at the
//! instant 1.55, at the instant with splitting 1.71; see
//! `docs/game-rate.md`). ARCHITECTURE.md walks through the whole path.
//!
//! # Precision
//!
//! The adapter reads Rapier's poses and velocities (f32 or f64) into f64, and
//! the resolver, the time-of-impact search and the groups work in f64 in both
//! builds; only what is written back is rounded to the build's precision. The
//! f32 build therefore carries Rapier's own f32 error: positions to about
//! 10⁻⁷ of their magnitude (0.1 µm at 1 m from the origin), velocities to
//! 10⁻⁷ relative per write. What the tests hold each build to:
//!
//! | check | f64 | f32 |
//! | --- | --- | --- |
//! | impact inside a step vs the closed form (`tests/rapier/game_rate.rs`) | 10⁻⁸ m/s | 2·10⁻⁵ m/s |
//! | box cradle at 1/60 s, momentum and energy | 10⁻⁶ relative | 10⁻⁶ relative |
//! | ideal Domino T row at 1/60 s, v̂_na | within 6 % of the reference | within 1 % of f64 |

#[cfg(feature = "f32")]
pub mod f32;
#[cfg(feature = "f64")]
pub mod f64;
pub mod scene;

use serde::{Deserialize, Serialize};

use crate::coupling::{ImpactReport, Resolution};

/// Natural frequency (Hz) of Rapier's soft contacts that domino rows use
/// (Rapier's default is 30 Hz; fixed pairs get twice the value). topple's
/// model keeps contacts rigid between impacts; at Rapier's default a row of
/// leaning blocks at a game step is spongy: the blocks leaning on the struck
/// one push it too weakly and re-touch it in many small impacts (ideal
/// Domino T, s/h 0.45, 100 blocks, measured in `docs/game-rate.md`: topple
/// at 1/60 s 1.53 against 1.64 at 480 Hz, reference 1.78; native Rapier 1.32
/// and 1.46). Both engines of a row comparison use the same value.
pub const ROW_CONTACT_HERTZ: f64 = 480.0;

/// Who resolves the impacts: topple (the LZB model with λ-point contact) or
/// Rapier itself (its own restitution per pair). One choice for every layer:
/// a Rapier world's hooks, a scene run, a domino row, the Bevy plugin's
/// default context and its rows, the CLI and the stress sweep. On the command
/// line and in JSON reports its values are `rapier` (topple on Rapier) and
/// `rapier-native`.
///
/// ```
/// use topple::coupling::ToppleSettings;
/// use topple::rapier::{f64::ToppleRapier, ImpactResponse};
/// assert_eq!(ToppleRapier::new(ToppleSettings::default()).hooks().mode(), ImpactResponse::Topple);
/// assert_eq!(ToppleRapier::native().hooks().mode(), ImpactResponse::Native);
/// assert_eq!(ImpactResponse::Native.name(), "rapier-native");
/// assert_eq!(ImpactResponse::default(), ImpactResponse::Topple);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[cfg_attr(feature = "bevy", derive(bevy::prelude::Resource))]
pub enum ImpactResponse {
    /// topple resolves impacts; Rapier keeps resting contact with restitution 0
    /// and without the contact points that are still open (speculative) or
    /// approach faster than topple's impact threshold: Rapier would stop those
    /// inelastically at the moment of touching, before topple sees them.
    #[default]
    #[serde(rename = "rapier")]
    #[cfg_attr(feature = "cli", value(name = "rapier"))]
    Topple,
    /// Rapier resolves impacts itself with the pair's restitution; the hook
    /// only sets friction and restitution per pair (native Rapier response).
    #[serde(rename = "rapier-native")]
    #[cfg_attr(feature = "cli", value(name = "rapier-native"))]
    Native,
}

impl ImpactResponse {
    /// The name used on the command line and in JSON: `rapier` or
    /// `rapier-native`.
    pub fn name(self) -> &'static str {
        match self {
            ImpactResponse::Topple => "rapier",
            ImpactResponse::Native => "rapier-native",
        }
    }
}

/// Which Rapier build runs a world. Each is compiled only with its cargo
/// feature (`f32`, `f64`); running on one that is not compiled gives
/// [`scene::SceneError::NotBuilt`].
///
/// ```
/// use topple::rapier::Precision;
/// // f64 when it is compiled (the default features compile both)
/// assert_eq!(Precision::default(), Precision::F64);
/// assert!(Precision::F32.is_built() && Precision::F64.is_built());
/// assert_eq!(Precision::F32.name(), "f32");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// `rapier2d` (f32), the build `bevy_rapier2d` uses.
    F32,
    /// `rapier2d-f64`.
    F64,
}

impl Default for Precision {
    /// [`Precision::F64`] when it is compiled, else [`Precision::F32`].
    fn default() -> Self {
        if cfg!(feature = "f64") || !cfg!(feature = "f32") {
            Precision::F64
        } else {
            Precision::F32
        }
    }
}

impl Precision {
    /// Whether this build of topple compiles this Rapier build (cargo
    /// features `f32` and `f64`).
    pub fn is_built(self) -> bool {
        match self {
            Precision::F32 => cfg!(feature = "f32"),
            Precision::F64 => cfg!(feature = "f64"),
        }
    }

    /// The name used on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }
}

/// Running totals of an adapter over all its impact passes.
///
/// ```
/// use topple::coupling::ToppleSettings;
/// use topple::rapier::f64::ToppleRapier;
/// assert_eq!(ToppleRapier::new(ToppleSettings::default()).stats().impacts, 0);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ToppleStats {
    /// Candidate pairs queried at the current positions.
    pub pairs_queried: u64,
    /// Closed contact points found (λ points counted one by one).
    pub contact_points: u64,
    /// Impacts resolved (every resolution below).
    pub impacts: u64,
    /// Resolver impulse steps, summed (plastic sweeps included).
    pub impulse_steps: u64,
    /// Impacts solved again with their e = 0 contacts held closed.
    pub held_impacts: u64,
    /// Impacts resolved as plastic (the last stage of the fallback policy).
    pub plastic_fallbacks: u64,
    /// Impact groups with invalid data (non-finite state), left unresolved.
    pub rejected_impacts: u64,
    /// Rapier steps split at a predicted impact instant.
    pub split_steps: u64,
    /// Rapier steps taken (sub-steps and split pieces counted one by one).
    #[serde(skip)]
    pub rapier_steps: u64,
    /// Work of the LZB resolver: impulse steps (accepted and rejected)
    /// times each impact's contact points, the unit of the step budget
    /// ([`crate::coupling::FallbackPolicy::max_work`]).
    pub work: u64,
    /// Steps whose work budget ran out: the impact that ran out was
    /// finished by the fallback policy and the rest of the step was native
    /// Rapier.
    pub budget_spent: u64,
    /// Managed pairs that approached faster than the impact threshold and got
    /// Rapier's own response instead of topple's: pairs topple leaves to
    /// Rapier ([`LeftToRapier`]) and pairs met after the step's budget ran
    /// out.
    pub native_impacts: u64,
    /// Wall time spent in topple's own work, Rapier's step excluded (s).
    /// Not serialized: outputs stay the same bits from run to run.
    #[serde(skip)]
    pub topple_seconds: f64,
    /// Impacts solved side by side with others of the same step: groups
    /// applied from batches of two or more instants (docs/bevy.md,
    /// "Independent impacts side by side"). Not serialized: how the work
    /// was shared out, not what it gave.
    #[serde(skip)]
    pub batched_impacts: u64,
    /// Batch items solved again, one after another, because the budget the
    /// impacts before them spent might have changed their result.
    #[serde(skip)]
    pub batch_resolves: u64,
}

impl ToppleStats {
    /// Adds the impacts of one pass.
    pub fn record(&mut self, reports: &[ImpactReport]) {
        for r in reports {
            self.impacts += 1;
            self.impulse_steps += r.steps as u64;
            match r.resolution {
                Resolution::Lzb => {}
                Resolution::Held => self.held_impacts += 1,
                Resolution::Plastic => self.plastic_fallbacks += 1,
                Resolution::Rejected => self.rejected_impacts += 1,
            }
        }
    }
}

/// Why topple leaves a managed collider's impacts to Rapier's own contact
/// solver (with the pair's friction and restitution, as native Rapier).
///
/// ```
/// use topple::rapier::LeftToRapier;
/// assert_eq!(LeftToRapier::Sensor.to_string(), "a sensor never touches anything");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LeftToRapier {
    /// The shape has no contact manifold topple can read (parry's voxels, a
    /// custom shape); its name is given.
    Shape(&'static str),
    /// A sensor never touches anything.
    Sensor,
    /// Its body moves but no impulse can move it: kinematic, or dynamic with
    /// zero mass (at rest such a body is a wall).
    Driven,
    /// Its dynamic body has one translation axis locked, or both locked but
    /// its rotation free: the resolver's bodies have one mass for both axes.
    LockedAxes,
    /// Two free bodies of different dominance groups (Rapier gives the
    /// dominant one infinite mass against the other).
    Dominance,
}

impl std::fmt::Display for LeftToRapier {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LeftToRapier::Shape(name) => {
                write!(f, "shape {name} has no contact manifold topple reads")
            }
            LeftToRapier::Sensor => write!(f, "a sensor never touches anything"),
            LeftToRapier::Driven => write!(
                f,
                "its body moves but no impulse can move it (kinematic or zero mass)"
            ),
            LeftToRapier::LockedAxes => write!(f, "its body has a translation axis locked"),
            LeftToRapier::Dominance => write!(f, "it meets a body of another dominance group"),
        }
    }
}
