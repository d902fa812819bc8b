//! Input checks, run before any stepping so that bad input is an error, never a
//! panic or a silent wrong answer.

use super::{Body, Contact, ImpactError, ImpactSettings, StepControl};
use crate::input::{fmt_value, InputError};

fn finite2(v: [f64; 2]) -> bool {
    v[0].is_finite() && v[1].is_finite()
}

pub(crate) fn check(
    bodies: &[Body],
    contacts: &[Contact],
    settings: &ImpactSettings,
) -> Result<(), ImpactError> {
    for (index, b) in bodies.iter().enumerate() {
        let bad = |reason: &str| ImpactError::InvalidBody {
            index,
            reason: reason.to_string(),
        };
        if !(b.mass.is_finite()
            && b.inertia.is_finite()
            && b.angle.is_finite()
            && b.angular_velocity.is_finite()
            && finite2(b.position)
            && finite2(b.velocity))
        {
            return Err(bad("a value is NaN or infinite"));
        }
        if !b.fixed && b.mass <= 0.0 {
            return Err(bad("mass must be > 0 on a free body"));
        }
        if !b.fixed && b.inertia <= 0.0 {
            return Err(bad("inertia must be > 0 on a free body"));
        }
    }
    for (index, c) in contacts.iter().enumerate() {
        let bad = |reason: String| ImpactError::InvalidContact { index, reason };
        for body in c.bodies.iter().flatten() {
            if *body >= bodies.len() {
                return Err(bad(format!(
                    "names body {body}, but there are {} bodies",
                    bodies.len()
                )));
            }
        }
        if let [Some(a), Some(b)] = c.bodies
            && a == b
        {
            return Err(bad(format!("joins body {a} to itself")));
        }
        let m = &c.material;
        if !(finite2(c.point)
            && finite2(c.normal)
            && m.stiffness.is_finite()
            && m.exponent.is_finite()
            && m.restitution.is_finite()
            && !m.friction.is_nan()
            && !m.stick_friction.is_nan())
        {
            return Err(bad("a value is NaN or infinite".into()));
        }
        let len = c.normal[0].hypot(c.normal[1]);
        if len < 1e-12 {
            return Err(bad("normal is zero".into()));
        }
        if (len - 1.0).abs() > 1e-6 {
            return Err(bad(format!("normal is not a unit vector (length {len})")));
        }
        if m.stiffness <= 0.0 {
            return Err(bad("stiffness must be > 0".into()));
        }
        if m.exponent <= 0.0 {
            return Err(bad("exponent must be > 0".into()));
        }
        if !(0.0..=1.0).contains(&m.restitution) {
            return Err(bad(format!(
                "restitution {} is outside [0, 1]",
                m.restitution
            )));
        }
        if m.friction < 0.0 {
            return Err(bad("friction must be >= 0".into()));
        }
        if m.stick_friction < 0.0 {
            return Err(bad("stick_friction must be >= 0".into()));
        }
    }
    match settings.step_control {
        StepControl::Fixed { impulse_step } => {
            if !(impulse_step > 0.0 && impulse_step <= 1.0) {
                return Err(ImpactError::InvalidSettings(InputError::new(
                    "impulse_step",
                    fmt_value(impulse_step),
                    "0 < impulse_step ≤ 1",
                )));
            }
        }
        StepControl::Adaptive { tolerance } | StepControl::AdaptiveImpulse { tolerance } => {
            if !(tolerance > 0.0 && tolerance < 1.0) {
                return Err(ImpactError::InvalidSettings(InputError::new(
                    "tolerance",
                    fmt_value(tolerance),
                    "0 < tolerance < 1",
                )));
            }
        }
    }
    if settings.fast_cycle.is_nan() || settings.fast_cycle < 0.0 {
        return Err(ImpactError::InvalidSettings(InputError::new(
            "fast_cycle",
            fmt_value(settings.fast_cycle),
            "fast_cycle ≥ 0",
        )));
    }
    if !(settings.rest_speed >= 0.0 && settings.rest_speed.is_finite()) {
        return Err(ImpactError::InvalidSettings(InputError::new(
            "rest_speed",
            fmt_value(settings.rest_speed),
            "finite rest_speed ≥ 0",
        )));
    }
    if settings.max_steps == 0 {
        return Err(ImpactError::InvalidSettings(InputError::new(
            "max_steps",
            0,
            "max_steps ≥ 1",
        )));
    }
    Ok(())
}
