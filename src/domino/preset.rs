//! Table 1 of the paper: Domino X, T and P, with every value overridable.

use serde::{Deserialize, Serialize};

use super::{Block, Ground};
use crate::input::{check_range, fmt_value, InputError};

/// The three block types of Table 1.
///
/// ```
/// use topple::domino::Preset;
/// let x = Preset::X.params();
/// assert_eq!(x.block.height, 4.18e-2);
/// assert_eq!((x.mu1, x.e1, x.mu2, x.e2), (0.17, 0.85, 0.25, 0.5));
/// assert_eq!(x.impact_friction_factor, 0.5);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Preset {
    /// Plastic block of Stronge (1987).
    X,
    /// Tufnol block of Stronge & Shu (1988).
    T,
    /// Perspex block of Stronge & Shu (1988).
    P,
}

impl std::str::FromStr for Preset {
    type Err = InputError;

    /// "X", "T" or "P" (either case).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_uppercase().as_str() {
            "X" => Ok(Preset::X),
            "T" => Ok(Preset::T),
            "P" => Ok(Preset::P),
            _ => Err(InputError::new(
                "preset",
                format!("{s:?}"),
                "X, T or P (either case)",
            )),
        }
    }
}

impl Preset {
    /// The Table 1 values of this preset.
    pub fn params(self) -> RowParams {
        let (h, d, mu1, mu2, mu1s, mu2s, e1) = match self {
            Preset::X => (4.18e-2, 7.58e-3, 0.17, 0.25, 0.20, 0.30, 0.85),
            Preset::T => (8.00e-2, 9.60e-3, 0.15, 0.20, 0.18, 0.25, 0.62),
            Preset::P => (8.00e-2, 9.90e-3, 0.25, 0.30, 0.30, 0.36, 0.55),
        };
        RowParams {
            block: Block::new(h, d),
            mu1,
            mu1_stick: mu1s,
            e1,
            k1: 2.30e8,
            mu2,
            mu2_stick: mu2s,
            e2: 0.5,
            k2: 6.90e8,
            lambda_points: 9,
            alpha: 1.5,
            impact_friction_factor: 0.5,
            gravity: 9.81,
            ground: Ground::Coulomb,
        }
    }
}

/// Material and geometry of a row of identical blocks (paper Table 1 and
/// Sec. 3.1). Index 1 is the block–block contact, index 2 the block–ground
/// contact.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowParams {
    /// Geometry and mass of one block.
    pub block: Block,
    /// Sliding friction between blocks μ1 (smooth phase).
    pub mu1: f64,
    /// Sticking friction between blocks μ1ˢ ≥ μ1.
    pub mu1_stick: f64,
    /// Energetic restitution between blocks e1.
    pub e1: f64,
    /// Contact stiffness between blocks k1 (N/m^α).
    pub k1: f64,
    /// Sliding friction with the ground μ2.
    pub mu2: f64,
    /// Sticking friction with the ground μ2ˢ ≥ μ2.
    pub mu2_stick: f64,
    /// Energetic restitution with the ground e2.
    pub e2: f64,
    /// Contact stiffness with the ground k2 (N/m^α).
    pub k2: f64,
    /// Number λ of points replacing the line contact under a standing block
    /// (docs/model.md §5; the paper uses 9).
    pub lambda_points: usize,
    /// Exponent α of the contact law F = k(−δ)^α (the paper uses 1.5).
    pub alpha: f64,
    /// Factor on the sliding friction coefficients μ1, μ2 inside impacts
    /// (Table 1 footnote, docs/model.md §4: 0.5); the sticking coefficients are not
    /// scaled.
    pub impact_friction_factor: f64,
    /// Gravity g (m/s²).
    pub gravity: f64,
    /// The ground model: the paper's Coulomb friction (default) or pivots
    /// that never slip. Absent in older files means Coulomb.
    #[serde(default)]
    pub ground: Ground,
}

impl RowParams {
    /// The "ideal" material of Sec. 3.2 (Stronge's assumptions): μ1 = 0, e1 = 0,
    /// μ2 = 0.9, e2 = 0, with sticking coefficients equal to the sliding ones.
    pub fn ideal(mut self) -> Self {
        self.mu1 = 0.0;
        self.mu1_stick = 0.0;
        self.e1 = 0.0;
        self.mu2 = 0.9;
        self.mu2_stick = 0.9;
        self.e2 = 0.0;
        self
    }

    /// Speed scale v̄ = √(g h) (m/s).
    pub fn speed_scale(&self) -> f64 {
        (self.gravity * self.block.height).sqrt()
    }

    /// Time scale t̄ = √(h / g) (s).
    pub fn time_scale(&self) -> f64 {
        (self.block.height / self.gravity).sqrt()
    }

    /// Checks that every value is usable; the error names the first one
    /// that is not (its field name in [`RowParams`] and [`Block`]), its value
    /// and the allowed range.
    ///
    /// ```
    /// use topple::domino::Preset;
    /// let mut p = Preset::X.params();
    /// p.e1 = 1.5;
    /// let e = p.validate().unwrap_err();
    /// assert_eq!((e.field.as_str(), e.value.as_str()), ("e1", "1.5"));
    /// assert_eq!(e.to_string(), "e1 = 1.5: allowed 0 ≤ e1 ≤ 1");
    /// ```
    pub fn validate(&self) -> Result<(), InputError> {
        let b = &self.block;
        let pos = [
            ("height", b.height),
            ("thickness", b.thickness),
            ("mass", b.mass),
            ("k1", self.k1),
            ("k2", self.k2),
            ("alpha", self.alpha),
            ("gravity", self.gravity),
        ];
        for (name, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(InputError::new(
                    name,
                    fmt_value(v),
                    format!("finite and {name} > 0"),
                ));
            }
        }
        let nonneg = [
            ("mu1", self.mu1),
            ("mu1_stick", self.mu1_stick),
            ("mu2", self.mu2),
            ("mu2_stick", self.mu2_stick),
            ("impact_friction_factor", self.impact_friction_factor),
        ];
        for (name, v) in nonneg {
            if !(v.is_finite() && v >= 0.0) {
                return Err(InputError::new(
                    name,
                    fmt_value(v),
                    format!("finite and {name} ≥ 0"),
                ));
            }
        }
        check_range("e1", self.e1, 0.0, 1.0)?;
        check_range("e2", self.e2, 0.0, 1.0)?;
        for (stick, v, slide, m) in [
            ("mu1_stick", self.mu1_stick, "mu1", self.mu1),
            ("mu2_stick", self.mu2_stick, "mu2", self.mu2),
        ] {
            if v < m {
                return Err(InputError::new(
                    stick,
                    fmt_value(v),
                    format!(
                        "{stick} ≥ {slide} = {} (sticking ≥ sliding friction)",
                        fmt_value(m)
                    ),
                ));
            }
        }
        if self.lambda_points < 2 {
            return Err(InputError::new(
                "lambda_points",
                self.lambda_points,
                "lambda_points ≥ 2 (the two bottom corners)",
            ));
        }
        if b.thickness >= b.height {
            return Err(InputError::new(
                "thickness",
                fmt_value(b.thickness),
                format!("0 < thickness < height = {}", fmt_value(b.height)),
            ));
        }
        Ok(())
    }
}
