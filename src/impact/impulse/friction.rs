//! Stage 4: held points and Coulomb friction over a step, on the trial
//! velocities after the normal increments, by projected Gauss–Seidel sweeps
//! until the corrections are rounding.
//!
//! Equations (docs/model.md §4): a contact without slip at the step's start
//! stays stuck while that needs |dP_t| ≤ μ_s dP_n and otherwise slides the
//! way it is pushed, |dP_t| = μ dP_n; a sliding contact takes
//! dP_t = −μ sgn(v_t) dP_n against its slip at the start (the step lands
//! where that slip stops, landing.rs); a no-slip contact (μ = ∞, "The no-slip
//! ground") takes whatever dP_t stops its slip while dP_n > 0. A held e = 0
//! contact ([`ImpactSettings::e0_hold`]) takes the non-negative normal
//! impulse dP_h = max(0, dP_h − δ̇/W_nn) that keeps it from approaching, a
//! plastic unilateral constraint that does no work. Each contact is one
//! Gauss–Seidel row: load its increments, solve, store, apply the change.
//!
//! [`ImpactSettings::e0_hold`]: super::super::ImpactSettings::e0_hold

use super::data::{Axis, BodySlot, ContactState, ImpulseStepper, Row, Scratch};

/// Friction sweeps per step at most, and the slip correction (relative to
/// the velocity scale) below which they stop.
const FRICTION_SWEEPS: usize = 16;
const FRICTION_SETTLED: f64 = 1e-13;

impl ImpulseStepper {
    /// Step 4 (see the file docs): the step's held normal and tangential
    /// increments in the scratch, applied to the trial velocities.
    pub(super) fn held_and_friction(&mut self) {
        let Some(coupled) = self.prepare_sweeps() else {
            return;
        };
        let settled = FRICTION_SETTLED * self.scales.velocity;
        for _sweep in 0..FRICTION_SWEEPS {
            let largest_change = self.sweep();
            if largest_change <= settled || !coupled {
                break;
            }
        }
    }

    /// Zeroes the step's held and tangential increments and records which
    /// contacts are stuck at the start. `None` when no contact is held or
    /// rubs; else whether any reads the trial velocities (held, stuck and
    /// no-slip contacts): without them one sweep settles every impulse.
    fn prepare_sweeps(&mut self) -> Option<bool> {
        let threshold = self.scales.threshold;
        let (mut sweeping, mut coupled) = (false, false);
        for (row, (s, x)) in self
            .rows
            .iter()
            .zip(self.state.iter().zip(&mut self.scratch))
        {
            x.tangent_step = 0.0;
            x.held_step = 0.0;
            let stuck = row.tangent_rate(&self.velocity).abs() <= threshold;
            x.stuck_at_start = stuck;
            let rubbing = x.increment > 0.0 && row.has_friction();
            sweeping |= row.movable && (s.held || rubbing);
            coupled |= row.movable && (s.held || (rubbing && (stuck || row.no_slip())));
        }
        sweeping.then_some(coupled)
    }

    /// One Gauss–Seidel sweep over the contacts; returns the largest
    /// velocity correction it made (m/s).
    fn sweep(&mut self) -> f64 {
        let mut largest_change: f64 = 0.0;
        for (row, (s, x)) in self
            .rows
            .iter()
            .zip(self.state.iter_mut().zip(&mut self.scratch))
        {
            if !row.movable {
                continue;
            }
            if s.held {
                let moved = solve_held(row, x, &self.body_slots, &mut self.trial);
                largest_change = largest_change.max(moved);
            }
            let inc = x.increment + x.held_step;
            if inc <= 0.0 || !row.has_friction() {
                continue;
            }
            let moved = solve_friction(
                row,
                inc,
                (s, x),
                &self.velocity,
                &self.body_slots,
                &mut self.trial,
            );
            largest_change = largest_change.max(moved);
        }
        largest_change
    }
}

/// A held contact: the non-negative normal increment of the step that keeps
/// it from approaching. Returns the velocity correction (m/s).
#[inline]
fn solve_held(row: &Row, x: &mut Scratch, slots: &[BodySlot], trial: &mut [[f64; 3]]) -> f64 {
    let rate = row.normal_rate(trial);
    let wanted = (x.held_step - rate / row.w_nn).max(0.0);
    settle(
        row,
        row.normal_axis(),
        row.w_nn,
        &mut x.held_step,
        wanted,
        slots,
        trial,
    )
}

/// Coulomb friction of one contact whose normal increment in the step is
/// `inc` (N·s) > 0. Returns the velocity correction (m/s).
#[inline]
fn solve_friction(
    row: &Row,
    inc: f64,
    (s, x): (&mut ContactState, &mut Scratch),
    start_velocity: &[[f64; 3]],
    slots: &[BodySlot],
    trial: &mut [[f64; 3]],
) -> f64 {
    // A no-slip contact (μ = ∞) takes whatever tangential impulse stops its
    // slip, whether or not it slipped at the start: the limit μ → ∞ of the
    // sliding branch.
    let (value, sticking) = if x.stuck_at_start || row.no_slip() {
        let slip = row.tangent_rate(trial);
        let wanted = x.tangent_step - slip / row.w_tt;
        if wanted.abs() <= row.stick_friction.max(row.friction) * inc {
            (wanted, true)
        } else {
            (wanted.signum() * row.friction * inc, false)
        }
    } else {
        let slip = row.tangent_rate(start_velocity);
        (-slip.signum() * row.friction * inc, false)
    };
    s.sticking = sticking;
    settle(
        row,
        row.tangent_axis(),
        row.w_tt,
        &mut x.tangent_step,
        value,
        slots,
        trial,
    )
}

/// Sets a step's accumulated impulse along `axis` to `wanted`, applies the
/// difference to the bodies and returns the velocity correction it made
/// (|change| · W along the axis, m/s).
#[inline]
fn settle(
    row: &Row,
    axis: Axis,
    w: f64,
    accumulated: &mut f64,
    wanted: f64,
    slots: &[BodySlot],
    v: &mut [[f64; 3]],
) -> f64 {
    let change = wanted - *accumulated;
    if change == 0.0 {
        return 0.0;
    }
    *accumulated = wanted;
    row.apply(axis, change, slots, v);
    change.abs() * w
}
