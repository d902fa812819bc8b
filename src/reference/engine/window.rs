//! The window of moving blocks lo..hi (the paper's κ, Sec. 2.1): its
//! state vector, the energies it holds, the candidate slots that involve a
//! moving block, and freezing the blocks at rest at its back.

use super::super::dynamics::View;
use super::super::geometry::{
    back_top_slot, far_slot, near_pair_contacts, outlines_within, pair_slot, partner, x_extent,
    Corner, Side, PAIR_SLOTS,
};
use super::{Engine, EngineError};

impl Engine {
    /// Kinetic and potential energy of the whole row (J).
    pub(super) fn total_energy(&self) -> f64 {
        let (k, u) = self.energies();
        k + u
    }

    pub(super) fn energies(&self) -> (f64, f64) {
        self.energies_of(0, self.row.n)
    }

    /// Kinetic + potential energy of the moving blocks only (J): what a
    /// projection or impact can change, in O(window).
    pub(super) fn window_energy(&self) -> f64 {
        let (k, u) = self.energies_of(self.lo, self.hi);
        k + u
    }

    pub(super) fn energies_of(&self, from: usize, to: usize) -> (f64, f64) {
        let b = &self.rc.p.block;
        let g = self.rc.p.gravity;
        let mut k = 0.0;
        let mut u = 0.0;
        for i in from..to {
            let (q, v) = self.state(i);
            k += 0.5 * b.mass * (v[0] * v[0] + v[1] * v[1]) + 0.5 * b.inertia() * v[2] * v[2];
            u += b.mass * g * q[1];
        }
        (k, u)
    }

    /// Configuration and velocity of block i (reads the window state).
    pub(super) fn state(&self, i: usize) -> ([f64; 3], [f64; 3]) {
        if i >= self.lo && i < self.hi {
            let k = 6 * (i - self.lo);
            (
                [self.y[k], self.y[k + 1], self.y[k + 2]],
                [self.y[k + 3], self.y[k + 4], self.y[k + 5]],
            )
        } else {
            (self.pos[i], self.vel[i])
        }
    }

    /// Writes the window state back to `pos`/`vel`.
    pub(super) fn sync_out(&mut self) {
        for i in self.lo..self.hi {
            let k = 6 * (i - self.lo);
            self.pos[i] = [self.y[k], self.y[k + 1], self.y[k + 2]];
            self.vel[i] = [self.y[k + 3], self.y[k + 4], self.y[k + 5]];
        }
    }

    /// Rebuilds the window state from `pos`/`vel`.
    pub(super) fn sync_in(&mut self) {
        self.y.clear();
        for i in self.lo..self.hi {
            self.y.extend_from_slice(&self.pos[i]);
            self.y.extend_from_slice(&self.vel[i]);
        }
        self.y.push(0.0);
    }

    pub(super) fn view(&self) -> View<'_> {
        View {
            lo: self.lo,
            hi: self.hi,
            y: &self.y,
            pos: &self.pos,
        }
    }

    /// Every (block, slot) pair that can involve a moving block, sorted by
    /// block, at the configuration of `view`: the ground contacts of the
    /// moving blocks, B_i and (see below) the heel of every pair, the
    /// other corner–face contacts of a pair (`geometry::PAIR_SLOTS`) whose
    /// corner lies within 10⁻³ h of the other block, and the same contacts
    /// between blocks that are not neighbours ([`Engine::far_pairs`]). The
    /// others cannot be closed, so no caller needs them.
    pub(super) fn for_each_slot(&self, view: &View, mut f: impl FnMut(usize, usize)) {
        let lambda = self.rc.p.lambda_points;
        let n = self.row.n;
        let block = &self.rc.p.block;
        let margin = 1e-3 * block.height;
        let first = self.lo.saturating_sub(1);
        let mut extents = self.reach.extents.borrow_mut();
        let from = self.x_extents(view, 2.0 * margin, &mut extents);
        for i in from..first {
            self.far_pairs(view, i, &extents, margin, &mut f);
        }
        for i in first..self.hi.min(n) {
            if i >= self.lo {
                for slot in 0..=lambda {
                    f(i, slot);
                }
                f(i, back_top_slot(lambda));
            }
            if i + 1 >= n {
                continue;
            }
            f(i, pair_slot(0, lambda));
            // The heel of block i+1 against block i: by default only for the
            // last pair, where the last block lies on the ground. Inside the
            // row the heel and B_i converge to face-to-face contact at the
            // rest angle, where the two corner contacts make the contact and
            // impact problems degenerate (the paper's model has only A_i and
            // B_i there); `Settings::heel_contacts` turns them on everywhere.
            // Without it the heel is left out against every face of block i,
            // so that a heel sunk into its front face is not taken for a
            // contact with another face.
            let heel = i + 2 == n || self.s.heel_contacts;
            if heel {
                f(i, pair_slot(1, lambda));
            }
            near_pair_contacts(block, view.q(i), view.q(i + 1), margin, |k| {
                let (side, corner, _) = PAIR_SLOTS[k];
                if k >= 2 && (heel || !(side == Side::Ahead && corner == Corner::BackBottom)) {
                    f(i, pair_slot(k, lambda));
                }
            });
            if i >= from {
                self.far_pairs(view, i, &extents, margin, &mut f);
            }
        }
    }

    /// The broad phase of the far pairs: into `extents`, the x extent of
    /// every block from lo on that a moving block can reach within
    /// `margin` (m) — the window, and the untouched blocks ahead up to the
    /// first one beyond the window's right end (they stand where the row
    /// put them, in order) — each with the least left end from it on.
    /// Returns the first frozen block behind the window whose extent
    /// reaches the window's left end (`Reach::behind`).
    fn x_extents(&self, view: &View, margin: f64, extents: &mut Vec<[f64; 3]>) -> usize {
        let block = &self.rc.p.block;
        let (lo, hi) = (self.lo, self.hi);
        let (mut left, mut right) = (f64::INFINITY, f64::NEG_INFINITY);
        extents.clear();
        for i in lo..hi {
            let (a, b) = x_extent(block, view.q(i));
            left = left.min(a);
            right = right.max(b);
            extents.push([a, b, 0.0]);
        }
        for j in hi..self.row.n {
            let (a, b) = x_extent(block, view.q(j));
            if a > right + margin {
                break;
            }
            extents.push([a, b, 0.0]);
        }
        let mut least = f64::INFINITY;
        for e in extents.iter_mut().rev() {
            least = least.min(e[0]);
            e[2] = least;
        }
        self.reach.behind.partition_point(|e| e[2] < left - margin)
    }

    /// The contacts between block `i` and the blocks j ≥ i + 2 whose x
    /// extents overlap its own within 2 `margin` (m), at least one of the
    /// two moving, that pass the separating-axis test and have a corner
    /// within `margin` of the other ([`near_pair_contacts`]), given to `f`
    /// as far slots of block i. `extents` as [`Engine::x_extents`] made
    /// them (from block lo on); a frozen block i < lo takes its extent from
    /// `Reach::behind` and meets only the blocks from lo on. The scan along
    /// the row stops at the first block from which every left end lies
    /// beyond block i's reach.
    fn far_pairs(
        &self,
        view: &View,
        i: usize,
        extents: &[[f64; 3]],
        margin: f64,
        f: &mut impl FnMut(usize, usize),
    ) {
        let block = &self.rc.p.block;
        let lambda = self.rc.p.lambda_points;
        let lo = self.lo;
        let moving = |j: usize| j >= lo && j < self.hi;
        let grown = 2.0 * margin;
        let [left, right, _] = if i < lo {
            self.reach.behind[i]
        } else {
            extents[i - lo]
        };
        for j in (i + 2).max(lo)..lo + extents.len() {
            let [a, b, least] = extents[j - lo];
            if least > right + grown {
                break;
            }
            if a > right + grown || b < left - grown || !(moving(i) || moving(j)) {
                continue;
            }
            let (qi, qj) = (view.q(i), view.q(j));
            if !outlines_within(block, qi, qj, grown) {
                continue;
            }
            near_pair_contacts(block, qi, qj, margin, |k| f(i, far_slot(j - i, k, lambda)));
        }
    }

    /// Freezes blocks at rest at the back of the window.
    pub(super) fn freeze(&mut self) -> Result<bool, EngineError> {
        let vf = self.s.freeze_tolerance * self.rc.p.speed_scale();
        let af = self.s.freeze_tolerance * self.rc.p.gravity;
        let h = self.rc.p.block.height;
        let mut changed = false;
        let base = self.lo;
        self.sync_out();
        while self.lo < self.hi {
            let v = self.vel[self.lo];
            let a = self.dynamics.acc[self.lo - base];
            let slow = v[0].abs() < vf && v[1].abs() < vf && (v[2] * h).abs() < vf;
            let still = a[0].abs() < af && a[1].abs() < af && (a[2] * h).abs() < af;
            if !(slow && still) {
                break;
            }
            let b = &self.rc.p.block;
            self.energy.frozen +=
                0.5 * b.mass * (v[0] * v[0] + v[1] * v[1]) + 0.5 * b.inertia() * v[2] * v[2];
            self.vel[self.lo] = [0.0; 3];
            self.lo += 1;
            changed = true;
        }
        if changed {
            self.rebuild_window()?;
        }
        Ok(changed)
    }

    /// After lo/hi changed: drops contacts without a moving block, rebuilds the
    /// state vector and the derivative.
    pub(super) fn rebuild_window(&mut self) -> Result<(), EngineError> {
        let (lo, hi) = (self.lo, self.hi);
        let lambda = self.rc.p.lambda_points;
        self.new_active.clear();
        for a in &self.active {
            let moving = |j: usize| j >= lo && j < hi;
            let keep = moving(a.block) && partner(a.block, a.slot, lambda).is_none_or(moving);
            if keep {
                self.new_active.push(*a);
            }
        }
        // the frozen blocks behind the window: their x extents and the
        // running maximum of the right ends (`Reach::behind`)
        let block = &self.rc.p.block;
        let behind = &mut self.reach.behind;
        behind.truncate(lo);
        while behind.len() < lo {
            let (left, right) = x_extent(block, self.pos[behind.len()]);
            let before = behind.last().map_or(f64::NEG_INFINITY, |e| e[2]);
            behind.push([left, right, before.max(right)]);
        }
        self.set_active();
        self.sync_in();
        self.eval_k0(true)
    }
}
