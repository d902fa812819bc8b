//! Resolve and continue: the group at the instant through the resolver
//! under the step's work budget, the events recorded, the changed bodies
//! moved on.

use super::super::hooks::ToppleHooks;
use super::super::motion::Path;
use crate::coupling::{FallbackPolicy, Resolution, ToppleSettings};

use super::{
    body_index, dynamic_parent, v2, ImpactContact, ImpactEvent, ImpactPass, World, NO_SLOT,
};

/// The settings an impact group is solved with: the step's work budget
/// `work_left` (the impacts of a step share it), the impact started at the
/// closing pairs' lowest `threshold` (an impact started below the frame's
/// threshold, a rebound, still ends at the frame's rest speed).
pub(super) fn budgeted(
    settings: &ToppleSettings,
    threshold: f64,
    work_left: Option<u64>,
) -> ToppleSettings {
    ToppleSettings {
        fallback: FallbackPolicy {
            max_work: work_left,
            ..settings.fallback
        },
        impact: settings.impact_settings(),
        min_approach_speed: threshold,
        ..*settings
    }
}

impl ImpactPass {
    /// Resolves the impacts at time `t`: the candidates closing then, with
    /// the group around them; then lets the changed bodies move on.
    pub(super) fn resolve_at(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        settings: &ToppleSettings,
        t: f64,
        offset: f64,
    ) -> usize {
        let threshold = self.build_at(world, hooks, settings, t);
        let budgeted = budgeted(settings, threshold, self.work_left);
        let groups = self
            .groups
            .resolve(&mut self.bodies, &self.contacts, &budgeted);
        self.finish_at(world, hooks, settings, t, offset, groups)
    }

    /// Builds the group of the impacts at time `t` into `bodies`, `handles`
    /// and `contacts`: the candidates closing then (marked done, their
    /// indices in `seeds`) and the bodies connected to them. Returns the
    /// lowest threshold of the closing pairs, which starts the impact.
    pub(super) fn build_at(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        settings: &ToppleSettings,
        t: f64,
    ) -> f64 {
        let at_once = 1e-9 * self.motion.dt;
        // the lowest threshold of the pairs closing now starts the impact
        let mut threshold = settings.min_approach_speed;
        self.bodies.clear();
        self.handles.clear();
        self.contacts.clear();
        self.queried.clear();
        self.seeds.clear();
        for k in 0..self.candidates.len() {
            let c = self.candidates[k];
            if c.done || c.toi > t + at_once {
                continue;
            }
            self.candidates[k].done = true;
            self.seeds.push(k);
            threshold = threshold.min(c.threshold);
            self.queried.push(c.key);
            self.note_reach(world, c.colliders[0]);
            self.note_reach(world, c.colliders[1]);
            self.query_pair(
                world,
                hooks,
                settings,
                c.colliders,
                t,
                world.allowed,
                false,
                0,
            );
        }
        // once the step's budget is spent, an impact is the closing pair
        // alone (and the walls it touches): its plastic solve stays small,
        // and Rapier's contact solver takes the neighbours as native Rapier
        // would (docs/bevy.md, "Bounded frames")
        let window = ToppleSettings {
            max_group_hops: if self.work_left == Some(0) {
                Some(0)
            } else {
                settings.max_group_hops
            },
            ..*settings
        };
        self.expand_group(world, hooks, &window, t);
        self.contact_points += self.contacts.len() as u64;
        for h in &self.handles {
            self.slot[body_index(*h)] = NO_SLOT;
        }
        threshold
    }

    /// After the groups built at `t` were solved (`groups` of them, in
    /// `groups`, with `bodies` holding their new velocities): the work
    /// taken from the step's budget, the events recorded, the changed
    /// bodies moved on. Returns `groups`.
    pub(super) fn finish_at(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        settings: &ToppleSettings,
        t: f64,
        offset: f64,
        groups: usize,
    ) -> usize {
        let work = self.groups.work();
        self.work += work;
        // the plastic fallback's sweeps (each over the impact's contact
        // points) spend the budget too, though they are not LZB work
        let sweeps: u64 = self.groups.reports()[..groups]
            .iter()
            .filter(|r| r.resolution == Resolution::Plastic)
            .map(|r| (r.steps * r.contacts) as u64)
            .sum();
        if let Some(left) = &mut self.work_left {
            *left = left.saturating_sub(work + sweeps);
        }
        self.record(offset + t, groups);
        self.move_on(world, hooks, settings, t, groups);
        groups
    }

    /// Keeps the reports, bodies and contacts of the groups just resolved.
    pub(super) fn record(&mut self, t: f64, groups: usize) {
        for g in 0..groups {
            let report = self.groups.reports()[g];
            self.reports.push(report);
            let b0 = self.event_bodies.len();
            for &i in self.groups.members(g) {
                self.event_bodies.push(self.handles[i]);
            }
            let c0 = self.event_contacts.len();
            for r in self.groups.records(g) {
                let handle = |i: Option<usize>| i.map(|i| self.handles[i]);
                self.event_contacts.push(ImpactContact {
                    bodies: [handle(r.bodies[0]), handle(r.bodies[1])],
                    point: r.point,
                    normal: r.normal,
                    normal_impulse: r.normal_impulse,
                    tangent_impulse: r.tangent_impulse,
                });
            }
            self.events.push(ImpactEvent {
                time_in_step: t,
                report,
                bodies: (b0, self.event_bodies.len()),
                contacts: (c0, self.event_contacts.len()),
            });
        }
    }

    /// The bodies whose velocity changed move on from `t` with the new
    /// velocity; their candidates get new times of impact, and their sweep
    /// over the rest of the step may add candidates.
    pub(super) fn move_on(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        s: &ToppleSettings,
        t: f64,
        groups: usize,
    ) {
        let dt = self.motion.dt;
        let first_new = self.candidates.len();
        let mut moved = false;
        for g in 0..groups {
            for m in 0..self.groups.members(g).len() {
                let i = self.groups.members(g)[m];
                let (h, b) = (self.handles[i], self.bodies[i]);
                let rb = &world.bodies[h];
                let path = self.motion.path(h, rb);
                let old = if path.changed {
                    (path.velocity, path.angular_velocity)
                } else {
                    (v2(rb.linvel()), f64::from(rb.angvel()))
                };
                if old == (b.velocity, b.angular_velocity) {
                    continue;
                }
                path.restart(t, dt, b.velocity, b.angular_velocity);
                moved = true;
                self.sweep(world, hooks, h);
            }
        }
        if !moved {
            return;
        }
        for k in 0..self.candidates.len() {
            if self.candidates[k].done {
                continue;
            }
            let touched = k >= first_new || self.candidate_moved(world, k, t);
            if touched {
                self.candidates[k].toi = self.time_of_impact(world, s, k);
            }
        }
    }

    /// A candidate has a body whose path restarted at `t`.
    pub(super) fn candidate_moved(&mut self, world: &World, k: usize, t: f64) -> bool {
        self.candidates[k].colliders.iter().any(|&c| {
            world
                .colliders
                .get(c)
                .and_then(|co| dynamic_parent(world, co))
                .is_some_and(|h| {
                    let rb = &world.bodies[h];
                    let p: Path = *self.motion.path(h, rb);
                    p.changed && p.t0 == t
                })
        })
    }
}
