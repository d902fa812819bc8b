//! Stage 8: the outcome — velocities, impulses, peak energies — and the
//! energy guard.
//!
//! The law never creates kinetic energy (e ≤ 1 returns at most the work
//! stored, friction only dissipates), but a Runge–Kutta step conserves
//! energy only to its error, so an elastic impact can come out a few
//! tolerance-sized parts above its start. When no kinematic body moves (none
//! can do work on the group) and the kinetic energy after exceeds the one
//! before, every impulse is scaled by the s < 1 at which the energy is what
//! it was: v = v₀ + s Δv, P = s P, with ½ Δvᵀ M Δv s² + v₀ᵀ M Δv s = 0. The
//! change is of the size of the integration error, momentum stays balanced
//! by the impulses, and the outcome never gains energy.

use super::super::{Body, BodyVelocity, ContactImpulse, ImpactOutcome, StopReason};
use super::Integrator;

impl Integrator {
    /// Writes the outcome of the finished impact into `out`.
    pub(super) fn finish(&mut self, bodies: &[Body], reason: StopReason, out: &mut ImpactOutcome) {
        let lay = self.layout;
        out.stop_reason = Some(reason);
        out.duration = self.y[lay.time()];
        out.bodies.clear();
        out.bodies.extend((0..bodies.len()).map(|b| BodyVelocity {
            velocity: [self.y[3 * b], self.y[3 * b + 1]],
            angular_velocity: self.y[3 * b + 2],
        }));
        out.contacts.clear();
        out.contacts
            .extend(self.rows.iter().enumerate().map(|(i, row)| ContactImpulse {
                normal_impulse: self.y[lay.pn(i)],
                tangent_impulse: self.y[lay.pt(i)],
                peak_energy: row.law.energy(self.points[i].peak),
            }));
        out.set_kinetic_energy_after(bodies);
        let kinematic = bodies
            .iter()
            .any(|b| b.fixed && (b.velocity != [0.0, 0.0] || b.angular_velocity != 0.0));
        if !kinematic && out.kinetic_energy_after > out.kinetic_energy_before {
            guard(bodies, out);
        }
    }
}

/// Scales every impulse so that the kinetic energy is not above its start
/// (see the module docs); leaves `out` as it is if no such scale exists.
fn guard(bodies: &[Body], out: &mut ImpactOutcome) {
    let (mut quad, mut lin) = (0.0, 0.0);
    for (b, v) in bodies.iter().zip(&out.bodies).filter(|(b, _)| !b.fixed) {
        let dv = [v.velocity[0] - b.velocity[0], v.velocity[1] - b.velocity[1]];
        let dw = v.angular_velocity - b.angular_velocity;
        quad += 0.5 * (b.mass * (dv[0] * dv[0] + dv[1] * dv[1]) + b.inertia * dw * dw);
        lin += b.mass * (b.velocity[0] * dv[0] + b.velocity[1] * dv[1])
            + b.inertia * b.angular_velocity * dw;
    }
    let s = -lin / quad;
    if !(s > 0.0 && s < 1.0) {
        return;
    }
    for (b, v) in bodies
        .iter()
        .zip(out.bodies.iter_mut())
        .filter(|(b, _)| !b.fixed)
    {
        for k in 0..2 {
            v.velocity[k] = b.velocity[k] + s * (v.velocity[k] - b.velocity[k]);
        }
        v.angular_velocity = b.angular_velocity + s * (v.angular_velocity - b.angular_velocity);
    }
    for c in &mut out.contacts {
        c.normal_impulse *= s;
        c.tangent_impulse *= s;
    }
    out.set_kinetic_energy_after(bodies);
}
