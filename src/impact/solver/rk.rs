//! Stage 4: one Runge–Kutta step of the impact's equations and its error
//! norm (the pair itself, its stages and interpolant: tableau.rs).
//!
//! The embedded pair of Dormand and Prince (1980) of orders 5 and 4 with
//! seven stages, the last evaluated at the new state (first same as last, so
//! six evaluations per accepted step), and the continuous extension of order
//! 4 given by Hairer, Nørsett and Wanner (*Solving Ordinary Differential
//! Equations I*, 2nd ed., Sec. II.6): the state anywhere inside the step from
//! five coefficient vectors, which the event stage searches for switches.

use super::data::{normal_rate, PointMode, Variable};
use super::tableau::{error_estimate, scale, stage_state, Rk, C};
use super::Integrator;

impl Integrator {
    /// dt/dx at x and state `y` (see `Variable`); NaN where an ending
    /// point stops separating (its segment does not apply any more).
    fn slope(&self, x: f64, y: &[f64]) -> f64 {
        match self.clock.variable {
            Variable::Time => 1.0,
            Variable::Root => 2.0 * x,
            Variable::End { point, sigma } => {
                let row = &self.rows[point];
                let rate = normal_rate(row, y);
                if rate > 0.0 {
                    2.0 * (sigma - x) * row.law.restitution_sq() / rate
                } else {
                    f64::NAN
                }
            }
        }
    }

    /// One trial step of length `h` (in the segment's x, see `Clock`) from
    /// `rk.y0`; returns the error estimate over the tolerance (≤ 1:
    /// acceptable; NaN if the state is not finite). The stages hold dy/dx =
    /// dy/dt · dt/dx. The probe notes the switches seen at stages 2–7.
    pub(super) fn rk_step(&mut self, rk: &mut Rk, h: f64) -> f64 {
        let len = rk.y0.len();
        rk.h = h;
        rk.dense_ready = false;
        let x0 = self.clock.x;
        let lay = self.layout;
        let now = rk.y0[lay.time()];
        for i in 0..self.points.len() {
            let q0 = rk.y0[lay.q(i)];
            let q_zero = self.rows[i].q_zero;
            let open = self.points[i].mode == PointMode::Compress
                && (q0 < 0.0 || (q0 <= q_zero && self.onset_due(i, &rk.y0, now)));
            self.points[i].open = open;
            // a gap closed at this instant with an earlier switch was set
            // to q = 0 (events.rs, `close_with`): as a landed closing, it
            // closes again only once q leaves the rounding
            let closed_now = self.points[i].closed_at == now;
            self.points[i].close_at = if q0 > 0.0 || closed_now { q_zero } else { 0.0 };
        }
        if !rk.fresh {
            let (y0, k) = (&rk.y0, &mut rk.k[0]);
            if self.slope_current {
                // y0 is the state the modes were just settled at (or the
                // end of a segment checked by `ending_point`)
                k.copy_from_slice(&self.probe_slope);
            } else {
                self.eval(y0, k, false);
            }
            scale(k, self.slope(x0, y0));
            rk.fresh = true;
        }
        self.clear_suspects();
        // the inner stages need only what the right-hand side reads (the
        // velocities and compressions); the last one is the whole new state
        let core = self.layout.q(self.layout.contacts);
        for (s, &c) in C.iter().enumerate().skip(1) {
            let upto = if s == 6 { len } else { core };
            stage_state(&mut rk.stage[..upto], &rk.y0, &rk.k, s, h);
            let (stage, k) = (&rk.stage, &mut rk.k[s]);
            self.eval(stage, k, true);
            scale(k, self.slope(x0 + c * h, stage));
            if s == 6 {
                // the last stage is the new state (A[6] holds the weights b)
                rk.y1.copy_from_slice(&rk.stage);
            }
        }
        self.error_norm(rk, h)
    }

    /// max over the state's parts of |error| / scale, over the tolerance:
    /// body velocities against the velocity scale (ω through the radius of
    /// gyration), compressions against their own scale; the impulses are
    /// outputs and follow the velocities.
    fn error_norm(&self, rk: &mut Rk, h: f64) -> f64 {
        let lay = self.layout;
        let core = lay.q(lay.contacts);
        error_estimate(&mut rk.err[..core], &rk.k, h);
        let v = self.scales.velocity;
        let mut worst = 0.0f64;
        let (velocities, _) = rk.err[..3 * lay.bodies].as_chunks::<3>();
        for (slot, e) in self.bodies.iter().zip(velocities) {
            if slot.inv_mass == 0.0 {
                continue;
            }
            let e = e[0].abs().max(e[1].abs()).max(e[2].abs() * slot.gyration);
            worst = worst.max(e / v);
        }
        let compressions = &rk.err[lay.q(0)..core];
        for (row, e) in self.rows.iter().zip(compressions) {
            if row.movable {
                worst = worst.max(e.abs() / row.q_scale);
            }
        }
        if rk.y1.iter().all(|x| x.is_finite()) {
            worst / self.tolerance
        } else {
            f64::NAN
        }
    }
}
