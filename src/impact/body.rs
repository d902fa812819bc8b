//! Rigid bodies as the resolver sees them: planar, with mass and inertia, frozen
//! in place during the impact (paper Sec. 2.3, assumption (i)).

use serde::{Deserialize, Serialize};

/// A planar rigid body entering an impact.
///
/// Units are the caller's, but consistent: mass in kg, inertia in kg·m² about the
/// centre of mass, positions in m, angle in rad (counter-clockwise positive),
/// velocities in m/s and rad/s. A `fixed` body never moves; its mass and inertia
/// are ignored.
///
/// ```
/// use topple::impact::Body;
/// let ball = Body::new(1.0, 0.1).with_velocity([1.0, 0.0]);
/// assert_eq!(ball.velocity, [1.0, 0.0]);
/// assert!(!ball.fixed);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Body {
    /// Mass m (kg); must be > 0 unless `fixed`.
    pub mass: f64,
    /// Moment of inertia about the centre of mass (kg·m²); must be > 0 unless `fixed`.
    pub inertia: f64,
    /// Centre of mass in world coordinates (m).
    pub position: [f64; 2],
    /// Orientation (rad, counter-clockwise). Not used by the impact itself, kept
    /// so that callers can hand over a whole body state.
    pub angle: f64,
    /// Linear velocity of the centre of mass (m/s).
    pub velocity: [f64; 2],
    /// Angular velocity (rad/s, counter-clockwise).
    pub angular_velocity: f64,
    /// A fixed body has infinite mass.
    pub fixed: bool,
}

impl Body {
    /// A free body at rest at the origin.
    pub fn new(mass: f64, inertia: f64) -> Self {
        Body {
            mass,
            inertia,
            position: [0.0, 0.0],
            angle: 0.0,
            velocity: [0.0, 0.0],
            angular_velocity: 0.0,
            fixed: false,
        }
    }

    /// A fixed body (infinite mass), e.g. the ground or a wall.
    pub fn fixed() -> Self {
        Body {
            fixed: true,
            ..Body::new(0.0, 0.0)
        }
    }

    /// Same body at another position.
    pub fn with_position(mut self, position: [f64; 2]) -> Self {
        self.position = position;
        self
    }

    /// Same body with another linear velocity.
    pub fn with_velocity(mut self, velocity: [f64; 2]) -> Self {
        self.velocity = velocity;
        self
    }

    /// Same body with another angular velocity.
    pub fn with_angular_velocity(mut self, angular_velocity: f64) -> Self {
        self.angular_velocity = angular_velocity;
        self
    }

    /// Kinetic energy ½ m v² + ½ I ω² (J); zero for a fixed body.
    pub fn kinetic_energy(&self) -> f64 {
        if self.fixed {
            return 0.0;
        }
        let [vx, vy] = self.velocity;
        0.5 * self.mass * (vx * vx + vy * vy)
            + 0.5 * self.inertia * self.angular_velocity * self.angular_velocity
    }
}

/// A body's velocity after the impact.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BodyVelocity {
    /// Linear velocity of the centre of mass (m/s).
    pub velocity: [f64; 2],
    /// Angular velocity (rad/s, counter-clockwise).
    pub angular_velocity: f64,
}
