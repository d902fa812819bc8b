//! Stage 1: the impact's frozen data — body slots, contact rows, the scales
//! P₀, the velocity scale and the approach threshold (docs/model.md §3, §6) —
//! and the initial state, into the buffers of data.rs.
//!
//! Equations: the diagonal
//! W_ii = m_a⁻¹ + (r_a×n)² I_a⁻¹ + m_b⁻¹ + (r_b×n)² I_b⁻¹ of the Delassus
//! operator (1/kg); the force prefactor c = (α+1)^(α/(α+1)) k^(1/(α+1)) of
//! F(E) = c E^(α/(α+1)) (docs/model.md §1); P₀ = max(|Σ m v| of the free
//! bodies, max_i |δ̇_i| / W_ii) (docs/model.md §3); the threshold 10⁻⁹ of
//! the largest approach speed (rounding left after a landing).

use super::super::contact::cross;
use super::super::{Body, Contact};
use super::data::{warped_nodes, BodySlot, ContactState, ImpulseStepper, Row, Scales, Scratch};

impl Row {
    /// The row of `c`: its frame, Delassus diagonal and law.
    fn new(c: &Contact, bodies: &[Body], slots: &[BodySlot]) -> Row {
        let frame = c.frame(bodies);
        let (a, b, normal, tangent) = (frame.a, frame.b, frame.normal, frame.tangent);
        let (ra, rb) = (frame.arm_a, frame.arm_b);
        let (a_rn, a_rt, b_rn, b_rt) = (
            cross(ra, normal),
            cross(ra, tangent),
            cross(rb, normal),
            cross(rb, tangent),
        );
        let (sa, sb) = (slots[a], slots[b]);
        let w = |arm_a: f64, arm_b: f64| {
            sa.inv_mass
                + arm_a * arm_a * sa.inv_inertia
                + sb.inv_mass
                + arm_b * arm_b * sb.inv_inertia
        };
        let m = &c.material;
        let a1 = m.exponent + 1.0;
        let w_nn = w(a_rn, b_rn);
        Row {
            a,
            b,
            normal,
            tangent,
            a_rn,
            a_rt,
            b_rn,
            b_rt,
            w_nn,
            w_tt: w(a_rt, b_rt),
            force_coeff: a1.powf(m.exponent / a1) * m.stiffness.powf(1.0 / a1),
            power: m.exponent / a1,
            exponent: m.exponent,
            restitution: m.restitution,
            friction: m.friction,
            stick_friction: m.stick_friction,
            movable: w_nn > 0.0,
        }
    }
}

impl ImpulseStepper {
    /// Builds body slots, rows, velocities and scales; sizes every buffer
    /// (allocating only when this impact is larger than any before).
    pub(super) fn load(&mut self, bodies: &[Body], contacts: &[Contact]) {
        self.body_slots.clear();
        self.velocity.clear();
        for b in bodies {
            self.body_slots.push(if b.fixed {
                BodySlot::default()
            } else {
                BodySlot {
                    inv_mass: 1.0 / b.mass,
                    inv_inertia: 1.0 / b.inertia,
                }
            });
            self.velocity
                .push([b.velocity[0], b.velocity[1], b.angular_velocity]);
        }
        self.body_slots.push(BodySlot::default());
        self.velocity.push([0.0; 3]);

        self.rows.clear();
        let slots = &self.body_slots;
        self.rows
            .extend(contacts.iter().map(|c| Row::new(c, bodies, slots)));

        if let Some(row) = self.rows.first() {
            let k = 1.0 / (1.0 - row.power);
            if k != self.warp.0 {
                self.warp = (k, warped_nodes(k));
            }
        }
        let n = self.rows.len();
        let nb = self.velocity.len();
        self.trial.resize(nb, [0.0; 3]);
        self.mid_velocity.resize(nb, [0.0; 3]);
        self.saved_velocity.resize(nb, [0.0; 3]);
        self.mid_state.resize(n, ContactState::default());
        self.saved_state.resize(n, ContactState::default());
        self.scratch.clear();
        self.scratch.resize(n, Scratch::default());
        self.state.clear();
        self.state.resize(n, ContactState::default());
        self.scales = self.measure_scales(bodies);
        // Contacts that start without slip are sticking.
        for (row, s) in self.rows.iter().zip(&mut self.state) {
            if row.movable {
                s.sticking = row.tangent_rate(&self.velocity).abs() <= self.scales.threshold;
            }
        }
    }

    /// P₀, the velocity scale and the approach threshold.
    fn measure_scales(&self, bodies: &[Body]) -> Scales {
        let mut momentum = [0.0, 0.0];
        for b in bodies.iter().filter(|b| !b.fixed) {
            momentum[0] += b.mass * b.velocity[0];
            momentum[1] += b.mass * b.velocity[1];
        }
        let mut speed: f64 = 0.0;
        let mut stopping_impulse: f64 = 0.0;
        for (row, s) in self.rows.iter().zip(&self.state) {
            if !row.movable {
                continue;
            }
            let rate = row.normal_rate(&self.velocity);
            if rate < 0.0 && s.gap == 0.0 {
                speed = speed.max(-rate);
                stopping_impulse = stopping_impulse.max(-rate / row.w_nn);
            }
        }
        Scales {
            impulse: momentum[0].hypot(momentum[1]).max(stopping_impulse),
            velocity: speed,
            // Relative rounding noise left after landing on a switch.
            threshold: 1e-9 * speed,
        }
    }
}
