//! Closed-form and iterative models of the domino wave's natural speed, the
//! lines the paper compares its simulations with (Sec. 3.2, Fig. 5). Formulas
//! from docs/theory.md (section names cited in each file); the single
//! collision model, which docs/theory.md gives only in words, is derived in
//! `single.rs` and summarised below.
//!
//! | file | concept |
//! | --- | --- |
//! | `geometry.rs` | [`Geometry`]: d/h, s/h, pitch, θ_c, θ_∞, the leaning-pair map, gravity torque |
//! | `train.rs` | the leaning train behind the leader: Σρc, Σρτ, Σρc' at one leader angle |
//! | `chebyshev.rs` | Chebyshev interpolation, cumulative integrals, Clenshaw–Curtis quadrature |
//! | `cooperative.rs` | the group model with friction μ: cooperative (μ = 0) and extended (μ > 0) |
//! | `period.rs` | the period integral ∫dθ/√u near a stall (sinh-stretched Clenshaw–Curtis), minimum search |
//! | `single.rs` | the single collision model (μ, e): derivation and solution |
//! | `threshold.rs` | [`min_spacing`]: the smallest spacing with a wave, bracketed |
//! | `sweep.rs` | [`sweep`] over s/h and the CSV table |
//! | `plot.rs` | `plot_svg`: the Fig. 5 theory lines as SVG (feature `plots`) |
//! | `outcome.rs` | [`Wave`], [`NoWave`], [`Outcome`], [`TheoryError`] |
//!
//! Units: lengths over the block height h, speeds over √(gh), angular
//! velocities over √(g/h), times over √(h/g), angles in radians.
//!
//! Accuracy (target 10⁻⁶ relative): group models: train summed until a block
//! adds less than 10⁻¹⁴ of the sums; the equation of motion sampled at n + 1
//! Chebyshev points in the leader angle, n doubled from 8 until two natural
//! speeds agree to 10⁻¹⁰; the fixed point of the affine cycle map of θ̇_0² in
//! closed form (no iteration); the period by Clenshaw–Curtis to 10⁻¹²,
//! stretched around the minimum of θ̇_0² (within ~10⁻⁸ in s/h of a stall the
//! rounding of θ̇_0² limits this to 10⁻⁶, and closer still `solve` reports
//! `NotConverged`). Single collision model: everything closed form but the
//! period. Cost per point (one thread): ~40 µs for the group models, ~2 µs
//! for the single collision model.
//!
//! # Single collision model
//! The striker A turns about its front bottom edge at θ_c (sin θ_c = s/h); its
//! top front edge hits the upright block B's back face at height h cos θ_c,
//! a distance d behind B's pivot edge. Angular impulse about each pivot edge:
//! `I Δω_B = P_n h cos θ_c + P_t d`, `I Δω_A = P_t h sin θ_c − P_n h cos θ_c`
//! (forward rotation positive, P_t up B's face); Coulomb friction along the
//! normal impulse, `dP_t = −μ dP_n` while A's edge slides down B's face (stick
//! or reversed slip if the slip stops); Newton's restitution at the contact
//! point ends the impact, `v_n⁺ = −e v_n⁻` with `v_n = h cos θ_c (ω_A − ω_B)`.
//! While sliding, `ω_B⁺ = k ω_A⁻`, `k = (1 + e)(h cos θ_c − μ d) /
//! (2 h cos θ_c + μ (h sin θ_c − d))`. B then falls freely from upright:
//! `θ̇² = θ̇_0² + (2 m g R/I)(cos φ − cos(θ − φ))`, `R = √(h²+d²)/2`, `tan φ = d/h`.
//! The cycle `θ̇_c² ↦ k² θ̇_c² + G` has the fixed point `θ̇_c² = G/(1 − k²)`;
//! a wave needs `G > 0` and B to get over its balance point θ = φ.
//! The full derivation is in the source, `src/theory/single.rs`.
//!
//! ```
//! use topple::theory::{solve, Geometry, Model};
//! // van Leeuwen's example: h = 48 mm, d = 7.5 mm, λ = 16 mm, g = 9.8 m/s²
//! let (h, d, lambda, g) = (0.048, 0.0075, 0.016, 9.8);
//! let geom = Geometry::new(d / h, (lambda - d) / h).unwrap();
//! let v = solve(&Model::Cooperative, &geom).unwrap().natural_speed().unwrap() * (g * h).sqrt();
//! assert!((v - 1.380).abs() < 0.005); // m/s, docs/theory.md
//! ```

mod chebyshev;
mod cooperative;
mod geometry;
mod outcome;
mod period;
#[cfg(feature = "plots")]
mod plot;
mod single;
mod sweep;
mod threshold;
mod train;

pub use geometry::Geometry;
pub use outcome::{NoWave, Outcome, TheoryError, Wave};
#[cfg(feature = "plots")]
pub use plot::plot_svg;
pub use sweep::{sweep, write_csv, SweepRow};
pub use threshold::{min_spacing, SpacingBracket};

use crate::input::InputError;
use serde::Serialize;

/// A model of the wave.
///
/// ```
/// use topple::theory::Model;
/// assert!(Model::Extended { mu: -0.1 }.validate().is_err());
/// assert!(Model::Single { mu: 0.15, e: 0.62 }.validate().is_ok());
/// assert_eq!(Model::Extended { mu: 0.2 }.name(), "extended");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "model", rename_all = "snake_case")]
pub enum Model {
    /// Cooperative group model (Stronge & Shu 1988; van Leeuwen 2010): the whole
    /// leaning train, frictionless contacts between blocks (μ = 0).
    Cooperative,
    /// Extended group model (van Leeuwen 2010; Fujii et al.): the cooperative
    /// model with Coulomb friction `mu` between blocks.
    Extended {
        /// Friction coefficient between blocks, ≥ 0.
        mu: f64,
    },
    /// Single collision model (Stronge 1987): two blocks per collision, friction
    /// `mu` and Newton's restitution `e` between them.
    Single {
        /// Friction coefficient between blocks, ≥ 0.
        mu: f64,
        /// Coefficient of restitution between blocks, in [0, 1].
        e: f64,
    },
}

impl Model {
    /// Short name: "cooperative", "extended" or "single".
    pub fn name(&self) -> &'static str {
        match self {
            Model::Cooperative => "cooperative",
            Model::Extended { .. } => "extended",
            Model::Single { .. } => "single",
        }
    }

    /// Friction coefficient between blocks (0 for the cooperative model).
    pub fn mu(&self) -> f64 {
        match *self {
            Model::Cooperative => 0.0,
            Model::Extended { mu } | Model::Single { mu, .. } => mu,
        }
    }

    /// Checks the parameters' ranges: μ finite and ≥ 0, e in [0, 1].
    pub fn validate(&self) -> Result<(), TheoryError> {
        let mu = self.mu();
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(TheoryError::InvalidParameter(InputError::new(
                "mu",
                mu,
                "finite and mu ≥ 0 (friction coefficient)",
            )));
        }
        if let Model::Single { e, .. } = *self
            && !(0.0..=1.0).contains(&e)
        {
            return Err(TheoryError::InvalidParameter(InputError::new(
                "e",
                e,
                "0 ≤ e ≤ 1 (coefficient of restitution)",
            )));
        }
        Ok(())
    }
}

/// The natural wave of `model` for `geometry`, or why there is none.
///
/// ```
/// use topple::theory::{solve, Geometry, Model, NoWave, Outcome};
/// let geom = Geometry::new(0.12, 0.4).unwrap();
/// let coop = solve(&Model::Cooperative, &geom).unwrap().natural_speed().unwrap();
/// let ext = solve(&Model::Extended { mu: 0.15 }, &geom).unwrap().natural_speed().unwrap();
/// assert!(ext < coop); // friction slows the wave
/// // the single collision model needs θ_c > 2 atan(d/h) for gravity to pay for the collision
/// let close = Geometry::new(0.12, 0.1).unwrap();
/// let single = solve(&Model::Single { mu: 0.0, e: 0.0 }, &close).unwrap();
/// assert_eq!(single, Outcome::NoWave(NoWave::NoEnergyGain));
/// ```
pub fn solve(model: &Model, geometry: &Geometry) -> Result<Outcome, TheoryError> {
    model.validate()?;
    match *model {
        Model::Cooperative => cooperative::solve_group(geometry, 0.0),
        Model::Extended { mu } => cooperative::solve_group(geometry, mu),
        Model::Single { mu, e } => single::solve_single(geometry, mu, e),
    }
}
