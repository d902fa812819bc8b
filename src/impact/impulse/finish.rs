//! Stage 8: the outcome — body velocities, each contact's normal and
//! tangential impulse and peak stored energy, the impact time, and the kinetic
//! energies before and after (½ m v² + ½ I ω² of the free bodies; the tests
//! and the engines' guards check that it never grows, docs/model.md §2).

use super::super::{Body, BodyVelocity, ContactImpulse, ImpactOutcome, StopReason};
use super::data::ImpulseStepper;

impl ImpulseStepper {
    /// Writes the impact's result into `out`, reusing its vectors.
    pub(super) fn finish(&self, bodies: &[Body], reason: StopReason, out: &mut ImpactOutcome) {
        out.stop_reason = Some(reason);
        out.duration = self.elapsed;
        out.bodies.clear();
        out.bodies
            .extend(self.velocity[..bodies.len()].iter().map(|v| BodyVelocity {
                velocity: [v[0], v[1]],
                angular_velocity: v[2],
            }));
        out.contacts.clear();
        out.contacts
            .extend(self.state.iter().map(|s| ContactImpulse {
                normal_impulse: s.normal_impulse,
                tangent_impulse: s.tangent_impulse,
                peak_energy: s.peak_energy,
            }));
        out.set_kinetic_energy_after(bodies);
    }
}
