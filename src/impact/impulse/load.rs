//! Stage 1: the impact's frozen data — body slots, contact rows, the scales
//! P₀, the velocity scale and the approach threshold (docs/model.md §3, §6) —
//! and the initial state; the kinematics every stage shares.
//!
//! Equations: the normal rate δ̇ = n·(v_b + ω_b × r_b − v_a − ω_a × r_a)
//! (negative while approaching, m/s) and its tangential twin; the diagonal
//! W_ii = m_a⁻¹ + (r_a×n)² I_a⁻¹ + m_b⁻¹ + (r_b×n)² I_b⁻¹ of the Delassus
//! operator (1/kg); the force prefactor c = (α+1)^(α/(α+1)) k^(1/(α+1)) of
//! F(E) = c E^(α/(α+1)) (docs/model.md §1); an impulse p along a direction
//! changes the velocities by ∓ M⁻¹ (dir, r × dir) p.

use super::super::contact::cross;
use super::super::{Body, Contact};
use super::energy::warped_nodes;
use super::{ImpulseStepper, Scratch};

/// Inverse mass (1/kg) and inverse inertia (1/(kg·m²)) of a body slot: 0
/// for fixed bodies and the world.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BodySlot {
    pub inv_mass: f64,
    pub inv_inertia: f64,
}

/// Frozen geometry and material of one contact.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Row {
    /// Body slots (the world is the last slot).
    pub a: usize,
    pub b: usize,
    pub normal: [f64; 2],
    pub tangent: [f64; 2],
    /// r×n and r×t for each body (r from the centre of mass to the point).
    pub a_rn: f64,
    pub a_rt: f64,
    pub b_rn: f64,
    pub b_rt: f64,
    /// Diagonal entries of the Delassus operator along n and t (1/kg).
    pub w_nn: f64,
    pub w_tt: f64,
    /// c = (α+1)^(α/(α+1)) k^(1/(α+1)), so F(E) = c E^(α/(α+1)).
    pub force_coeff: f64,
    /// α/(α+1).
    pub power: f64,
    pub exponent: f64,
    pub restitution: f64,
    pub friction: f64,
    pub stick_friction: f64,
    /// False when neither body can move: such a contact takes no part.
    pub movable: bool,
}

/// A direction of impulse with its moment arms r×dir on the two bodies.
#[derive(Clone, Copy, Debug)]
pub(super) struct Axis {
    pub dir: [f64; 2],
    pub arm_a: f64,
    pub arm_b: f64,
}

/// Evolving state of one contact.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ContactState {
    /// Stored potential energy E (J).
    pub energy: f64,
    pub normal_impulse: f64,
    pub tangent_impulse: f64,
    pub peak_energy: f64,
    /// Separation opened after release (m); the contact is closed while 0.
    pub gap: f64,
    /// Stick (true) or slip (false) for the friction law.
    pub sticking: bool,
    /// e = 0 contact whose compression has ended without separating: held
    /// closed by a non-negative impulse (the sliding-mode limit of e = 0).
    pub held: bool,
}

/// Scales of one impact, fixed at its start.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Scales {
    /// P₀ (N·s), see [`crate::impact::StepControl::Fixed`].
    pub impulse: f64,
    /// Largest approach speed at the start (m/s).
    pub velocity: f64,
    /// Rates above −threshold count as not approaching (m/s).
    pub threshold: f64,
}

impl Row {
    #[inline]
    pub fn normal_axis(&self) -> Axis {
        Axis {
            dir: self.normal,
            arm_a: self.a_rn,
            arm_b: self.b_rn,
        }
    }

    #[inline]
    pub fn tangent_axis(&self) -> Axis {
        Axis {
            dir: self.tangent,
            arm_a: self.a_rt,
            arm_b: self.b_rt,
        }
    }

    /// δ̇ = n·(v_b + ω_b × r_b − v_a − ω_a × r_a) (m/s).
    #[inline]
    pub fn normal_rate(&self, v: &[[f64; 3]]) -> f64 {
        let (va, vb) = (v[self.a], v[self.b]);
        self.normal[0] * (vb[0] - va[0]) + self.normal[1] * (vb[1] - va[1]) + vb[2] * self.b_rn
            - va[2] * self.a_rn
    }

    /// Tangential relative velocity along t (m/s).
    #[inline]
    pub fn tangent_rate(&self, v: &[[f64; 3]]) -> f64 {
        let (va, vb) = (v[self.a], v[self.b]);
        self.tangent[0] * (vb[0] - va[0]) + self.tangent[1] * (vb[1] - va[1]) + vb[2] * self.b_rt
            - va[2] * self.a_rt
    }

    /// Applies impulse `p` (N·s) along `axis` to the row's bodies: −p on a,
    /// +p on b.
    #[inline]
    pub fn apply(&self, axis: Axis, p: f64, slots: &[BodySlot], v: &mut [[f64; 3]]) {
        let Axis { dir, arm_a, arm_b } = axis;
        let (sa, sb) = (slots[self.a], slots[self.b]);
        let (ma, ia) = (sa.inv_mass * p, sa.inv_inertia * p);
        let va = &mut v[self.a];
        va[0] -= ma * dir[0];
        va[1] -= ma * dir[1];
        va[2] -= ia * arm_a;
        let (mb, ib) = (sb.inv_mass * p, sb.inv_inertia * p);
        let vb = &mut v[self.b];
        vb[0] += mb * dir[0];
        vb[1] += mb * dir[1];
        vb[2] += ib * arm_b;
    }

    /// The contact has friction along its tangent.
    #[inline]
    pub fn has_friction(&self) -> bool {
        self.w_tt > 0.0 && (self.friction > 0.0 || self.stick_friction > 0.0)
    }

    /// Unbounded friction (μ = ∞, [`ContactMaterial::no_slip`]): the
    /// contact never slides while it takes normal impulse.
    ///
    /// [`ContactMaterial::no_slip`]: super::super::ContactMaterial::no_slip
    #[inline]
    pub fn no_slip(&self) -> bool {
        self.friction == f64::INFINITY
    }

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
