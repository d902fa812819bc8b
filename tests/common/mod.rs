#![allow(dead_code)]
pub mod compliant;
pub mod cooperative;
pub mod hertz;
pub mod leaning;

use topple::impact::BodyVelocity;

/// The largest difference between two outcomes' body velocities (m/s): the
/// components of v, and ω times the radius of gyration `rho` (m) so that
/// turning counts in the same unit.
pub fn velocity_distance(a: &[BodyVelocity], b: &[BodyVelocity], rho: f64) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| {
            (a.velocity[0] - b.velocity[0])
                .abs()
                .max((a.velocity[1] - b.velocity[1]).abs())
                .max(rho * (a.angular_velocity - b.angular_velocity).abs())
        })
        .fold(0.0, f64::max)
}
