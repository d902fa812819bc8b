//! The magnitudes of an impact given as data (`topple impact`'s JSON): the
//! resolver checks signs and finiteness; here values whose squares or
//! products would overflow or underflow are refused (kinetic energy m v²,
//! contact force k δ^α), so that no input ends in a misleading step-limit
//! error.

use super::{check_range, InputError};
use crate::impact::{Body, Contact};

/// Largest |position| (m), |velocity| (m/s), |angular velocity| (rad/s).
pub const MAX_MAGNITUDE: f64 = 1e6;
/// Mass (kg) and inertia (kg m²) of a free body: [1e-12, 1e12].
pub const MASS_RANGE: (f64, f64) = (1e-12, 1e12);
/// Smallest non-zero relative speed the resolver is given (m/s).
pub const MIN_SPEED: f64 = 1e-9;

/// Checks the magnitudes of an impact's bodies and contacts.
///
/// ```
/// use topple::impact::Body;
/// use topple::validate::impact;
/// let fast = Body { mass: 1.0, inertia: 0.1, position: [0.0, 0.0], angle: 0.0,
///                   velocity: [1e200, 0.0], angular_velocity: 0.0, fixed: false };
/// let e = impact(&[fast], &[]).unwrap_err();
/// assert_eq!(e.to_string(), "bodies[0].velocity[0] = 1e200: allowed -1e6 ≤ bodies[0].velocity[0] ≤ 1e6");
/// ```
pub fn impact(bodies: &[Body], contacts: &[Contact]) -> Result<(), InputError> {
    let m = MAX_MAGNITUDE;
    let mut fastest: f64 = 0.0;
    for (i, b) in bodies.iter().enumerate() {
        for k in 0..2 {
            check_range(&format!("bodies[{i}].position[{k}]"), b.position[k], -m, m)?;
            check_range(&format!("bodies[{i}].velocity[{k}]"), b.velocity[k], -m, m)?;
        }
        check_range(&format!("bodies[{i}].angle"), b.angle, -m, m)?;
        check_range(
            &format!("bodies[{i}].angular_velocity"),
            b.angular_velocity,
            -m,
            m,
        )?;
        if b.fixed {
            check_range(&format!("bodies[{i}].mass"), b.mass, 0.0, f64::MAX)?;
            check_range(&format!("bodies[{i}].inertia"), b.inertia, 0.0, f64::MAX)?;
        } else {
            let (lo, hi) = MASS_RANGE;
            check_range(&format!("bodies[{i}].mass"), b.mass, lo, hi)?;
            check_range(&format!("bodies[{i}].inertia"), b.inertia, lo, hi)?;
        }
        fastest = fastest
            .max(b.velocity[0].abs())
            .max(b.velocity[1].abs())
            .max(b.angular_velocity.abs());
    }
    if fastest > 0.0 && fastest < MIN_SPEED {
        return Err(InputError::new(
            "the fastest body speed",
            super::fmt_value(fastest),
            format!("0 or ≥ {MIN_SPEED:e} m/s (below, energies underflow)"),
        ));
    }
    for (i, c) in contacts.iter().enumerate() {
        for k in 0..2 {
            check_range(&format!("contacts[{i}].point[{k}]"), c.point[k], -m, m)?;
        }
        for (k, body) in c.bodies.iter().enumerate() {
            if let Some(b) = body
                && *b >= bodies.len()
            {
                return Err(InputError::new(
                    format!("contacts[{i}].bodies[{k}]"),
                    b,
                    format!("a body index < {} or null (the fixed world)", bodies.len()),
                ));
            }
        }
        if let [Some(a), Some(b)] = c.bodies
            && a == b
        {
            return Err(InputError::new(
                format!("contacts[{i}].bodies"),
                format!("[{a}, {b}]"),
                "two different bodies",
            ));
        }
        let len = c.normal[0].hypot(c.normal[1]);
        if !(len.is_finite() && (len - 1.0).abs() <= 1e-6) {
            return Err(InputError::new(
                format!("contacts[{i}].normal"),
                format!(
                    "[{}, {}]",
                    super::fmt_value(c.normal[0]),
                    super::fmt_value(c.normal[1])
                ),
                "a unit vector (length 1 ± 1e-6)",
            ));
        }
        let mat = &c.material;
        check_range(
            &format!("contacts[{i}].restitution"),
            mat.restitution,
            0.0,
            1.0,
        )?;
        check_range(
            &format!("contacts[{i}].stiffness"),
            mat.stiffness,
            1e-6,
            1e18,
        )?;
        check_range(&format!("contacts[{i}].exponent"), mat.exponent, 1.0, 3.0)?;
        check_range(&format!("contacts[{i}].friction"), mat.friction, 0.0, 5.0)?;
        check_range(
            &format!("contacts[{i}].stick_friction"),
            mat.stick_friction,
            0.0,
            5.0,
        )?;
    }
    Ok(())
}

/// Smallest and largest fixed impulse step ΔP/P₀ of the reference engine's
/// impacts (`--impact-step`): below, an impact takes more steps than its
/// limit; above, one step is a tenth of the impact.
pub const IMPACT_STEP_RANGE: (f64, f64) = (1e-9, 0.1);
/// Smallest and largest adaptive impulse tolerance (`--impact-tolerance`):
/// below, round-off; above, no accuracy left.
pub const IMPACT_TOLERANCE_RANGE: (f64, f64) = (1e-12, 0.1);

/// Checks the impulse stepping asked of the reference engine's impacts: a
/// fixed step ΔP/P₀ (`--impact-step`) or an adaptive tolerance
/// (`--impact-tolerance`), each optional.
///
/// ```
/// use topple::validate::impact_stepping;
/// assert!(impact_stepping(Some(1e-4), None).is_ok());
/// let e = impact_stepping(None, Some(0.5)).unwrap_err();
/// assert_eq!(e.to_string(), "--impact-tolerance = 0.5: allowed 1e-12 ≤ --impact-tolerance ≤ 0.1");
/// ```
pub fn impact_stepping(step: Option<f64>, tolerance: Option<f64>) -> Result<(), InputError> {
    if let Some(step) = step {
        let (lo, hi) = IMPACT_STEP_RANGE;
        check_range("--impact-step", step, lo, hi)?;
    }
    if let Some(tolerance) = tolerance {
        let (lo, hi) = IMPACT_TOLERANCE_RANGE;
        check_range("--impact-tolerance", tolerance, lo, hi)?;
    }
    Ok(())
}
