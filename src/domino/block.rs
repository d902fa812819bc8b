//! One rectangular block (paper Sec. 2.1, Fig. 1).

use serde::{Deserialize, Serialize};

/// A rectangular block of height h and thickness d (m) and mass m (kg).
///
/// Body frame: origin at the centre of mass, x towards the front (the direction
/// the wave travels), y up when the block stands. The paper's angle θ is
/// clockwise; this crate's angles are counter-clockwise (φ = −θ).
///
/// ```
/// use topple::domino::Block;
/// let b = Block::new(0.08, 0.0096);
/// // I = m (h² + d²) / 12 about the centre of mass (docs/model.md §6)
/// assert!((b.inertia() - (0.08f64.powi(2) + 0.0096f64.powi(2)) / 12.0).abs() < 1e-15);
/// assert_eq!(b.front_bottom(), [0.0048, -0.04]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Block {
    /// Height h (m).
    pub height: f64,
    /// Thickness d (m).
    pub thickness: f64,
    /// Mass m (kg); it does not affect the motion of a row of identical blocks.
    pub mass: f64,
}

impl Block {
    /// A block of mass 1 kg (the paper's choice).
    pub fn new(height: f64, thickness: f64) -> Self {
        Block {
            height,
            thickness,
            mass: 1.0,
        }
    }

    /// Moment of inertia about the centre of mass, m (h² + d²)/12 (kg·m²).
    pub fn inertia(&self) -> f64 {
        self.mass * (self.height * self.height + self.thickness * self.thickness) / 12.0
    }

    /// Moment of inertia about a bottom edge, m (h² + d²)/3 (kg·m²).
    pub fn inertia_about_edge(&self) -> f64 {
        4.0 * self.inertia()
    }

    /// Front bottom corner A (the pivot), body frame (m).
    pub fn front_bottom(&self) -> [f64; 2] {
        [0.5 * self.thickness, -0.5 * self.height]
    }

    /// Back bottom corner (the heel), body frame (m).
    pub fn back_bottom(&self) -> [f64; 2] {
        [-0.5 * self.thickness, -0.5 * self.height]
    }

    /// Front top corner B (strikes the next block), body frame (m).
    pub fn front_top(&self) -> [f64; 2] {
        [0.5 * self.thickness, 0.5 * self.height]
    }

    /// Back top corner, body frame (m).
    pub fn back_top(&self) -> [f64; 2] {
        [-0.5 * self.thickness, 0.5 * self.height]
    }

    /// The `p`-th of `lambda` equidistant points on the bottom face, p = 0..λ−1,
    /// from the back edge to the front edge (docs/model.md §5: x_p = p/(λ−1)·d − d/2).
    pub fn bottom_point(&self, p: usize, lambda: usize) -> [f64; 2] {
        let f = if lambda > 1 {
            p as f64 / (lambda - 1) as f64
        } else {
            1.0
        };
        [(f - 0.5) * self.thickness, -0.5 * self.height]
    }

    /// The four corners in world coordinates for a block whose centre is at
    /// `centre` and whose counter-clockwise angle is `angle`: front bottom, front
    /// top, back top, back bottom.
    pub fn world_corners(&self, centre: [f64; 2], angle: f64) -> [[f64; 2]; 4] {
        let (s, c) = angle.sin_cos();
        let w = |p: [f64; 2]| {
            [
                centre[0] + c * p[0] - s * p[1],
                centre[1] + s * p[0] + c * p[1],
            ]
        };
        [
            w(self.front_bottom()),
            w(self.front_top()),
            w(self.back_top()),
            w(self.back_bottom()),
        ]
    }
}
