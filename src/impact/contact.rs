//! Contacts and the contact law they carry into the impact.

use serde::{Deserialize, Serialize};

/// The material of one contact point: the power law F = k (−δ)^α (paper Eq. 25),
/// the energetic restitution e (Eq. 23) and Coulomb friction (Eq. 20).
///
/// ```
/// use topple::impact::ContactMaterial;
/// let m = ContactMaterial::hertz(1e9).with_restitution(0.5).with_friction(0.2, 0.3);
/// assert_eq!(m.exponent, 1.5);
/// assert_eq!(m.stick_friction, 0.3);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactMaterial {
    /// Contact stiffness k (N/m^α); only ratios between contacts matter.
    pub stiffness: f64,
    /// Exponent α of the force law: 1.5 for Hertz, 1 for linear.
    pub exponent: f64,
    /// Energetic coefficient of restitution e ∈ [0, 1].
    pub restitution: f64,
    /// Sliding friction μ ≥ 0 used during the impact; `f64::INFINITY` is a
    /// contact that never slides ([`ContactMaterial::no_slip`]).
    pub friction: f64,
    /// Sticking friction μ_s ≥ 0: a sticking contact stays stuck while
    /// |dP_t| ≤ μ_s dP_n.
    pub stick_friction: f64,
}

impl ContactMaterial {
    /// Hertzian (α = 1.5), perfectly elastic, frictionless contact of stiffness k.
    pub fn hertz(stiffness: f64) -> Self {
        ContactMaterial {
            stiffness,
            exponent: 1.5,
            restitution: 1.0,
            friction: 0.0,
            stick_friction: 0.0,
        }
    }

    /// Same material with another restitution coefficient.
    pub fn with_restitution(mut self, restitution: f64) -> Self {
        self.restitution = restitution;
        self
    }

    /// Same material with sliding friction μ and sticking friction μ_s.
    pub fn with_friction(mut self, friction: f64, stick_friction: f64) -> Self {
        self.friction = friction;
        self.stick_friction = stick_friction;
        self
    }

    /// Same material without slip: μ = μ_s = ∞. While the contact takes
    /// normal impulse its tangential impulse is whatever stops its slip
    /// (unbounded, not a large finite μ); it may still separate. The
    /// assumption of a pivot that holds (the cooperative domino model).
    ///
    /// ```
    /// use topple::impact::ContactMaterial;
    /// let m = ContactMaterial::hertz(1e9).no_slip();
    /// assert!(m.is_no_slip());
    /// assert!(!ContactMaterial::hertz(1e9).with_friction(1e6, 1e6).is_no_slip());
    /// ```
    pub fn no_slip(mut self) -> Self {
        self.friction = f64::INFINITY;
        self.stick_friction = f64::INFINITY;
        self
    }

    /// Whether the contact never slides (μ = ∞).
    pub fn is_no_slip(&self) -> bool {
        self.friction == f64::INFINITY
    }

    /// Same material with another exponent α.
    pub fn with_exponent(mut self, exponent: f64) -> Self {
        self.exponent = exponent;
        self
    }

    /// Contact force as a function of stored energy (docs/model.md §1, the corrected
    /// paper Eq. 26): F(E) = (α+1)^(α/(α+1)) k^(1/(α+1)) E^(α/(α+1)).
    #[inline]
    pub fn force_from_energy(&self, stored_energy: f64) -> f64 {
        let a1 = self.exponent + 1.0;
        let power = self.exponent / a1;
        a1.powf(power) * self.stiffness.powf(1.0 / a1) * stored_energy.max(0.0).powf(power)
    }
}

/// A contact point between two bodies, or between a body and the fixed world.
///
/// `bodies[0]` is the first body, `bodies[1]` the second; `None` is the fixed
/// world. `normal` is a unit vector pointing from the first body to the second,
/// so the normal relative velocity δ̇ = n·(v₂ − v₁) at the point is negative
/// while the bodies approach. The tangent is the normal turned +90°:
/// t = (−n_y, n_x).
///
/// ```
/// use topple::impact::{Contact, ContactMaterial};
/// // body 0 resting on the ground (the world is the first body, normal up)
/// let c = Contact::new([None, Some(0)], [0.0, 0.0], [0.0, 1.0], ContactMaterial::hertz(1e9));
/// assert_eq!(c.tangent(), [-1.0, 0.0]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// The two bodies (indices into the body slice); `None` is the fixed world.
    pub bodies: [Option<usize>; 2],
    /// Contact point in world coordinates (m).
    pub point: [f64; 2],
    /// Unit normal from the first body to the second.
    pub normal: [f64; 2],
    /// The contact law.
    pub material: ContactMaterial,
}

impl Contact {
    /// A contact with the given bodies, point, normal and material.
    pub fn new(
        bodies: [Option<usize>; 2],
        point: [f64; 2],
        normal: [f64; 2],
        material: ContactMaterial,
    ) -> Self {
        Contact {
            bodies,
            point,
            normal,
            material,
        }
    }

    /// Unit tangent t = (−n_y, n_x), the positive direction of tangential
    /// impulses and velocities.
    #[inline]
    pub fn tangent(&self) -> [f64; 2] {
        [-self.normal[1], self.normal[0]]
    }

    /// The contact's frame among `bodies`, the world being slot
    /// `bodies.len()`: the body slots, the normal made unit, the tangent and
    /// each body's arm (contact point minus centre of mass, m; zero for the
    /// world). One definition for every solver that builds rows from it.
    #[inline]
    pub(crate) fn frame(&self, bodies: &[super::Body]) -> ContactFrame {
        let world = bodies.len();
        let a = self.bodies[0].unwrap_or(world);
        let b = self.bodies[1].unwrap_or(world);
        let len = self.normal[0].hypot(self.normal[1]);
        let normal = [self.normal[0] / len, self.normal[1] / len];
        let arm = |slot: usize| {
            if slot == world {
                [0.0, 0.0]
            } else {
                let p = bodies[slot].position;
                [self.point[0] - p[0], self.point[1] - p[1]]
            }
        };
        ContactFrame {
            a,
            b,
            normal,
            tangent: [-normal[1], normal[0]],
            arm_a: arm(a),
            arm_b: arm(b),
        }
    }
}

/// See [`Contact::frame`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct ContactFrame {
    pub a: usize,
    pub b: usize,
    pub normal: [f64; 2],
    pub tangent: [f64; 2],
    pub arm_a: [f64; 2],
    pub arm_b: [f64; 2],
}

/// The planar cross product r × v (the moment arm of v about r's origin).
#[inline]
pub(crate) fn cross(r: [f64; 2], v: [f64; 2]) -> f64 {
    r[0] * v[1] - r[1] * v[0]
}
