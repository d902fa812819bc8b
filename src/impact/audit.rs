//! An independent check of every impact an engine accepts, for the stress
//! sweep (`topple stress`): switched on per thread, it recomputes each
//! outcome from its input and impulses, so that a bug in the resolver's own
//! bookkeeping cannot hide a wrong answer.
//!
//! For each accepted impact (bodies with masses m, inertias I and velocities
//! before; contact points, normals and the impulses P_n n + P_t t acting on
//! the second body, −P on the first):
//!
//! * velocities after = velocities before + Σ P/m and ω + Σ (r × P)/I,
//!   compared with the velocities the engine applies (`consistency`);
//! * kinetic energy ½ m v² + ½ I ω² after ≤ before (`energy_gain`, relative);
//! * with every contact elastic (e = 1) and frictionless, and no fixed body
//!   or world in the group: energy and momentum are kept (`elastic_energy`,
//!   `momentum`, relative).
//!
//! Off (the default), a call costs one thread-local read.

use std::cell::RefCell;

use super::{Body, Contact, ImpactOutcome};

/// The worst of each measure over the impacts checked since
/// [`start`] (all relative, dimensionless).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AuditSummary {
    /// Impacts checked.
    pub impacts: usize,
    /// Impacts whose outcome held a NaN or an infinity.
    pub non_finite: usize,
    /// Largest (KE_after − KE_before)/KE_before.
    pub energy_gain: f64,
    /// Largest |applied − recomputed velocity| over the speed scale
    /// (the largest |v| + |ω| ρ before or after, ρ = √(I/m)).
    pub consistency: f64,
    /// Elastic frictionless free groups checked.
    pub elastic_impacts: usize,
    /// Largest |KE_after − KE_before|/KE_before of those.
    pub elastic_energy: f64,
    /// Largest |Σ m v_after − Σ m v_before| / Σ m |v_before| of those.
    pub momentum: f64,
}

thread_local! {
    static AUDIT: RefCell<Option<AuditSummary>> = const { RefCell::new(None) };
}

/// Starts checking the impacts of this thread (clears what was recorded).
pub fn start() {
    AUDIT.with(|a| *a.borrow_mut() = Some(AuditSummary::default()));
}

/// Stops checking and returns what was recorded since [`start`].
pub fn finish() -> AuditSummary {
    AUDIT.with(|a| a.borrow_mut().take().unwrap_or_default())
}

/// Whether this thread is checking impacts (between [`start`] and
/// [`finish`]). The Rapier pass then solves its impacts one instant at a
/// time on this thread, so that every one of them is checked.
pub fn is_on() -> bool {
    AUDIT.with(|a| a.borrow().is_some())
}

/// Records an accepted impact if this thread is checking (see [`start`]).
pub fn record(bodies: &[Body], contacts: &[Contact], out: &ImpactOutcome) {
    AUDIT.with(|a| {
        if let Some(s) = a.borrow_mut().as_mut() {
            check(bodies, contacts, out, s);
        }
    });
}

fn kinetic(m: f64, i: f64, v: [f64; 2], w: f64) -> f64 {
    0.5 * m * (v[0] * v[0] + v[1] * v[1]) + 0.5 * i * w * w
}

/// Checks one outcome into `s` (see the module docs).
pub fn check(bodies: &[Body], contacts: &[Contact], out: &ImpactOutcome, s: &mut AuditSummary) {
    s.impacts += 1;
    let finite = out.bodies.iter().all(|b| {
        b.velocity[0].is_finite() && b.velocity[1].is_finite() && b.angular_velocity.is_finite()
    });
    if !finite || out.bodies.len() != bodies.len() {
        s.non_finite += 1;
        return;
    }
    // velocities rebuilt from the impulses
    let mut v: Vec<[f64; 3]> = bodies
        .iter()
        .map(|b| [b.velocity[0], b.velocity[1], b.angular_velocity])
        .collect();
    let with_impulses = out.contacts.len() == contacts.len();
    if with_impulses {
        for (c, p) in contacts.iter().zip(&out.contacts) {
            let t = [-c.normal[1], c.normal[0]];
            let imp = [
                p.normal_impulse * c.normal[0] + p.tangent_impulse * t[0],
                p.normal_impulse * c.normal[1] + p.tangent_impulse * t[1],
            ];
            for (side, sign) in [(0, -1.0), (1, 1.0)] {
                let Some(k) = c.bodies[side] else { continue };
                let b = &bodies[k];
                if b.fixed {
                    continue;
                }
                let r = [c.point[0] - b.position[0], c.point[1] - b.position[1]];
                v[k][0] += sign * imp[0] / b.mass;
                v[k][1] += sign * imp[1] / b.mass;
                v[k][2] += sign * (r[0] * imp[1] - r[1] * imp[0]) / b.inertia;
            }
        }
    }
    let (mut ke0, mut ke1, mut scale) = (0.0, 0.0, 0.0f64);
    let (mut p0, mut p1, mut pabs) = ([0.0; 2], [0.0; 2], 0.0);
    let mut mismatch = 0.0f64;
    for (k, b) in bodies.iter().enumerate() {
        if b.fixed {
            continue;
        }
        let a = &out.bodies[k];
        let rho = (b.inertia / b.mass).sqrt();
        ke0 += kinetic(b.mass, b.inertia, b.velocity, b.angular_velocity);
        ke1 += kinetic(b.mass, b.inertia, a.velocity, a.angular_velocity);
        for (vel, w) in [
            (b.velocity, b.angular_velocity),
            (a.velocity, a.angular_velocity),
        ] {
            scale = scale.max(vel[0].hypot(vel[1]) + w.abs() * rho);
        }
        mismatch = mismatch
            .max((a.velocity[0] - v[k][0]).abs())
            .max((a.velocity[1] - v[k][1]).abs())
            .max((a.angular_velocity - v[k][2]).abs() * rho);
        for d in 0..2 {
            p0[d] += b.mass * b.velocity[d];
            p1[d] += b.mass * a.velocity[d];
        }
        pabs += b.mass * b.velocity[0].hypot(b.velocity[1]);
    }
    if ke0 <= 0.0 {
        return;
    }
    if with_impulses && scale > 0.0 {
        s.consistency = s.consistency.max(mismatch / scale);
    }
    s.energy_gain = s.energy_gain.max((ke1 - ke0) / ke0);
    let elastic = contacts.iter().all(|c| {
        c.material.restitution == 1.0
            && c.material.friction == 0.0
            && c.material.stick_friction == 0.0
    });
    let free = contacts
        .iter()
        .all(|c| c.bodies.iter().all(|b| b.is_some_and(|k| !bodies[k].fixed)));
    if elastic && free && pabs > 0.0 {
        s.elastic_impacts += 1;
        s.elastic_energy = s.elastic_energy.max(((ke1 - ke0) / ke0).abs());
        s.momentum = s.momentum.max((p1[0] - p0[0]).hypot(p1[1] - p0[1]) / pabs);
    }
}
