//! The TOML scene format (serde). Units: m, kg, s, rad. See docs/scenes.md
//! section "Rapier plugin (`topple scene`)" for a commented example.

use serde::{Deserialize, Serialize};

/// A whole scene.
///
/// ```
/// let scene: topple::rapier::scene::Scene = toml::from_str(r#"
///     duration = 1.0
///     [[materials]]
///     name = "steel"
///     stiffness = 1e10
///     [[bodies]]
///     shape = "ball"
///     radius = 0.05
///     position = [0.0, 1.0]
///     material = "steel"
/// "#).unwrap();
/// assert_eq!(scene.bodies.len(), 1);
/// assert_eq!(scene.gravity, [0.0, -9.81]);
/// ```
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// What the scene shows (free text).
    #[serde(default)]
    pub description: String,
    /// Simulated time (s).
    pub duration: f64,
    /// Gravity (m/s²).
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 2],
    /// Integrator and impact-solver settings.
    #[serde(default)]
    pub solver: SolverSpec,
    /// Materials by name.
    #[serde(default)]
    pub materials: Vec<MaterialSpec>,
    /// Per-pair overrides.
    #[serde(default)]
    pub pairs: Vec<PairSpec>,
    /// A fixed ground (top face at `y`).
    #[serde(default)]
    pub ground: Option<GroundSpec>,
    /// Bodies.
    #[serde(default)]
    pub bodies: Vec<BodySpec>,
    /// A generated domino row (adds its blocks, materials, pair rules and ground).
    #[serde(default)]
    pub row: Option<RowSection>,
}

fn default_gravity() -> [f64; 2] {
    [0.0, -9.81]
}

/// Time stepping and impact resolution.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSpec {
    /// Rapier time step (s).
    pub dt: f64,
    /// Rapier's length unit (m): scales its allowed penetration (0.005 of
    /// it), prediction distance (0.02 of it) and corrective velocities; set it
    /// to a typical body size. Default: a row's block height for a scene with
    /// a row, else 1 m (Rapier's default).
    pub length_unit: Option<f64>,
    /// Natural frequency (Hz) of Rapier's soft contacts between dynamic
    /// bodies (twice that against fixed bodies). Default: Rapier's 30 Hz,
    /// and [`crate::rapier::ROW_CONTACT_HERTZ`] for a scene with a row.
    pub contact_hertz: Option<f64>,
    /// Rapier solver iterations per step.
    pub iterations: usize,
    /// Rapier's contact recycling (pairs with hooks are never recycled).
    pub contact_recycling: bool,
    /// The paper's fixed impulse step ΔP/P₀ of the LZB resolver (10⁻⁴ in
    /// the paper), if set and `tolerance` is not.
    pub impulse_step: Option<f64>,
    /// The time-domain resolver at this relative tolerance; when neither
    /// this nor `impulse_step` is set, the default of
    /// [`crate::coupling::ToppleSettings`] (this resolver at 10⁻⁶).
    pub tolerance: Option<f64>,
    /// λ points across a flat contact patch.
    pub lambda: usize,
    /// Approach speed (m/s) above which a new closed contact starts an
    /// impact; default 10⁻³. Never below 2|g|Δt, the approach a resting
    /// contact picks up in one step.
    pub min_approach_speed: Option<f64>,
    /// Impact window: bodies more than this many closed contacts away from
    /// the impact and their contacts are left out (default
    /// [`crate::coupling::ToppleSettings::DEFAULT_WINDOW`]).
    pub max_group_hops: Option<usize>,
    /// Rapier steps split at predicted impact instants, at most, per step
    /// (default 4; 0 never splits).
    pub max_splits: Option<usize>,
    /// The impact ends once what is left of it is slower than this fraction
    /// of the impact threshold ([`crate::coupling::ToppleSettings::rest_fraction`];
    /// default 0.01, 0: every impact runs to its end).
    pub rest_fraction: Option<f64>,
    /// Steps longer than this (s) are taken as equal sub-steps no longer
    /// than it ([`crate::coupling::ToppleSettings::max_substep`], default
    /// 1/240 s); 0: never sub-step. Native Rapier never sub-steps.
    pub max_substep: Option<f64>,
    /// Gap (m) at or below which a contact point is closed.
    pub closed_tolerance: f64,
    /// Work budget of one step, shared by the step's impacts
    /// ([`WorkBudget`]): by default a game's bounded step,
    /// [`crate::coupling::ToppleSettings::DEFAULT_STEP_WORK`]; `"none"`
    /// runs every impact to its end (accuracy runs).
    pub max_work: WorkBudget,
}

/// The work budget of one Rapier step for the impacts in it: LZB impulse
/// steps (accepted and rejected) times each impact's contact points
/// ([`crate::coupling::FallbackPolicy::max_work`]). Counted in work, not in
/// time, so that a run gives the same bits on any machine and under any
/// load. Once a step's budget is spent, the impact that ran out is finished
/// by the fallback policy (the held retry, at the latest a plastic solve:
/// the group's contacts end the impact closing, e = 0, no energy created)
/// and the rest of the step is native Rapier (docs/bevy.md, "Bounded
/// frames"). In TOML: a number, or `"none"`.
///
/// ```
/// use topple::coupling::ToppleSettings;
/// use topple::rapier::scene::{SolverSpec, WorkBudget};
/// let s: SolverSpec = toml::from_str("").unwrap();
/// assert_eq!(s.max_work.max_work(), Some(ToppleSettings::DEFAULT_STEP_WORK));
/// let s: SolverSpec = toml::from_str("max_work = 20000").unwrap();
/// assert_eq!(s.max_work, WorkBudget::Work(20_000));
/// let s: SolverSpec = toml::from_str(r#"max_work = "none""#).unwrap();
/// assert_eq!(s.max_work, WorkBudget::Unbounded);
/// assert!(toml::from_str::<SolverSpec>(r#"max_work = "lots""#).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "BudgetText", into = "BudgetText")]
pub enum WorkBudget {
    /// At most this much work per step.
    Work(u64),
    /// No bound: every impact runs to its end however long it takes (the
    /// researcher's runs and the CLI's accuracy runs).
    Unbounded,
}

impl Default for WorkBudget {
    /// A game's bounded step, [`crate::coupling::ToppleSettings::DEFAULT_STEP_WORK`].
    fn default() -> Self {
        WorkBudget::Work(crate::coupling::ToppleSettings::DEFAULT_STEP_WORK)
    }
}

impl WorkBudget {
    /// As [`crate::coupling::FallbackPolicy::max_work`] takes it (`None`:
    /// unbounded).
    pub fn max_work(self) -> Option<u64> {
        match self {
            WorkBudget::Work(w) => Some(w),
            WorkBudget::Unbounded => None,
        }
    }
}

/// How a [`WorkBudget`] is written: a number or the word `"none"`.
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum BudgetText {
    Work(u64),
    Word(String),
}

impl TryFrom<BudgetText> for WorkBudget {
    type Error = String;
    fn try_from(t: BudgetText) -> Result<Self, String> {
        match t {
            BudgetText::Work(w) => Ok(WorkBudget::Work(w)),
            BudgetText::Word(w) if w == "none" => Ok(WorkBudget::Unbounded),
            BudgetText::Word(w) => Err(format!(
                "max_work = \"{w}\": a number of work units or \"none\""
            )),
        }
    }
}

impl From<WorkBudget> for BudgetText {
    fn from(b: WorkBudget) -> Self {
        match b {
            WorkBudget::Work(w) => BudgetText::Work(w),
            WorkBudget::Unbounded => BudgetText::Word("none".into()),
        }
    }
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            dt: 1e-3,
            length_unit: None,
            contact_hertz: None,
            max_splits: None,
            rest_fraction: None,
            iterations: 4,
            contact_recycling: true,
            impulse_step: None,
            tolerance: None,
            lambda: 9,
            min_approach_speed: None,
            max_group_hops: None,
            max_substep: None,
            closed_tolerance: 1e-9,
            max_work: WorkBudget::default(),
        }
    }
}

/// A named material: contact law for impacts, friction for both phases.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Name used by bodies and pairs.
    pub name: String,
    /// Contact stiffness k (N/m^α); only ratios matter.
    pub stiffness: f64,
    /// Exponent α of F = k δ^α.
    #[serde(default = "default_exponent")]
    pub exponent: f64,
    /// Energetic restitution e ∈ [0, 1].
    #[serde(default = "one")]
    pub restitution: f64,
    /// Sliding friction μ of the smooth phase.
    #[serde(default)]
    pub friction: f64,
    /// Sticking friction μ_s inside impacts.
    #[serde(default)]
    pub stick_friction: f64,
    /// Factor on μ inside impacts (the paper's presets: 0.5).
    #[serde(default = "one")]
    pub impact_friction_factor: f64,
}

impl MaterialSpec {
    /// The material's law against itself (never no-slip): what a pair of
    /// two bodies of this material takes unless a pair rule says otherwise.
    ///
    /// ```
    /// use topple::rapier::scene::MaterialSpec;
    /// let m: MaterialSpec = toml::from_str("name = \"wood\"\nstiffness = 1e8\nrestitution = 0.3").unwrap();
    /// let law = m.law();
    /// assert_eq!((law.stiffness, law.restitution, law.exponent), (1e8, 0.3, 1.5));
    /// assert!(!law.no_slip);
    /// ```
    pub fn law(&self) -> PairLaw {
        PairLaw {
            stiffness: self.stiffness,
            exponent: self.exponent,
            restitution: self.restitution,
            friction: self.friction,
            stick_friction: self.stick_friction,
            impact_friction_factor: self.impact_friction_factor,
            no_slip: false,
        }
    }
}

fn default_exponent() -> f64 {
    1.5
}
fn one() -> f64 {
    1.0
}

/// A pair rule: the material between two named materials.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairSpec {
    /// The two material names (either order).
    pub materials: [String; 2],
    /// The law between them (its `name` is ignored).
    #[serde(flatten)]
    pub law: PairLaw,
}

/// The law of a pair rule.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PairLaw {
    /// Contact stiffness k (N/m^α).
    pub stiffness: f64,
    /// Exponent α.
    #[serde(default = "default_exponent")]
    pub exponent: f64,
    /// Restitution e.
    #[serde(default = "one")]
    pub restitution: f64,
    /// Sliding friction μ.
    #[serde(default)]
    pub friction: f64,
    /// Sticking friction μ_s.
    #[serde(default)]
    pub stick_friction: f64,
    /// Factor on μ inside impacts.
    #[serde(default = "one")]
    pub impact_friction_factor: f64,
    /// The pair never slides (a no-slip ground): unbounded friction inside
    /// impacts and [`crate::rapier::scene::NO_SLIP_FRICTION`] in Rapier's
    /// smooth phase; `friction`, `stick_friction` and
    /// `impact_friction_factor` are then not used.
    #[serde(default)]
    pub no_slip: bool,
}

/// The ground: a fixed slab whose top face is at height `y`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundSpec {
    /// Height of the top face (m).
    #[serde(default)]
    pub y: f64,
    /// Material name.
    pub material: String,
}

/// Shape of a body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    /// A rectangle of `size` = [width, height].
    Box,
    /// A disc of `radius`.
    Ball,
}

/// One body.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Name in the output (default: its index).
    #[serde(default)]
    pub name: Option<String>,
    /// Box or ball.
    pub shape: ShapeKind,
    /// Box full size [width, height] (m).
    #[serde(default)]
    pub size: Option<[f64; 2]>,
    /// Ball radius (m).
    #[serde(default)]
    pub radius: Option<f64>,
    /// Centre (m).
    pub position: [f64; 2],
    /// Angle (rad, counter-clockwise).
    #[serde(default)]
    pub angle: f64,
    /// Velocity of the centre (m/s).
    #[serde(default)]
    pub velocity: [f64; 2],
    /// Angular velocity (rad/s, counter-clockwise).
    #[serde(default)]
    pub angular_velocity: f64,
    /// Density (kg/m², per unit depth); default 1000 unless `mass` is given.
    #[serde(default)]
    pub density: Option<f64>,
    /// Mass (kg); overrides density.
    #[serde(default)]
    pub mass: Option<f64>,
    /// A fixed body never moves.
    #[serde(default)]
    pub fixed: bool,
    /// Material name.
    pub material: String,
}

/// A scene file's `[row]` section: a domino row on the ground (paper
/// Sec. 3), blocks standing at spacing s, the first pushed about its front
/// bottom edge. [`row_params`](super::row_params) turns it into the
/// [`crate::domino::RowParams`] of a [`crate::domino::RowSpec`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RowSection {
    /// Table 1 preset: "X", "T" or "P".
    pub preset: String,
    /// Number of blocks.
    pub n: usize,
    /// Spacing s/h (gap between faces over height).
    pub spacing: f64,
    /// Push: the first block's dimensionless angular velocity θ̇₁ t̄ about its
    /// front bottom edge, t̄ = √(h/g).
    #[serde(default = "one")]
    pub push: f64,
    /// The ideal parameters μ₁ = 0, e₁ = 0, μ₂ = 0.9, e₂ = 0 (paper Fig. 5).
    #[serde(default)]
    pub ideal: bool,
    /// Block density (kg/m² per unit depth).
    #[serde(default = "default_density")]
    pub density: f64,
    /// Block mass (kg); overrides density.
    #[serde(default)]
    pub mass: Option<f64>,
    /// The ground under the feet: `"coulomb"` (the paper's friction μ₂,
    /// default) or `"no-slip"` (pivots never slide; the cooperative model's
    /// assumption).
    #[serde(default)]
    pub ground: crate::domino::Ground,
    /// Overrides of the preset (applied after `ideal`).
    #[serde(default, flatten)]
    pub overrides: RowOverrides,
}

/// Values that replace the preset's (Table 1) in a row.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RowOverrides {
    /// Block height h (m).
    pub height: Option<f64>,
    /// Block thickness d (m).
    pub thickness: Option<f64>,
    /// Sliding friction between blocks μ₁ (sets μ₁ˢ too unless given).
    pub mu1: Option<f64>,
    /// Sticking friction between blocks μ₁ˢ.
    pub mu1_stick: Option<f64>,
    /// Restitution between blocks e₁.
    pub e1: Option<f64>,
    /// Stiffness between blocks k₁ (N/m^α).
    pub k1: Option<f64>,
    /// Sliding friction with the ground μ₂ (sets μ₂ˢ too unless given).
    pub mu2: Option<f64>,
    /// Sticking friction with the ground μ₂ˢ.
    pub mu2_stick: Option<f64>,
    /// Restitution with the ground e₂.
    pub e2: Option<f64>,
    /// Stiffness with the ground k₂ (N/m^α).
    pub k2: Option<f64>,
    /// Exponent α of the contact law (1.5).
    pub alpha: Option<f64>,
    /// Factor on μ inside impacts (0.5).
    pub impact_friction_factor: Option<f64>,
}

fn default_density() -> f64 {
    1000.0
}
