//! The active set: the mode search among the closed contacts (paper
//! Eqs. 18–20, `modes.rs`) and the projection that keeps the pressing
//! contacts exactly closed, with its energy change booked.

use super::super::dynamics::{Active, RowConst, View};
use super::super::geometry::{Geom, Kin};
use super::super::modes::{initial_mode, select, Candidate, Search};
use super::Engine;

/// Slot `slot` of block `i` if it is a closed contact (gap ≤ `eps`, m)
/// between moving blocks, with its kinematics. Contacts with a frozen block
/// never press: a moving block that approaches a frozen one starts an
/// impact, which wakes it.
fn closed_between_moving(
    rc: &RowConst,
    view: &View,
    i: usize,
    slot: usize,
    eps: f64,
) -> Option<(Geom, Kin)> {
    let g = rc.geom(view, i, slot)?;
    if !g.valid || g.gap > eps {
        return None;
    }
    moving_kin(view, rc, &g).map(|k| (g, k))
}

/// The velocity terms of closed contact `g` if both its blocks move (the
/// ground counts as moving).
fn moving_kin(view: &View, rc: &RowConst, g: &Geom) -> Option<Kin> {
    if view.local(Some(g.corner)).is_none() || (g.face.is_some() && view.local(g.face).is_none()) {
        return None;
    }
    Some(rc.kin(view, g))
}

impl Engine {
    pub(super) fn set_active(&mut self) {
        for a in &self.active {
            self.is_active.set(a.block, a.slot, false);
        }
        std::mem::swap(&mut self.active, &mut self.new_active);
        for a in &self.active {
            self.is_active.set(a.block, a.slot, true);
        }
    }

    /// [`Engine::project`], then the closed contacts left out of the active
    /// set that the projection drives into approach join it and the
    /// projection is repeated from the same state: the velocities end on
    /// {active: δ̇ = 0, other closed contacts: δ̇ ≥ 0}.
    ///
    /// Used once impacts repeat at one instant (`handle_events`): a
    /// face-to-face pair (B_i and the heel contact closed together) can
    /// cycle there. The impact leaves the heel separating at 10⁻⁷ m/s, the
    /// mode search (acceleration level) does not need it, the projection of
    /// B_i turns the pair so that the heel approaches at 4·10⁻⁵ m/s, and the
    /// impact that follows at the same instant starts the cycle again (ideal
    /// Domino T rows with `heel_contacts`). Not used otherwise: where blocks
    /// chatter at the back of a Table 1 row, contacts joined this way are
    /// dropped by the next mode search and joined again thousands of times.
    pub(super) fn project_unilateral(&mut self) {
        let start = self.y.clone();
        let booked = self.energy.projection;
        for _ in 0..4 {
            let _ = self.project(false);
            let mut joined = std::mem::take(&mut self.new_active);
            joined.clear();
            {
                let view = self.view();
                let (rc, tol, eps, vapp) = (&self.rc, &self.tol, self.eps_gap, self.v_app);
                let is_active = &self.is_active;
                self.for_each_slot(&view, |i, slot| {
                    if is_active.contains(i, slot) {
                        return;
                    }
                    let Some((_, kk)) = closed_between_moving(rc, &view, i, slot, eps) else {
                        return;
                    };
                    if kk.gdot < -vapp {
                        joined.push(Active {
                            block: i,
                            slot,
                            mode: initial_mode(rc, slot, kk.vt, tol),
                        });
                    }
                });
            }
            if joined.is_empty() {
                self.new_active = joined;
                break;
            }
            joined.extend_from_slice(&self.active);
            // the band solve wants the contacts sorted by block
            joined.sort_by_key(|a| (a.block, a.slot));
            self.new_active = joined;
            self.set_active();
            self.y.copy_from_slice(&start);
            self.energy.projection = booked;
        }
    }

    /// Projection onto the active constraints, with its energy change booked;
    /// returns whether the active set changed. `at_forces`: the dynamics
    /// hold the forces of the active contacts at the present state
    /// (`forces_at_y1` of the step just taken), whose geometry the
    /// projection then reuses ([`Dynamics::project`]).
    ///
    /// [`Dynamics::project`]: super::super::dynamics::Dynamics::project
    pub(super) fn project(&mut self, at_forces: bool) -> bool {
        let before = self.window_energy();
        let (lo, hi) = (self.lo, self.hi);
        let mut act = std::mem::take(&mut self.new_active);
        act.clear();
        act.extend_from_slice(&self.active);
        let changed = self.dynamics.project(
            &self.rc,
            lo,
            hi,
            &mut self.y,
            &self.pos,
            &mut act,
            self.v_tol,
            at_forces,
        );
        self.new_active = act;
        if changed {
            self.set_active();
        }
        let after = self.window_energy();
        self.energy.projection += before - after;
        changed
    }

    /// The contact mode at the present state (paper Eqs. 18–20): the closed
    /// contacts between moving blocks that neither approach nor separate are
    /// the candidates, the active-set search picks which press and how they
    /// rub, and they become the active set.
    pub(super) fn choose_mode(&mut self) {
        // candidates: closed, valid, neither approaching nor separating
        let mut cands = std::mem::take(&mut self.candidates);
        cands.clear();
        {
            let view = self.view();
            let rc = &self.rc;
            let eps = self.eps_gap;
            let vt = self.v_tol;
            let vapp = self.v_app;
            let mut take = |i: usize, slot: usize, k: Kin| {
                if k.gdot >= -vapp && k.gdot <= vt {
                    cands.push(Candidate {
                        block: i,
                        slot,
                        vt: k.vt,
                    });
                }
            };
            // the impact stage's list of the closed contacts, when it holds
            // the present positions and window (the same contacts in the
            // same order as the scan below)
            let closed = &self.impact_buffers;
            if closed.closed_known {
                for &(i, slot, g) in &closed.closed {
                    if let Some(k) = moving_kin(&view, rc, &g) {
                        take(i, slot, k);
                    }
                }
            } else {
                self.for_each_slot(&view, |i, slot| {
                    if let Some((_, k)) = closed_between_moving(rc, &view, i, slot, eps) {
                        take(i, slot, k);
                    }
                });
            }
        }
        {
            let view = View {
                lo: self.lo,
                hi: self.hi,
                y: &self.y,
                pos: &self.pos,
            };
            // a search that does not converge keeps its last mode without
            // any pulling contact (see `select`); one that let a sliding
            // contact press without friction runs again after the next step
            let search = select(
                &mut self.dynamics,
                &self.rc,
                &view,
                &cands,
                &mut self.mode_state,
                &mut self.new_active,
                &self.tol,
            );
            self.mode_unsettled = search == Search::Frictionless;
        }
        self.candidates = cands;
        self.set_active();
    }
}
