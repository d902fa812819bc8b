//! What an impact resolution returns.

use serde::{Deserialize, Serialize};

use super::body::{Body, BodyVelocity};

/// Per-contact result of an impact.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactImpulse {
    /// Total normal impulse P_n ≥ 0 (N·s), acting on the second body along +n.
    pub normal_impulse: f64,
    /// Total tangential impulse P_t (N·s), acting on the second body along +t.
    pub tangent_impulse: f64,
    /// Largest potential energy E stored at the contact during the impact (J).
    pub peak_energy: f64,
}

/// Why the resolver stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum StopReason {
    /// No closed contact was approaching: nothing to resolve.
    NoApproach,
    /// Every contact released its energy and none approaches any more.
    Released,
    /// What was left of the impact was slower than
    /// [`crate::impact::ImpactSettings::rest_speed`]: no point approached
    /// faster, none stored the energy to rebound faster. The stored energy
    /// left was dropped; the slow approaches are the engine's to stop.
    AtRest,
}

/// Result of [`crate::impact::ImpactSolver::solve`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ImpactOutcome {
    /// Post-impact velocity of every body, in input order (fixed bodies keep 0).
    pub bodies: Vec<BodyVelocity>,
    /// Impulses and peak energy of every contact, in input order.
    pub contacts: Vec<ContactImpulse>,
    /// Kinetic energy of all bodies before the impact (J).
    pub kinetic_energy_before: f64,
    /// Kinetic energy of all bodies after the impact (J).
    pub kinetic_energy_after: f64,
    /// Duration of the impact (s) under the contact law F = k δ^α: the
    /// resolver tracks time as dt = dP_p / F_p to follow micro-gaps.
    pub duration: f64,
    /// Impulse steps taken (accepted steps in adaptive mode).
    pub steps: usize,
    /// Steps rejected by the adaptive error control.
    pub rejected_steps: usize,
    /// Right-hand-side evaluations the time-domain resolver spent settling
    /// the modes at the start and at each switch (0 for the impulse
    /// stepping). A step of the time-domain resolver evaluates six stages,
    /// so `settling_evaluations / 6` is the settling's cost in steps; the
    /// step limit counts it (`ImpactSettings::max_steps`), and so does the
    /// engines' work budget (`crate::coupling::FallbackPolicy::max_work`).
    #[serde(default)]
    pub settling_evaluations: usize,
    /// Why the resolver stopped.
    pub stop_reason: Option<StopReason>,
}

impl ImpactOutcome {
    /// Kinetic energy after the impact exceeds the energy before by more
    /// than rounding (10⁻⁹ relative). No stage of topple's impacts may
    /// create energy (the LZB law has e ≤ 1 and friction dissipates; the
    /// plastic solve re-solves without friction rather than return one).
    ///
    /// ```
    /// use topple::impact::ImpactOutcome;
    /// let mut out = ImpactOutcome::default();
    /// out.kinetic_energy_before = 1.0;
    /// out.kinetic_energy_after = 1.0 + 1e-12;
    /// assert!(!out.gains_energy());
    /// out.kinetic_energy_after = 1.01;
    /// assert!(out.gains_energy());
    /// ```
    pub fn gains_energy(&self) -> bool {
        self.kinetic_energy_after > self.kinetic_energy_before * (1.0 + 1e-9) + f64::MIN_POSITIVE
    }

    /// Sets `kinetic_energy_after` from the velocities after: ½ m v² + ½ I ω²
    /// of the free bodies (J), `bodies` giving their masses in the same order.
    pub(crate) fn set_kinetic_energy_after(&mut self, bodies: &[Body]) {
        self.kinetic_energy_after = bodies
            .iter()
            .zip(&self.bodies)
            .filter(|(b, _)| !b.fixed)
            .map(|(b, v)| {
                let [vx, vy] = v.velocity;
                0.5 * b.mass * (vx * vx + vy * vy)
                    + 0.5 * b.inertia * v.angular_velocity * v.angular_velocity
            })
            .sum();
    }
}
