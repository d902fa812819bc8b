//! What happened inside a step (a closed contact approaching, lift-off,
//! stick → slip, slip reversal, a contact leaving its face) and the answer
//! at the located instant: impacts until none is left, hits, the contact
//! mode, the projection, the derivative for the next step.

use super::super::dynamics::{Mode, View};
use super::{Engine, EngineError, EventKey};

impl Engine {
    /// True if any event happened in state `y1` (the dynamics must hold the
    /// forces at `y1`). Also tracks the deepest penetration.
    pub(super) fn events_at(&mut self, y1: &[f64]) -> bool {
        let mut event = false;
        // the margins of the conditions (> 0: violated) for `probe`; an
        // invalid contact has none
        let watch = self.probe.watch;
        let mut first: Option<(EventKey, f64)> = None;
        let mut watched: Option<f64> = None;
        let mut note = |key: EventKey, margin: f64, violated: bool| {
            if violated && first.is_none() {
                first = Some((key, margin));
            }
            if watch == Some(key) {
                watched = Some(margin);
            }
        };
        for (c, a) in self.active.iter().enumerate() {
            let d = &self.dynamics;
            let fnn = d.fn_[c];
            let lift = fnn < self.ref_fn[c] - self.tol.force;
            if !d.valid[c] || lift {
                event = true;
            }
            if d.valid[c] {
                let margin = (self.ref_fn[c] - self.tol.force - fnn) / self.tol.force;
                note(EventKey::Lift(c), margin, lift);
            }
            match a.mode {
                Mode::Stick => {
                    let excess = self.rc.stick_excess(a.slot, d.ft[c], fnn);
                    let limit = self.ref_stick[c] + self.tol.force;
                    if excess > limit {
                        event = true;
                    }
                    note(
                        EventKey::Stick(c),
                        (excess - limit) / self.tol.force,
                        excess > limit,
                    );
                }
                Mode::Slide(dir) => {
                    let limit = self.ref_slide[c] - 0.5 * self.v_tol;
                    if dir * d.vt[c] < limit {
                        event = true;
                    }
                    let margin = (limit - dir * d.vt[c]) / (0.5 * self.v_tol);
                    note(EventKey::Slide(c), margin, dir * d.vt[c] < limit);
                }
                Mode::Frictionless => {}
            }
        }
        // the candidate that is followed is measured even once an event
        // was found (the other candidates are then skipped, as before)
        let watch_slot = match watch {
            Some(EventKey::Close(i, slot)) => Some((i, slot)),
            _ => None,
        };
        let view = View {
            lo: self.lo,
            hi: self.hi,
            y: y1,
            pos: &self.pos,
        };
        let mut deepest = self.dynamics.gap.iter().cloned().fold(0.0f64, f64::min);
        let rc = &self.rc;
        let is_active = &self.is_active;
        let eps = self.eps_gap;
        let vapp = self.v_app;
        // a slot whose gap bound clears zero has no part in the scan
        // (`scan.rs`); the others are measured and their bounds renewed
        let mut bounds = std::mem::take(&mut self.gap_bounds);
        bounds.start(self.lo, self.hi, &self.y, y1);
        self.for_each_slot(&view, |i, slot| {
            let watched_slot = watch_slot == Some((i, slot));
            if is_active.contains(i, slot) || (event && !watched_slot) {
                return;
            }
            let kept = bounds.index(i, slot);
            if let Some(k) = kept
                && !watched_slot
                && bounds.clear(k)
            {
                return;
            }
            let Some(g) = rc.geom(&view, i, slot) else {
                return;
            };
            if let Some(k) = kept {
                bounds.keep(k, &g, &view);
            }
            if !g.valid {
                return;
            }
            let margin = (-eps - g.gap) / eps;
            if !event {
                deepest = deepest.min(g.gap);
            }
            if g.gap >= -eps {
                if watched_slot {
                    note(EventKey::Close(i, slot), margin, false);
                }
                return;
            }
            let kk = rc.kin(&view, &g);
            if kk.gdot < -vapp {
                note(EventKey::Close(i, slot), margin, !event);
                event = true;
            }
        });
        self.probe.first = first;
        self.probe.watched = watched;
        // The heel-on-front-face pairs inside the row are not contacts (see
        // for_each_slot) but their overlap is measured, so that the reported
        // penetration covers every corner the row can drive into a neighbour.
        let lambda = self.rc.p.lambda_points;
        for i in self.lo.saturating_sub(1)..self.hi.min(self.row.n.saturating_sub(2)) {
            let kept = bounds.index(i, lambda + 2);
            if kept.is_some_and(|k| bounds.clear(k)) {
                continue;
            }
            if let Some(g) = rc.geom(&view, i, lambda + 2) {
                if let Some(k) = kept {
                    bounds.keep(k, &g, &view);
                }
                if g.valid {
                    deepest = deepest.min(g.gap);
                }
            }
        }
        self.gap_bounds = bounds;
        self.max_penetration = self.max_penetration.max(-deepest);
        event
    }

    /// Impacts, contact mode, projection; then the derivative for the next step.
    pub(super) fn handle_events(&mut self) -> Result<(), EngineError> {
        self.sync_out();
        self.impact_buffers.closed_known = false;
        let mut impacted = false;
        for _ in 0..20 {
            if !self.resolve_impacts()? {
                break;
            }
            impacted = true;
        }
        if impacted {
            if self.t - self.last_impact_time <= self.s.event_time_tolerance {
                self.impacts_at_this_instant += 1;
            } else {
                self.impacts_at_this_instant = 0;
            }
            self.last_impact_time = self.t;
        }
        self.record_hits();
        self.choose_mode();
        if self.impacts_at_this_instant >= 2 {
            self.project_unilateral();
        } else {
            let _ = self.project(false);
        }
        self.eval_k0(true)
    }
}
