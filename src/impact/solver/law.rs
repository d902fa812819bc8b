//! The contact law of one point in the impact's own time (docs/model.md §7).
//!
//! With the compression q = −δ ≥ 0 as state, the power law F = k q^α (paper
//! Eq. 25) stores E = k q^(α+1)/(α+1), and the energetic restitution of paper
//! Eq. 23 reads
//!
//! * compression (δ̇ ≤ 0): dq/dt = −δ̇, so dE = −δ̇ dP (paper Eq. 22);
//! * expansion (δ̇ > 0): dq/dt = −δ̇ / e², so the energy falls 1/e² times
//!   faster than the work the force gives back (dE = −δ̇ dP / e²);
//! * e = 0: the energy is lost when compression ends (q is set to 0).
//!
//! Eliminating q gives back F(E) of paper Eq. 26 (docs/model.md §1), so the
//! impulses share out in the ratios F_i/F_j of Eq. 27: the same law the
//! impulse stepping follows, with time instead of the primary's impulse as
//! the independent variable.

/// How F = k q^α is evaluated: without `powf` for the two usual exponents.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    /// α = 1.
    Linear,
    /// α = 3/2: q·√q.
    Hertz,
    /// Any other α > 0.
    Power,
}

/// One contact point's law: stiffness, exponent and restitution.
#[derive(Clone, Copy, Debug)]
pub(super) struct Law {
    /// k (N/m^α).
    stiffness: f64,
    /// α.
    exponent: f64,
    shape: Shape,
    /// e, and e² (the expansion's efficiency η of paper Eq. 23).
    pub restitution: f64,
    restitution_sq: f64,
}

impl Law {
    pub fn new(stiffness: f64, exponent: f64, restitution: f64) -> Self {
        let shape = if exponent == 1.0 {
            Shape::Linear
        } else if exponent == 1.5 {
            Shape::Hertz
        } else {
            Shape::Power
        };
        Law {
            stiffness,
            exponent,
            shape,
            restitution,
            restitution_sq: restitution * restitution,
        }
    }

    /// F = k q^α (N) of a loaded contact. Past the point where the contact
    /// lets go (q < 0, only at trial points beyond an event that the step
    /// is cut back to) the law continues as −k |q|^α, which is as smooth at
    /// q = 0 as the law itself, so the step's interpolant stays accurate up
    /// to the event.
    #[inline]
    pub fn force(&self, q: f64) -> f64 {
        let m = q.abs();
        let f = match self.shape {
            Shape::Linear => self.stiffness * m,
            Shape::Hertz => self.stiffness * m * m.sqrt(),
            Shape::Power => self.stiffness * m.powf(self.exponent),
        };
        f.copysign(q)
    }

    /// Stored energy E = k q^(α+1)/(α+1) (J) at compression q ≥ 0.
    pub fn energy(&self, q: f64) -> f64 {
        if q <= 0.0 {
            0.0
        } else {
            self.force(q) * q / (self.exponent + 1.0)
        }
    }

    /// e², the expansion's efficiency η (paper Eq. 23).
    pub fn restitution_sq(&self) -> f64 {
        self.restitution_sq
    }

    /// The compression (m) that stores energy `e` (J).
    pub fn compression(&self, energy: f64) -> f64 {
        ((self.exponent + 1.0) * energy / self.stiffness).powf(1.0 / (self.exponent + 1.0))
    }

    /// dq/dt (m/s) at normal rate δ̇ (m/s): −δ̇ in compression, −δ̇/e² in
    /// expansion (`expanding`, only for e > 0).
    #[inline]
    pub fn compression_rate(&self, rate: f64, expanding: bool) -> f64 {
        if expanding {
            -rate / self.restitution_sq
        } else {
            -rate
        }
    }

    /// The time scale of an approach at speed `speed` (m/s) through effective
    /// mass 1/`w` (w in 1/kg): the compression that stores its energy over
    /// the speed (s), about a third of the single contact's duration.
    pub fn time_scale(&self, speed: f64, w: f64) -> f64 {
        self.compression(0.5 * speed * speed / w) / speed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn energy_and_compression_are_inverse_and_match_the_power_law() {
        for alpha in [1.0, 1.5, 1.3] {
            let law = Law::new(2e8, alpha, 0.5);
            let q = 3e-5;
            let e = law.energy(q);
            // E = ∫ k q^α dq
            let closed = 2e8 * q.powf(alpha + 1.0) / (alpha + 1.0);
            assert!((e - closed).abs() <= 1e-12 * closed);
            assert!((law.compression(e) - q).abs() <= 1e-12 * q);
            assert!((law.force(q) - 2e8 * q.powf(alpha)).abs() <= 1e-12 * law.force(q));
            assert_eq!(law.force(-q), -law.force(q));
        }
    }

    #[test]
    fn expansion_runs_one_over_e_squared_faster() {
        let law = Law::new(1e9, 1.5, 0.5);
        assert_eq!(law.compression_rate(-2.0, false), 2.0);
        assert_eq!(law.compression_rate(2.0, true), -8.0);
    }
}
