//! Impacts (paper Sec. 2.3): a closed contact approaching faster than the
//! velocity tolerance starts an impact of every body linked to it by closed
//! contacts; the group goes to the LZB resolver [`crate::impact`] with the
//! impact friction at `impact_friction_factor` × Table 1 (docs/model.md §4). A frozen
//! block struck by an approaching contact joins the moving set; frozen blocks
//! merely touching the group take no part in the impact (an approximation: the
//! tail at rest behind the wave would take a vanishing share of the impulse; if
//! the impact drives a block into it, that is a new impact which wakes it).

use super::super::geometry::{partner, surface, Surface};
use super::{Engine, EngineError, ImpactBuffers};
use crate::coupling::Resolution;
use crate::domino::Ground;
use crate::impact::{Body, Contact, ContactMaterial};

impl Engine {
    pub(super) fn material(&self, slot: usize) -> ContactMaterial {
        let p = &self.rc.p;
        let f = p.impact_friction_factor;
        let (k, e, mu, mus) = match surface(slot, p.lambda_points) {
            Surface::Ground => (p.k2, p.e2, p.mu2, p.mu2_stick),
            Surface::Block => (p.k1, p.e1, p.mu1, p.mu1_stick),
        };
        let material = ContactMaterial {
            stiffness: k,
            exponent: p.alpha,
            restitution: e,
            // Only the sliding coefficient is scaled (Table 1's footnote:
            // "the coefficient of sliding friction in impact"; docs/model.md §4);
            // a contact stuck at the start of an impulse step stays stuck
            // while that needs |dP_t| ≤ μ_s dP_n with the table's μ_s.
            friction: f * mu,
            stick_friction: mus,
        };
        // A no-slip ground holds the feet inside impacts too: unbounded
        // tangential impulse (μ = ∞ in the resolver), whatever the factor.
        if p.ground == Ground::NoSlip && surface(slot, p.lambda_points) == Surface::Ground {
            material.no_slip()
        } else {
            material
        }
    }

    /// Resolves the impacts present now, if any. Returns whether there was one.
    pub(super) fn resolve_impacts(&mut self) -> Result<bool, EngineError> {
        let mut buf = std::mem::take(&mut self.impact_buffers);
        let result = self.resolve_impacts_with(&mut buf);
        self.impact_buffers = buf;
        result
    }

    pub(super) fn resolve_impacts_with(
        &mut self,
        buf: &mut ImpactBuffers,
    ) -> Result<bool, EngineError> {
        self.find_approaching(buf)?;
        if buf.approaching.is_empty() {
            return Ok(false);
        }
        self.mark_group(buf);
        self.gather_group(buf);
        self.solve_group(buf)?;
        self.apply_outcome(buf);
        Ok(true)
    }

    /// Step 1: the closed contacts approaching faster than the impact
    /// threshold, into `buf.approaching`; the frozen blocks they strike are
    /// woken (the window grows) until none is left outside it. Every closed
    /// contact goes into `buf.closed` on the way, for the group (step 2)
    /// and for the next impact at this instant, which tests only those
    /// (`closed_known`: the positions and the window have not changed).
    pub(super) fn find_approaching(&mut self, buf: &mut ImpactBuffers) -> Result<(), EngineError> {
        loop {
            buf.approaching.clear();
            if !buf.closed_known {
                self.scan_closed(buf);
            }
            let view = self.view();
            let (mut new_lo, mut new_hi) = (self.lo, self.hi);
            for &(i, slot, g) in &buf.closed {
                let k = self.rc.kin(&view, &g);
                if k.gdot < -self.v_app {
                    buf.approaching.push((i, slot));
                    for b in [Some(g.corner), g.face].into_iter().flatten() {
                        if b < self.lo {
                            new_lo = new_lo.min(b);
                        }
                        if b >= self.hi {
                            new_hi = new_hi.max(b + 1);
                        }
                    }
                }
            }
            if (new_lo, new_hi) == (self.lo, self.hi) {
                return Ok(());
            }
            self.sync_out();
            self.lo = new_lo;
            self.hi = new_hi;
            self.rebuild_window()?;
            buf.closed_known = false;
        }
    }

    /// Every closed contact of the window (valid, gap within the gap
    /// tolerance) with its geometry into `buf.closed`, in slot order.
    fn scan_closed(&self, buf: &mut ImpactBuffers) {
        buf.closed.clear();
        let view = self.view();
        self.for_each_slot(&view, |i, slot| {
            if let Some(g) = self.rc.geom(&view, i, slot)
                && g.valid
                && g.gap <= self.eps_gap
            {
                buf.closed.push((i, slot, g));
            }
        });
        buf.closed_known = true;
    }

    /// Step 2: the group, `buf.in_group`: the blocks of the approaching
    /// contacts and the runs of moving blocks linked to them by the closed
    /// contacts of step 1.
    pub(super) fn mark_group(&self, buf: &mut ImpactBuffers) {
        let lambda = self.rc.p.lambda_points;
        let nb = self.hi - self.lo;
        let view = self.view();
        buf.linked.clear();
        buf.linked.resize(nb, false);
        buf.far_links.clear();
        for &(i, slot, _) in &buf.closed {
            let Some(j) = partner(i, slot, lambda) else {
                continue;
            };
            if i >= self.lo && j < self.hi {
                if j == i + 1 {
                    buf.linked[i - self.lo] = true;
                } else {
                    buf.far_links.push((i - self.lo, j - self.lo));
                }
            }
        }
        buf.in_group.clear();
        buf.in_group.resize(nb, false);
        for &(i, slot) in &buf.approaching {
            let g = self.rc.geom(&view, i, slot).expect("slot exists");
            for b in [Some(g.corner), g.face].into_iter().flatten() {
                if b >= self.lo && b < self.hi {
                    buf.in_group[b - self.lo] = true;
                }
            }
        }
        // spread along links (both directions), then along the links
        // between blocks that are not neighbours, until nothing joins
        loop {
            for b in 0..nb.saturating_sub(1) {
                if buf.in_group[b] && buf.linked[b] {
                    buf.in_group[b + 1] = true;
                }
            }
            for b in (0..nb.saturating_sub(1)).rev() {
                if buf.in_group[b + 1] && buf.linked[b] {
                    buf.in_group[b] = true;
                }
            }
            let mut joined = false;
            for &(a, b) in &buf.far_links {
                if buf.in_group[a] != buf.in_group[b] {
                    buf.in_group[a] = true;
                    buf.in_group[b] = true;
                    joined = true;
                }
            }
            if !joined {
                break;
            }
        }
    }

    /// Step 3: the group's bodies (`buf.bodies`, their blocks in
    /// `buf.members`) and its contacts (`buf.contacts`) for the resolver.
    pub(super) fn gather_group(&self, buf: &mut ImpactBuffers) {
        let nb = self.hi - self.lo;
        let p = self.rc.p;
        buf.index.clear();
        buf.index.resize(nb, None);
        buf.bodies.clear();
        buf.members.clear();
        for b in 0..nb {
            if buf.in_group[b] {
                buf.index[b] = Some(buf.bodies.len());
                let i = self.lo + b;
                let (q, v) = self.state(i);
                buf.bodies.push(Body {
                    mass: p.block.mass,
                    inertia: p.block.inertia(),
                    position: [q[0], q[1]],
                    angle: q[2],
                    velocity: [v[0], v[1]],
                    angular_velocity: v[2],
                    fixed: false,
                });
                buf.members.push(i);
            }
        }
        let (lo, hi) = (self.lo, self.hi);
        let (in_group, index) = (&buf.in_group, &buf.index);
        let to_body = |j: Option<usize>| -> Option<usize> {
            let j = j?;
            if j >= lo && j < hi && in_group[j - lo] {
                index[j - lo]
            } else {
                None
            }
        };
        buf.contacts.clear();
        for &(_, slot, g) in &buf.closed {
            let a = to_body(Some(g.corner));
            let f = to_body(g.face);
            if a.is_none() && f.is_none() {
                continue;
            }
            // A frozen block that is not struck takes no part: treating it as a
            // fixed wall can wedge a block between it and the ground so that no
            // finite impulse ends the impact; the tail behind the wave is at
            // rest and would take a negligible share anyway.
            let frozen = |j: usize| j < lo || j >= hi;
            if frozen(g.corner) || g.face.is_some_and(frozen) {
                continue;
            }
            buf.contacts.push(Contact {
                bodies: [f, a],
                point: g.point,
                normal: g.normal,
                material: self.material(slot),
            });
        }
    }

    /// Step 4: the solve, by the coupling layer's policy
    /// ([`crate::coupling::GroupSolver`], the same code as the Rapier
    /// adapter's): the paper's LZB law; for a group with e = 0 contacts
    /// that has not finished after `held_retry_after` resolver steps (a
    /// wedged group whose e = 0 contacts release and reload in ever smaller
    /// cycles), again with those contacts held closed, their limit (counted
    /// as a held impact); if that fails too, or an outcome would create
    /// kinetic energy, a plastic impact with Coulomb friction (counted as a
    /// fallback). Only input the resolver refuses (a non-finite state)
    /// fails the run.
    pub(super) fn solve_group(&mut self, buf: &mut ImpactBuffers) -> Result<(), EngineError> {
        let how = self
            .solver
            .solve_into(
                &buf.bodies,
                &buf.contacts,
                &self.impact,
                &self.policy,
                &mut buf.outcome,
            )
            .map_err(|source| EngineError::Impact {
                time: self.t,
                source,
            })?;
        match how {
            Resolution::Lzb | Resolution::Rejected => {}
            Resolution::Held => self.held_impacts += 1,
            Resolution::Plastic => self.impact_fallbacks += 1,
        }
        Ok(())
    }

    /// Step 5: the resolver's velocities into the state, with the counts and
    /// the energy bookkeeping.
    pub(super) fn apply_outcome(&mut self, buf: &mut ImpactBuffers) {
        let out = &buf.outcome;
        self.impacts += 1;
        self.energy.impacts += out.kinetic_energy_before - out.kinetic_energy_after;
        for (k, &i) in buf.members.iter().enumerate() {
            let bv = out.bodies[k];
            let off = 6 * (i - self.lo) + 3;
            self.y[off] = bv.velocity[0];
            self.y[off + 1] = bv.velocity[1];
            self.y[off + 2] = bv.angular_velocity;
        }
        self.sync_out();
    }
}
