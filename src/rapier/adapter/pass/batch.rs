//! Batches: the impacts of the next instants of a step whose groups cannot
//! meet before the last of them, solved side by side.
//!
//! The sequential pass resolves one instant τ at a time: the group at the
//! earliest τ is built, solved, recorded, and its bodies move on (new times
//! of impact, new sweeps) before the next τ is looked for. A batch keeps
//! that order and its bits, and only the solves run side by side:
//!
//! 1. **Build**, one instant after another as the sequential pass would
//!    pick them (the earliest open candidate after the items before it
//!    marked theirs done): the group is built at its τ with the poses of
//!    that τ, paths looked at but not made ([`super::ImpactPass::build_path`]),
//!    every body it looks at noted (its *reach*: the bodies of its closing
//!    pairs and of every pair of a group body it enumerates, queried or
//!    not). An item joins the batch only if its reach holds no body of an
//!    earlier item's group (checked first on its closing pairs, before any
//!    query, then on the whole reach).
//! 2. **Solve** every item with the budget left at the batch's start, side
//!    by side (rayon with the `parallel` feature, in order without it);
//!    each item has its own [`ImpactGroups`] (resolver scratch kept between
//!    steps).
//! 3. **Apply** in τ order: before item j (j ≥ 1), the sequential pass
//!    would build exactly item j if no open candidate closes by τⱼ (plus the
//!    pass's 10⁻⁹ Δt of "at once") and the budget did not run out since the
//!    batch's start (an item built with the impact window is kept only
//!    while the budget lasts); else items j… are given back (their
//!    candidates open again) and the pass goes on from the earliest
//!    instant. An item whose solve might have depended on the budget the
//!    items before it spent is solved again with what they left
//!    ([`ImpactGroups::same_under`]). Its paths are made (in the order its
//!    build first looked at them), its events recorded, its bodies moved on;
//!    if their sweep finds a pair with a body a later item's build looked
//!    at, the later items are given back.
//!
//! Why that is the sequential result: applying item k changes (a) the
//! paths of its group's bodies from τₖ on, (b) the candidate list (new
//! pairs of those bodies from their sweeps) and the times of impact of
//! their pairs, (c) the budget. A later item j's build reads paths of its
//! reach only, none of them in k's group (a); it enumerates the candidates
//! of its group's colliders, and a new one with a body of its reach gives
//! it back (b); which candidates it starts from is the set closing by τⱼ,
//! checked before it is applied (b); its window depends on whether the
//! budget is spent, checked, and its solve on the budget, checked or
//! solved again (c). Applying j changes nothing k's build read, since k is
//! applied first. Paths are made in the sequential order, so
//! [`super::Motion::changed`] (the order of the write-back into Rapier,
//! which orders its island updates) is the same.

use super::super::backend::prelude::RigidBodyHandle;
use super::resolve::budgeted;
use super::{body_index, ImpactPass, World};
use crate::coupling::{ImpactGroups, PointContact, ToppleSettings};
use crate::impact::Body;

use super::super::hooks::ToppleHooks;

/// One instant of a batch: its group as built, then solved.
#[derive(Debug, Default)]
pub(super) struct Item {
    /// Its instant (s from the start of the step).
    t: f64,
    /// The lowest threshold of its closing pairs.
    threshold: f64,
    pub(super) groups: ImpactGroups,
    /// The group's bodies: their velocities before the solve in `start`,
    /// after it in `bodies`.
    bodies: Vec<Body>,
    start: Vec<Body>,
    handles: Vec<RigidBodyHandle>,
    contacts: Vec<PointContact>,
    /// The candidates its build marked done.
    seeds: Vec<usize>,
    /// The paths its build looked at that were not made yet, in order.
    fresh: Vec<RigidBodyHandle>,
    /// The pairs queried and contact points counted by its build.
    queried: u64,
    points: u64,
    /// Groups its solve found.
    solved: usize,
}

impl Item {
    /// Solves the item's groups with the work budget `left`.
    fn solve(&mut self, settings: &ToppleSettings, left: Option<u64>) {
        let settings = budgeted(settings, self.threshold, left);
        self.solved = self
            .groups
            .resolve(&mut self.bodies, &self.contacts, &settings);
    }
}

impl ImpactPass {
    /// Resolves the impacts from instant `t` on as a batch of at most `max`
    /// instants; returns the instants applied (at least one) and the groups
    /// resolved.
    pub(super) fn batch(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        settings: &ToppleSettings,
        t: f64,
        offset: f64,
        max: usize,
    ) -> (usize, usize) {
        let n = self.build_batch(world, hooks, settings, t, max);
        self.solve_batch(n, settings);
        let done = self.apply_batch(world, hooks, settings, n, offset);
        self.return_buffers(n);
        done
    }

    /// Gives the pass back the buffers its builds handed to the first `n`
    /// items (each build swapped the pass's for the item's, a rotation):
    /// every buffer stays with its owner from batch to batch, so each one
    /// grows to what its owner needs once and a steady scene allocates
    /// nothing.
    fn return_buffers(&mut self, n: usize) {
        for item in self.items[..n].iter_mut().rev() {
            std::mem::swap(&mut item.bodies, &mut self.bodies);
            std::mem::swap(&mut item.handles, &mut self.handles);
            std::mem::swap(&mut item.contacts, &mut self.contacts);
            std::mem::swap(&mut item.seeds, &mut self.seeds);
            std::mem::swap(&mut item.fresh, &mut self.fresh);
        }
    }

    /// Builds the items of a batch from instant `t` on; returns how many.
    fn build_batch(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        settings: &ToppleSettings,
        mut t: f64,
        max: usize,
    ) -> usize {
        self.stamp += 1;
        let mut n = 0;
        loop {
            if n > 0 && self.closing_claimed(world, t) {
                break;
            }
            let (queried, points) = (self.pairs_queried, self.contact_points);
            self.speculative = true;
            self.fresh.clear();
            self.reach.clear();
            let threshold = self.build_at(world, hooks, settings, t);
            self.speculative = false;
            if n > 0 && self.reach.iter().any(|&h| self.is_claimed(h)) {
                for &k in &self.seeds {
                    self.candidates[k].done = false;
                }
                (self.pairs_queried, self.contact_points) = (queried, points);
                break;
            }
            self.claim(n);
            if self.items.len() <= n {
                self.items.push(Item::default());
            }
            let item = &mut self.items[n];
            std::mem::swap(&mut item.bodies, &mut self.bodies);
            std::mem::swap(&mut item.handles, &mut self.handles);
            std::mem::swap(&mut item.contacts, &mut self.contacts);
            std::mem::swap(&mut item.seeds, &mut self.seeds);
            std::mem::swap(&mut item.fresh, &mut self.fresh);
            item.t = t;
            item.threshold = threshold;
            item.queried = self.pairs_queried - queried;
            item.points = self.contact_points - points;
            n += 1;
            match self.earliest() {
                Some(next) if n < max => t = next,
                _ => break,
            }
        }
        n
    }

    /// A candidate closing by `t` has a body of a group already in the
    /// batch.
    fn closing_claimed(&self, world: &World, t: f64) -> bool {
        let at_once = 1e-9 * self.motion.dt;
        self.candidates
            .iter()
            .filter(|c| !c.done && c.toi <= t + at_once)
            .flat_map(|c| c.colliders)
            .filter_map(|c| world.colliders.get(c).and_then(|co| co.parent()))
            .any(|h| self.is_claimed(h))
    }

    fn is_claimed(&self, h: RigidBodyHandle) -> bool {
        self.claimed.get(body_index(h)) == Some(&self.stamp)
    }

    /// Marks the group just built as item `n`'s and its reach as looked at
    /// by item `n`.
    fn claim(&mut self, n: usize) {
        for &h in &self.handles {
            let i = body_index(h);
            if self.claimed.len() <= i {
                self.claimed.resize(i + 1, 0);
            }
            self.claimed[i] = self.stamp;
        }
        for &h in &self.reach {
            let i = body_index(h);
            if self.reached.len() <= i {
                self.reached.resize(i + 1, (0, 0));
            }
            self.reached[i] = (self.stamp, n);
        }
    }

    /// Solves the first `n` items with the budget left now, side by side
    /// when there are two or more and the `parallel` feature is on.
    fn solve_batch(&mut self, n: usize, settings: &ToppleSettings) {
        let left = self.work_left;
        let items = &mut self.items[..n];
        for item in items.iter_mut() {
            item.start.clone_from(&item.bodies);
        }
        if n == 1 {
            items[0].solve(settings, left);
            return;
        }
        crate::par::for_each_mut(items, |item| item.solve(settings, left));
    }

    /// Applies the first `n` solved items in time order while they are
    /// what the sequential pass would do (module docs); gives the rest
    /// back. Returns the items applied and the groups resolved.
    fn apply_batch(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        settings: &ToppleSettings,
        n: usize,
        offset: f64,
    ) -> (usize, usize) {
        let at_start = self.work_left;
        let at_once = 1e-9 * self.motion.dt;
        let mut groups = 0;
        let mut applied = 0;
        while applied < n {
            let j = applied;
            let t = self.items[j].t;
            if j > 0 {
                let earlier = self.earliest().is_some_and(|e| e <= t + at_once);
                let spent = at_start != Some(0) && self.work_left == Some(0);
                if earlier || spent {
                    self.give_back(j, n);
                    break;
                }
            }
            let left = self.work_left;
            let item = &mut self.items[j];
            if !item.groups.same_under(at_start, left) {
                item.bodies.clone_from(&item.start);
                item.solve(settings, left);
                self.solved_again += 1;
            }
            for k in 0..self.items[j].fresh.len() {
                let h = self.items[j].fresh[k];
                self.motion.path(h, &world.bodies[h]);
            }
            let first_new = self.candidates.len();
            let solved = self.items[j].solved;
            self.swap_item(j);
            groups += self.finish_at(world, hooks, settings, t, offset, solved);
            self.swap_item(j);
            applied += 1;
            if n > 1 {
                self.batched += solved as u64;
            }
            if applied < n && self.new_pairs_reached(world, first_new, j) {
                self.give_back(applied, n);
                break;
            }
        }
        // the last groups applied are the grouping stage's (`groups()`)
        self.last_item = Some(applied - 1);
        (applied, groups)
    }

    /// Exchanges item `j`'s groups, bodies and handles with the pass's
    /// (done twice around applying it: each keeps its own).
    fn swap_item(&mut self, j: usize) {
        let item = &mut self.items[j];
        std::mem::swap(&mut item.groups, &mut self.groups);
        std::mem::swap(&mut item.bodies, &mut self.bodies);
        std::mem::swap(&mut item.handles, &mut self.handles);
    }

    /// A candidate added since index `first` has a body that an item after
    /// `j` looked at.
    fn new_pairs_reached(&self, world: &World, first: usize, j: usize) -> bool {
        self.candidates[first..]
            .iter()
            .flat_map(|c| c.colliders)
            .filter_map(|c| world.colliders.get(c).and_then(|co| co.parent()))
            .any(|h| {
                self.reached
                    .get(body_index(h))
                    .is_some_and(|&(stamp, item)| stamp == self.stamp && item > j)
            })
    }

    /// Gives items `from..n` back: their candidates open again, their
    /// queries uncounted (the sequential pass builds them later).
    fn give_back(&mut self, from: usize, n: usize) {
        for j in from..n {
            let item = &self.items[j];
            for &k in &item.seeds {
                self.candidates[k].done = false;
            }
            self.pairs_queried -= item.queried;
            self.contact_points -= item.points;
        }
    }
}
