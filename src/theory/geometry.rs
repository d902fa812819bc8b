//! Block and row geometry in units of the block height `h` (docs/theory.md,
//! "Notation" and "Cooperative group": the leaning-pair relation, θ_c, θ_∞).
//!
//! Every length here is divided by `h`; angles are in radians, measured from
//! the vertical, positive when a block leans forward (towards the blocks not yet
//! hit). Mass and gravity are set to 1 (the motion of a row of identical blocks
//! does not depend on the mass, docs/model.md §6), so a torque is in units of
//! `m g h` and an angular velocity in units of √(g/h).

use super::TheoryError;
use crate::input::InputError;

/// The shape of a row of identical blocks: thickness `d/h` and gap `s/h`.
///
/// ```
/// use topple::theory::Geometry;
/// // Domino T of the paper's Table 1 (d/h = 0.12) at spacing s/h = 0.3
/// let g = Geometry::new(0.12, 0.3).unwrap();
/// assert!((g.pitch() - 0.42).abs() < 1e-15);
/// // sin θ_c = s/h, cos θ_∞ = d/λ
/// assert!((g.collision_angle().unwrap().sin() - 0.3).abs() < 1e-15);
/// assert!((g.rest_angle().cos() - 0.12 / 0.42).abs() < 1e-15);
/// assert!(Geometry::new(0.12, -0.1).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    d: f64,
    s: f64,
}

impl Geometry {
    /// Makes a geometry from the thickness ratio `d/h` (in (0, 1)) and the
    /// spacing ratio `s/h` (> 0). A spacing of `h` or more is accepted: it gives
    /// "no wave" (the falling block never reaches the next one).
    pub fn new(thickness_ratio: f64, spacing_ratio: f64) -> Result<Self, TheoryError> {
        if !(thickness_ratio.is_finite() && thickness_ratio > 0.0 && thickness_ratio < 1.0) {
            return Err(TheoryError::InvalidParameter(InputError::new(
                "d/h",
                thickness_ratio,
                "0 < d/h < 1 (thickness ratio)",
            )));
        }
        if !(spacing_ratio.is_finite() && spacing_ratio > 0.0) {
            return Err(TheoryError::InvalidParameter(InputError::new(
                "s/h",
                spacing_ratio,
                "finite and s/h > 0 (spacing ratio)",
            )));
        }
        Ok(Self {
            d: thickness_ratio,
            s: spacing_ratio,
        })
    }

    /// Thickness `d/h`.
    pub fn thickness_ratio(&self) -> f64 {
        self.d
    }

    /// Gap between neighbouring blocks, `s/h`.
    pub fn spacing_ratio(&self) -> f64 {
        self.s
    }

    /// Pitch `λ/h = (s + d)/h`, the distance between neighbouring pivots.
    pub fn pitch(&self) -> f64 {
        self.s + self.d
    }

    /// Collision angle θ_c (rad): the falling block's top front edge meets the
    /// back face of the next upright block, `sin θ_c = s/h` (docs/theory.md).
    /// `None` when `s ≥ h`: the block lands without touching the next one.
    pub fn collision_angle(&self) -> Option<f64> {
        (self.s < 1.0).then(|| self.s.asin())
    }

    /// Rest angle θ_∞ (rad) of the fallen train, `cos θ_∞ = d/λ` (docs/theory.md):
    /// the fixed point of [`Geometry::lean_behind`].
    pub fn rest_angle(&self) -> f64 {
        (self.d / self.pitch()).acos()
    }

    /// Angle of the block leaning on the back face of a block at angle
    /// `theta_front` (rad), from the leaning-pair relation
    /// `h sin(θ_{k+1} − θ_k) = λ cos θ_k − d` (docs/theory.md, "Cooperative group").
    /// Valid while `|λ cos θ_k − d| ≤ h`, which holds for `0 ≤ θ_k ≤ θ_∞` and `s < h`.
    pub fn lean_behind(&self, theta_front: f64) -> f64 {
        theta_front + (self.pitch() * theta_front.cos() - self.d).asin()
    }

    /// Angle φ = atan(d/h) (rad) between a block's long axis and the line from
    /// its front bottom edge to its centre of mass: gravity pulls a block back
    /// for θ < φ and forward for θ > φ.
    pub fn tip_angle(&self) -> f64 {
        self.d.atan()
    }

    /// Distance from the pivot edge to the centre of mass, `√(h² + d²)/2`, over `h`.
    pub fn pivot_to_centre(&self) -> f64 {
        0.5 * (1.0 + self.d * self.d).sqrt()
    }

    /// Moment of inertia about the pivot edge, `I = m (h² + d²)/3`, over `m h²`
    /// (docs/theory.md, "Notation").
    pub fn pivot_inertia(&self) -> f64 {
        (1.0 + self.d * self.d) / 3.0
    }

    /// Gravity torque about the pivot edge, `m g (√(h²+d²)/2) sin(θ − φ)`, over
    /// `m g h` (docs/theory.md, τ_k).
    pub fn gravity_torque(&self, theta: f64) -> f64 {
        self.pivot_to_centre() * (theta - self.tip_angle()).sin()
    }
}
