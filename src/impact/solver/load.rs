//! Stage 1: the impact's frozen data — bodies, contact rows, friction
//! patches, scales — and the initial state vector.
//!
//! The state vector y holds, in this order: [vx, vy, ω] of every body slot
//! (the fixed world is the last slot), the compression q of every contact
//! (negative: an open gap), the normal and tangential impulses P_n, P_t of
//! every contact (outputs: they feed nothing back, but integrating them with
//! the same Runge–Kutta weights keeps v − M⁻¹ Jᵀ P exactly constant, so the
//! impulses reported explain the velocities) and the time since the impact
//! started (the independent variable is not always the time, see `Clock`).

use super::super::contact::cross;
use super::super::{Body, Contact};
use super::data::{Axis, BodySlot, Layout, Patch, PatchMode, PointState, Row, Scales};
use super::law::Law;
use super::Integrator;

/// Same direction, same arms: the tangential rows of two points coincide.
fn same_axis(x: &Axis, y: &Axis, length: f64) -> bool {
    let close = |p: f64, q: f64, scale: f64| (p - q).abs() <= 1e-9 * scale;
    close(x.dir[0], y.dir[0], 1.0)
        && close(x.dir[1], y.dir[1], 1.0)
        && close(x.arm_a, y.arm_a, length)
        && close(x.arm_b, y.arm_b, length)
}

impl Integrator {
    /// Builds every frozen datum and the initial state; sizes the buffers.
    pub(super) fn load(&mut self, bodies: &[Body], contacts: &[Contact]) {
        let world = bodies.len();
        self.layout = Layout {
            bodies: world + 1,
            contacts: contacts.len(),
        };
        self.bodies.clear();
        self.y.clear();
        for b in bodies {
            let slot = if b.fixed {
                BodySlot::default()
            } else {
                BodySlot {
                    inv_mass: 1.0 / b.mass,
                    inv_inertia: 1.0 / b.inertia,
                    gyration: (b.inertia / b.mass).sqrt(),
                }
            };
            self.bodies.push(slot);
            self.y
                .extend([b.velocity[0], b.velocity[1], b.angular_velocity]);
        }
        self.bodies.push(BodySlot::default());
        self.y.extend([0.0; 3]);

        // body size, for comparing moment arms
        let length = self
            .bodies
            .iter()
            .map(|s| s.gyration)
            .fold(0.0f64, f64::max)
            .max(f64::MIN_POSITIVE);

        self.rows.clear();
        self.patches.clear();
        self.members.clear();
        let mut tangents = std::mem::take(&mut self.tangents);
        tangents.clear();
        for c in contacts {
            let frame = c.frame(bodies);
            let (a, b, n, t) = (frame.a, frame.b, frame.normal, frame.tangent);
            let (ra, rb) = (frame.arm_a, frame.arm_b);
            let normal = Axis {
                dir: n,
                arm_a: cross(ra, n),
                arm_b: cross(rb, n),
            };
            let tangent = Axis {
                dir: t,
                arm_a: cross(ra, t),
                arm_b: cross(rb, t),
            };
            let w_nn = self.w(a, b, &normal, &normal);
            let m = &c.material;
            let (sa, sb) = (self.bodies[a], self.bodies[b]);
            self.rows.push(Row {
                a,
                b,
                normal,
                drive: normal,
                slide: 0.0,
                inverse: [sa.inv_mass, sa.inv_inertia, sb.inv_mass, sb.inv_inertia],
                law: Law::new(m.stiffness, m.exponent, m.restitution),
                patch: 0,
                w_nn,
                q_scale: 0.0,
                q_zero: 0.0,
                q_load: 0.0,
                movable: w_nn > 0.0,
            });
            tangents.push(tangent);
        }
        self.group_patches(contacts, &tangents, length);
        self.tangents = tangents;

        let n = contacts.len();
        let layout = self.layout;
        self.y.resize(layout.len(), 0.0);
        self.points.clear();
        self.points.resize(
            n,
            PointState {
                switched_at: f64::NAN,
                closed_at: f64::NAN,
                hold_limit: f64::INFINITY,
                ..PointState::default()
            },
        );
        self.patch_modes.clear();
        self.patch_modes
            .resize(self.patches.len(), PatchMode::default());
        self.patch_states.clear();
        self.patch_states
            .resize(self.patches.len(), Default::default());

        // Scales: the largest approach speed and the compression scales.
        let mut speed: f64 = 0.0;
        for i in 0..n {
            if self.rows[i].movable {
                speed = speed.max(-super::data::normal_rate(&self.rows[i], &self.y));
            }
        }
        let mut time = f64::INFINITY;
        for row in &mut self.rows {
            if row.movable && speed > 0.0 {
                row.q_scale = row.law.compression(0.5 * speed * speed / row.w_nn);
                row.q_zero = 1e-12 * row.q_scale;
                row.q_load = 1e-6 * row.q_scale;
                let rate = super::data::normal_rate(row, &self.y);
                if rate < 0.0 {
                    time = time.min(row.law.time_scale(-rate, row.w_nn));
                }
            }
        }
        self.scales = Scales {
            velocity: speed,
            rate: 1e-9 * speed,
            onset: 1e-3 * speed,
            time: if time.is_finite() { time } else { 0.0 },
            accel: if time.is_finite() && time > 0.0 {
                1e-9 * speed / time
            } else {
                0.0
            },
        };
        self.generation = 0;
        self.clock = super::Clock::default();
    }

    /// W = J_x M⁻¹ J_yᵀ for two axes on the same pair of body slots (1/kg).
    pub(super) fn w(&self, a: usize, b: usize, x: &Axis, y: &Axis) -> f64 {
        let (sa, sb) = (&self.bodies[a], &self.bodies[b]);
        let dot = x.dir[0] * y.dir[0] + x.dir[1] * y.dir[1];
        (sa.inv_mass + sb.inv_mass) * dot
            + sa.inv_inertia * x.arm_a * y.arm_a
            + sb.inv_inertia * x.arm_b * y.arm_b
    }

    /// Groups the contacts into friction patches (contacts of one body pair
    /// with the same tangential row and the same coefficients) and lists
    /// each patch's members contiguously in `members`.
    fn group_patches(&mut self, contacts: &[Contact], tangents: &[Axis], length: f64) {
        let n = contacts.len();
        self.order.clear();
        self.order.extend(0..n);
        let rows = &self.rows;
        self.order.sort_by_key(|&i| (rows[i].a, rows[i].b, i));
        let mut pair_start = 0; // first patch of the current body pair
        for k in 0..n {
            let i = self.order[k];
            let (a, b) = (self.rows[i].a, self.rows[i].b);
            if k > 0 {
                let prev = &self.rows[self.order[k - 1]];
                if (prev.a, prev.b) != (a, b) {
                    pair_start = self.patches.len();
                }
            }
            let m = &contacts[i].material;
            let stick_bound = m.stick_friction.max(m.friction);
            let found = (pair_start..self.patches.len()).find(|&p| {
                let patch = &self.patches[p];
                patch.friction == m.friction
                    && patch.stick_bound == stick_bound
                    && same_axis(&patch.tangent, &tangents[i], length)
            });
            self.rows[i].patch = found.unwrap_or_else(|| {
                let tangent = tangents[i];
                self.patches.push(Patch {
                    a,
                    b,
                    tangent,
                    w_tt: self.w(a, b, &tangent, &tangent),
                    friction: m.friction,
                    stick_bound,
                    first: 0,
                    count: 0,
                });
                self.patches.len() - 1
            });
        }
        // members, patch by patch (a counting sort)
        for i in 0..n {
            self.patches[self.rows[i].patch].count += 1;
        }
        let mut next = 0;
        for patch in &mut self.patches {
            patch.first = next;
            next += patch.count;
            patch.count = 0;
        }
        self.members.clear();
        self.members.resize(n, 0);
        for i in 0..n {
            let patch = &mut self.patches[self.rows[i].patch];
            self.members[patch.first + patch.count] = i;
            patch.count += 1;
        }
    }
}
