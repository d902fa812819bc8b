//! Lower bounds on the gaps of the candidate slots, so that the event scan
//! of a step (`events.rs`) computes the exact geometry only of the slots
//! that can have closed since they were last measured.
//!
//! A slot's gap δ = n·(P − c) (`geometry::geom`) is a function of the two
//! blocks' configurations alone, and a Lipschitz one: moving the corner's
//! block by (Δx, Δφ) moves the corner P by at most |Δx| + r |Δφ| (r the
//! half diagonal, the farthest any corner or bottom point lies from the
//! centre); moving the face's block by Δx changes δ by at most |Δx|, and
//! turning it by Δφ with P held changes δ = n·(P − x_f) − d/2 by at most
//! |P − x_f| |Δφ|. Taking these moves one after the other from the
//! configuration where δ was measured, δ_ref, to any other:
//!
//! δ ≥ δ_ref − t_c − t_f − (ρ_ref + t_c + t_f) |Δφ_f|,
//! t_c = |Δx_c|₁ + r |Δφ_c|, t_f = |Δx_f|₁, ρ_ref = |P_ref − x_f,ref|,
//!
//! for the ground (a fixed face along x) δ ≥ δ_ref − |Δy_c| − r |Δφ_c|.
//! This holds for any two configurations, whatever happened between them
//! (steps, projections, rejected trials), so a bound measured once serves
//! every later scan until it no longer clears. To make the test a few
//! operations per slot, each moving block carries two running sums of its
//! moves between the configurations the scans see (each accepted state,
//! and the trial state a scan looks at, reached from the accepted one):
//! V = Σ |Δy| + r |Δφ| for the ground, T = Σ |Δx|₁ + R |Δφ| with the lever
//! R = 2h for the pairs. The travel of a block between two scans is at
//! most the difference of its sums, so a slot measured at gap δ_ref stays
//! open while δ_ref exceeds the travel of its corner's block (V, ground)
//! or of both blocks (T, pairs). For the pairs this needs ρ ≤ R along the
//! way: a pair slot is kept only where ρ_ref + δ_ref ≤ R, and as it stays
//! open only while the travel is below δ_ref, ρ ≤ ρ_ref + travel < R. A
//! block outside the window stands still (frozen or not yet struck); the
//! sums start again whenever the window changes. A slot whose bound stays
//! above `SAFETY` of the block height has a positive gap: the scan would
//! have done nothing with it (it neither closes, nor deepens the
//! penetration, nor is it the condition being followed), so skipping it
//! changes no bit of the run. `SAFETY` (10⁻⁹ h) is far above the rounding
//! of a gap (10⁻¹⁶ of the coordinates, 10⁻¹⁴ m at x = 100 m).
//!
//! Bounds are kept for the slots below `slots_per_block` of the moving
//! blocks (ground contacts, B_i, the heel, the pair contacts of a
//! neighbour), in a table that follows the window; the rare slots between
//! blocks that are not neighbours are always measured.

use super::super::dynamics::View;
use super::super::geometry::Geom;

/// A bound is used only while it clears zero by this fraction of h.
const SAFETY: f64 = 1e-9;

/// A slot's gap where it was last measured, less the safety margin, and
/// the running sums of its blocks there.
#[derive(Clone, Copy, Debug)]
struct GapRecord {
    /// δ_ref − safety (m).
    budget: f64,
    /// Window index of the corner's block, if it moves.
    corner: Option<usize>,
    /// Window index of the face's block, if it moves (`None` too for the
    /// ground).
    face: Option<usize>,
    /// Which sum the bound uses: V (ground) or T (pairs).
    sum: usize,
    /// The corner's and face's sums at the measurement (m).
    at_corner: f64,
    at_face: f64,
}

/// The [`GapRecord`]s of the window's near slots and the running sums of
/// the moving blocks.
#[derive(Debug, Default)]
pub(super) struct GapBounds {
    /// The window lo..hi the tables are laid out for.
    window: (usize, usize),
    /// Slots per block (`slots_per_block`).
    per_block: usize,
    /// The levers r (half diagonal) and R = 2h, the safety margin (m).
    reach: f64,
    lever: f64,
    safety: f64,
    records: Vec<Option<GapRecord>>,
    /// Per window block: its configuration at the last scan's accepted
    /// state, its sums [V, T] there, and its sums at the scan's state
    /// counted up (`ahead`) and down (`behind`) from them.
    last: Vec<[f64; 3]>,
    sums: Vec<[f64; 2]>,
    ahead: Vec<[f64; 2]>,
    behind: Vec<[f64; 2]>,
}

impl GapBounds {
    pub(super) fn new(per_block: usize, height: f64, thickness: f64) -> Self {
        GapBounds {
            per_block,
            reach: 0.5 * height.hypot(thickness),
            lever: 2.0 * height,
            safety: SAFETY * height,
            window: (usize::MAX, usize::MAX),
            ..Default::default()
        }
    }

    /// The moves [V, T] between two configurations of a block.
    #[inline]
    fn moves(&self, a: &[f64], b: &[f64]) -> [f64; 2] {
        let (dx, dy, dphi) = (
            (a[0] - b[0]).abs(),
            (a[1] - b[1]).abs(),
            (a[2] - b[2]).abs(),
        );
        [dy + self.reach * dphi, dx + dy + self.lever * dphi]
    }

    /// Starts a scan of the window lo..hi at the state `y1` (6 numbers per
    /// window block) reached from the accepted state `y`: the sums are
    /// brought up to `y`, then counted on to `y1` both ways. A new window
    /// drops every record and starts the sums again.
    pub(super) fn start(&mut self, lo: usize, hi: usize, y: &[f64], y1: &[f64]) {
        let nb = hi - lo;
        if self.window != (lo, hi) {
            self.window = (lo, hi);
            self.records.clear();
            self.records.resize(nb * self.per_block, None);
            self.last.clear();
            self.last
                .extend((0..nb).map(|b| [y[6 * b], y[6 * b + 1], y[6 * b + 2]]));
            self.sums.clear();
            self.sums.resize(nb, [0.0; 2]);
        }
        self.ahead.clear();
        self.behind.clear();
        for b in 0..nb {
            let (q, q1) = (&y[6 * b..6 * b + 3], &y1[6 * b..6 * b + 3]);
            let m = self.moves(q, &self.last[b]);
            let s = [self.sums[b][0] + m[0], self.sums[b][1] + m[1]];
            self.sums[b] = s;
            self.last[b] = [q[0], q[1], q[2]];
            let e = self.moves(q1, q);
            self.ahead.push([s[0] + e[0], s[1] + e[1]]);
            self.behind.push([s[0] - e[0], s[1] - e[1]]);
        }
    }

    /// Where slot `slot` of block `i` is kept, if it is.
    #[inline]
    pub(super) fn index(&self, i: usize, slot: usize) -> Option<usize> {
        let (lo, hi) = self.window;
        (i >= lo && i < hi && slot < self.per_block).then(|| (i - lo) * self.per_block + slot)
    }

    /// True if the slot kept at `k` certainly has a positive gap at the
    /// scan's state (see the module's bound).
    #[inline]
    pub(super) fn clear(&self, k: usize) -> bool {
        let Some(r) = self.records[k] else {
            return false;
        };
        let travel = |b: Option<usize>, at: f64| b.map_or(0.0, |b| self.ahead[b][r.sum] - at);
        r.budget > travel(r.corner, r.at_corner) + travel(r.face, r.at_face)
    }

    /// Keeps `g`, measured at the scan's state (`view`), at `k`.
    #[inline]
    pub(super) fn keep(&mut self, k: usize, g: &Geom, view: &View) {
        let local = |j: usize| view.local(Some(j));
        let (corner, face) = (local(g.corner), g.face.and_then(local));
        let budget = g.gap - self.safety;
        let sum = match g.face {
            None => 0,
            Some(f) => {
                let qf = view.q(f);
                let rho = (g.point[0] - qf[0]).hypot(g.point[1] - qf[1]);
                let within = rho + g.gap <= self.lever;
                if !within {
                    self.records[k] = None;
                    return;
                }
                1
            }
        };
        let at = |b: Option<usize>| b.map_or(0.0, |b| self.behind[b][sum]);
        self.records[k] = (budget > 0.0).then_some(GapRecord {
            budget,
            corner,
            face,
            sum,
            at_corner: at(corner),
            at_face: at(face),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::dynamics::View;
    use super::super::super::geometry::{geom, slots_per_block};
    use super::GapBounds;
    use crate::domino::Block;

    // Against the exact geometry: two blocks measured at random poses,
    // then moved at random through a chain of states (accepted states and
    // trial states off them, as the scans see them). Wherever a bound
    // clears, the slot's gap recomputed by `geom` is positive; and the
    // bounds do clear most slots of small moves (the test is not empty).
    #[test]
    fn a_cleared_slot_has_a_positive_gap() {
        let block = Block::new(0.08, 0.012);
        let lambda = 5;
        let k_slots = slots_per_block(lambda);
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut unit = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let pos = [[0.0; 3]; 2];
        let gap = |y: &[f64], slot: usize| {
            let view = View {
                lo: 0,
                hi: 2,
                y,
                pos: &pos,
            };
            geom(&block, lambda, 2, 0, slot, |j| view.q(j)).map(|g| g.gap)
        };
        let (mut cleared, mut checked) = (0, 0);
        for _ in 0..400 {
            let mut y = vec![0.0; 13];
            y[..3].copy_from_slice(&[0.0, 0.03 + 0.02 * unit(), (unit() - 0.5) * 2.0]);
            y[6..9].copy_from_slice(&[0.03 + 0.03 * unit(), 0.04, (unit() - 0.5) * 2.0]);
            let mut b = GapBounds::new(k_slots, block.height, block.thickness);
            b.start(0, 2, &y, &y);
            for slot in 0..k_slots {
                let view = View {
                    lo: 0,
                    hi: 2,
                    y: &y,
                    pos: &pos,
                };
                if let Some(g) = geom(&block, lambda, 2, 0, slot, |j| view.q(j)) {
                    b.keep(b.index(0, slot).unwrap(), &g, &view);
                }
            }
            let size = 10f64.powf(-4.0 + 3.0 * unit());
            for _ in 0..20 {
                // an accepted move, then a trial off it
                let mut step = |y: &mut Vec<f64>| {
                    for x in [0, 1, 2, 6, 7, 8] {
                        y[x] += size * (unit() - 0.5);
                    }
                };
                step(&mut y);
                let mut y1 = y.clone();
                step(&mut y1);
                b.start(0, 2, &y, &y1);
                for slot in 0..k_slots {
                    let Some(k) = b.index(0, slot) else { continue };
                    checked += 1;
                    if b.clear(k) {
                        cleared += 1;
                        let g = gap(&y1, slot).unwrap();
                        assert!(g > 0.0, "slot {slot}: cleared at gap {g}");
                    }
                }
            }
        }
        assert!(cleared * 10 > checked, "{cleared} of {checked}");
    }
}
