//! The row builder: n identical blocks standing at a regular pitch.

use serde::{Deserialize, Serialize};

use super::RowParams;
use crate::input::{fmt_value, InputError};

/// A row of `n` identical blocks standing on the ground at gap `spacing` s (m),
/// block 1 at the origin, the wave running towards +x; block 1 starts rotating
/// forward about its front bottom edge with dimensionless angular velocity
/// `push` = θ̇₁ √(h/g) (the paper's θ̂₁(0), Sec. 3.1).
///
/// ```
/// use topple::domino::{Preset, RowSpec};
/// let p = Preset::X.params();
/// let row = RowSpec::new(p, 0.18 * p.block.height, 10, 1.8);
/// assert!((row.pitch() - (0.18 * 4.18e-2 + 7.58e-3)).abs() < 1e-15);
/// assert_eq!(row.centre(2), [2.0 * row.pitch(), 0.5 * 4.18e-2]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowSpec {
    /// Blocks and materials.
    pub params: RowParams,
    /// Gap s between neighbouring blocks (m).
    pub spacing: f64,
    /// Number of blocks.
    pub n: usize,
    /// Dimensionless initial angular velocity of block 1 about its front edge.
    pub push: f64,
}

impl RowSpec {
    /// A row of `n` blocks at gap `spacing` (m) with the given push.
    pub fn new(params: RowParams, spacing: f64, n: usize, push: f64) -> Self {
        RowSpec {
            params,
            spacing,
            n,
            push,
        }
    }

    /// Pitch s + d (m), the distance the wave travels per block.
    pub fn pitch(&self) -> f64 {
        self.spacing + self.params.block.thickness
    }

    /// Spacing ratio s/h.
    pub fn spacing_ratio(&self) -> f64 {
        self.spacing / self.params.block.height
    }

    /// Centre of block `i` (0-based) standing upright (m).
    pub fn centre(&self, i: usize) -> [f64; 2] {
        [i as f64 * self.pitch(), 0.5 * self.params.block.height]
    }

    /// Block 1's initial velocity: rotation about its front bottom corner at
    /// θ̇₁ = push/t̄ clockwise. Returns (velocity of the centre (m/s), angular
    /// velocity (rad/s, counter-clockwise)).
    pub fn initial_velocity(&self) -> ([f64; 2], f64) {
        let b = &self.params.block;
        let omega = -self.push / self.params.time_scale();
        // v = ω × (c − A) with c − A = (−d/2, h/2)
        let r = [-0.5 * b.thickness, 0.5 * b.height];
        ([-omega * r[1], omega * r[0]], omega)
    }

    /// Checks the row is usable: its [`RowParams`] (see
    /// [`RowParams::validate`]), then `spacing`, `n` and `push`; the error names
    /// the field, its value and the allowed range.
    ///
    /// ```
    /// use topple::domino::{Preset, RowSpec};
    /// let p = Preset::X.params();
    /// let e = RowSpec::new(p, 0.3 * p.block.height, 1, 1.0).validate().unwrap_err();
    /// assert_eq!(e.to_string(), "n = 1: allowed n ≥ 2");
    /// ```
    pub fn validate(&self) -> Result<(), InputError> {
        self.params.validate()?;
        let h = self.params.block.height;
        if !(self.spacing.is_finite() && self.spacing > 0.0 && self.spacing < h) {
            return Err(InputError::new(
                "spacing",
                fmt_value(self.spacing),
                format!("0 < spacing < height = {}", fmt_value(h)),
            ));
        }
        if self.n < 2 {
            return Err(InputError::new("n", self.n, "n ≥ 2"));
        }
        if !(self.push.is_finite() && self.push > 0.0) {
            return Err(InputError::new(
                "push",
                fmt_value(self.push),
                "finite and push > 0",
            ));
        }
        Ok(())
    }
}
