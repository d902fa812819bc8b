//! Impact events and their groups, engine-agnostic: plain bodies and contact
//! points at the current positions in, post-impact velocities out.
//!
//! A closed contact (gap ≤ tolerance) of a pair that was not closed at the
//! previous pass, whose normal relative velocity δ̇ = n·(v₂ − v₁) is below
//! −`min_approach_speed`, starts an impact. (In discrete time a persistent
//! sliding contact shows small spurious approaches of order g·Δt and
//! v_t·ω·Δt; those are the engine's contact solver's business.) The free
//! bodies connected to it through closed contacts form its group (fixed bodies
//! do not connect); every closed contact touching the group takes part. Each
//! group is solved by the LZB resolver ([`crate::impact`]) and the new
//! velocities are written back, through the fallback policy of
//! [`super::fallback`]. An engine adapter (the Rapier one in
//! [`crate::rapier`], compiled for f64 and f32) only has to fill the two
//! slices.

use crate::impact::{Body, Contact, ContactMaterial, ImpactOutcome};

use super::fallback::{GroupSolver, Resolution};
use super::settings::ToppleSettings;

/// A contact point between two bodies (indices into the body slice; `None` is
/// the fixed world) at the current positions.
///
/// ```
/// use topple::impact::{Body, ContactMaterial};
/// use topple::coupling::{normal_velocity, PointContact};
/// // a ball falling at 2 m/s onto the ground (the world is the first body)
/// let bodies = [Body::new(1.0, 0.004).with_position([0.0, 0.1]).with_velocity([0.0, -2.0])];
/// let c = PointContact {
///     bodies: [None, Some(0)], point: [0.0, 0.0], normal: [0.0, 1.0], dist: 0.0,
///     material: ContactMaterial::hertz(1e8), persistent: false,
/// };
/// assert_eq!(normal_velocity(&bodies, &c), -2.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointContact {
    /// First and second body; the normal points from the first to the second.
    pub bodies: [Option<usize>; 2],
    /// Contact point, world frame (m).
    pub point: [f64; 2],
    /// Unit normal from the first body to the second.
    pub normal: [f64; 2],
    /// Signed gap (m); negative when penetrating.
    pub dist: f64,
    /// The contact law at this point.
    pub material: ContactMaterial,
    /// The pair was already in closed contact at the previous pass: a
    /// persistent (resting or sliding) contact never starts an impact, though
    /// it takes part in one that another contact starts.
    pub persistent: bool,
}

/// What one resolved impact did.
///
/// ```
/// let r = topple::coupling::ImpactReport::default();
/// assert!(r.kinetic_energy_after <= r.kinetic_energy_before);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ImpactReport {
    /// Free bodies in the group.
    pub bodies: usize,
    /// Contact points taking part (λ points counted one by one).
    pub contacts: usize,
    /// Fastest approach speed among the contacts that started it (m/s).
    pub approach_speed: f64,
    /// Kinetic energy of the group before (J).
    pub kinetic_energy_before: f64,
    /// Kinetic energy of the group after the impact (J).
    pub kinetic_energy_after: f64,
    /// Resolver impulse steps (plastic sweeps for a plastic fallback).
    pub steps: usize,
    /// How the impact was resolved (the fallback policy's stage).
    pub resolution: Resolution,
    /// A large group under a work budget, its LZB attempts capped
    /// ([`super::FallbackPolicy::large_group`]): a pile rather than a chain
    /// or a row's front.
    pub large_group: bool,
}

/// One contact of a resolved group, with the impulse it carried: what a game
/// needs to drive sound and particles.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ContactRecord {
    /// The two bodies, as indices into the caller's body slice (`None`: the
    /// fixed world).
    pub bodies: [Option<usize>; 2],
    /// Contact point, world frame (m).
    pub point: [f64; 2],
    /// Unit normal from the first body to the second.
    pub normal: [f64; 2],
    /// Normal impulse on the second body along the normal (N·s), ≥ 0.
    pub normal_impulse: f64,
    /// Tangential impulse on the second body along (−n_y, n_x) (N·s).
    pub tangent_impulse: f64,
}

const NONE: usize = usize::MAX;

/// Finds impact groups and solves them; keeps every buffer between calls, so
/// a steady scene allocates nothing.
///
/// The groups of the last call are kept: [`ImpactGroups::reports`], and for
/// each group its bodies ([`ImpactGroups::members`]) and contacts with their
/// impulses ([`ImpactGroups::records`]).
///
/// ```
/// use topple::impact::{Body, ContactMaterial};
/// use topple::coupling::{ImpactGroups, PointContact, ToppleSettings};
/// // two touching balls (r = 0.1 m), the first moving at 1 m/s
/// let mut bodies = [
///     Body::new(1.0, 0.004).with_velocity([1.0, 0.0]),
///     Body::new(1.0, 0.004).with_position([0.2, 0.0]),
/// ];
/// let contacts = [PointContact {
///     bodies: [Some(0), Some(1)], point: [0.1, 0.0], normal: [1.0, 0.0], dist: 0.0,
///     material: ContactMaterial::hertz(1e8), persistent: false,
/// }];
/// let mut groups = ImpactGroups::default();
/// assert_eq!(groups.resolve(&mut bodies, &contacts, &ToppleSettings::default()), 1);
/// assert_eq!(groups.members(0), &[0, 1]);
/// assert!((bodies[1].velocity[0] - 1.0).abs() < 1e-3);
/// assert!((groups.records(0)[0].normal_impulse - 1.0).abs() < 1e-3);
/// ```
#[derive(Debug, Default)]
pub struct ImpactGroups {
    solver: GroupSolver,
    parent: Vec<usize>,
    group_of_root: Vec<usize>,
    seeds: Vec<(usize, f64)>,
    body_start: Vec<usize>,
    body_order: Vec<usize>,
    contact_start: Vec<usize>,
    contact_order: Vec<usize>,
    group_speed: Vec<f64>,
    cursor_b: Vec<usize>,
    inside: Vec<bool>,
    adj_start: Vec<usize>,
    adj: Vec<usize>,
    depth: Vec<usize>,
    queue: Vec<usize>,
    cursor_c: Vec<usize>,
    local: Vec<usize>,
    group_bodies: Vec<Body>,
    group_contacts: Vec<Contact>,
    reports: Vec<ImpactReport>,
    records: Vec<ContactRecord>,
    /// The resolver's output, reused so that a steady scene allocates nothing.
    outcome: ImpactOutcome,
    /// Work of the LZB attempts of the last call, all groups together
    /// ([`super::FallbackPolicy::max_work`]).
    work: u64,
    /// Work of each group of the last call.
    group_work: Vec<u64>,
    /// The last call's cap on large groups ([`super::FallbackPolicy::large_group`]).
    large_group: Option<super::LargeGroup>,
    /// Whether the last call probed its large groups
    /// ([`super::FallbackPolicy::probe_large_groups`]).
    probe: bool,
}

#[inline]
fn velocity_at(b: &Body, p: [f64; 2]) -> [f64; 2] {
    let r = [p[0] - b.position[0], p[1] - b.position[1]];
    [
        b.velocity[0] - b.angular_velocity * r[1],
        b.velocity[1] + b.angular_velocity * r[0],
    ]
}

/// Normal relative velocity δ̇ = n·(v₂ − v₁) at a contact (m/s), negative
/// while approaching.
#[inline]
pub fn normal_velocity(bodies: &[Body], c: &PointContact) -> f64 {
    let v = |i: Option<usize>| match i {
        Some(i) if !bodies[i].fixed => velocity_at(&bodies[i], c.point),
        _ => [0.0, 0.0],
    };
    let (v1, v2) = (v(c.bodies[0]), v(c.bodies[1]));
    c.normal[0] * (v2[0] - v1[0]) + c.normal[1] * (v2[1] - v1[1])
}

/// The approach speed −δ̇ of a contact that starts an impact: closed, new
/// (not persistent), approaching faster than `min_approach_speed`, with a
/// free body on at least one side. `None` for every other contact.
pub fn seed_approach(bodies: &[Body], c: &PointContact, settings: &ToppleSettings) -> Option<f64> {
    if c.dist > settings.patch.closed_tolerance || c.persistent {
        return None;
    }
    let free = |i: Option<usize>| i.is_some_and(|i| !bodies[i].fixed);
    let vn = normal_velocity(bodies, c);
    (vn < -settings.min_approach_speed && (free(c.bodies[0]) || free(c.bodies[1]))).then_some(-vn)
}

impl ImpactGroups {
    /// A large group of `contacts` points had its LZB attempts bounded by
    /// its cap under the budget `left` as under any larger one
    /// ([`ImpactGroups::same_under`]).
    ///
    /// Without the progress probe the attempts need `floor(left/points) ≥
    /// cap + 2·margin` (`cap = work/points` steps). The probe
    /// ([`super::FallbackPolicy::probe_large_groups`]) comes first, its
    /// limit at most half the cap (at least two halvings) and its steps
    /// taken from the cap as from the budget, with one more margin kept
    /// back after it: `floor(left/points) ≥ cap + 3·margin`.
    fn cap_binds(&self, contacts: usize, left: u64) -> bool {
        let Some(large) = self.large_group else {
            return false;
        };
        let points = contacts.max(1) as u64;
        let (cap, margin) = (
            large.work / points,
            super::fallback::budget_margin(contacts),
        );
        let needed = if self.probe {
            cap + 3 * margin
        } else {
            cap + 2 * margin
        };
        left / points >= needed
    }

    /// The margins an impact that finished by the law kept back before its
    /// attempt ([`lzb_fits`]): one, and one more after a large group's
    /// progress probe.
    fn margins(&self, report: &ImpactReport) -> u64 {
        if report.large_group && self.probe {
            2
        } else {
            1
        }
    }
}

/// Whether the LZB work `work` of an impact of `contacts` points that
/// finished by the law's first attempt (after a large group's probe, if it
/// had one) is done the same under the budget `left`
/// ([`ImpactGroups::same_under`]): `floor(left/points) ≥ s + 1 +
/// margins·margin`, `s = work/points` its steps (the probe's and the
/// attempt's), with the `margins` the fallback policy kept back before the
/// attempt.
fn lzb_fits(work: u64, contacts: usize, left: u64, margins: u64) -> bool {
    let points = contacts.max(1) as u64;
    left / points >= work / points + 1 + margins * super::fallback::budget_margin(contacts)
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

impl ImpactGroups {
    /// The bodies and contacts of the group solved last, in the resolver's
    /// input form (the input of `topple impact`).
    pub fn last_group(&self) -> (&[Body], &[Contact]) {
        (&self.group_bodies, &self.group_contacts)
    }

    /// One report per group resolved by the last [`ImpactGroups::resolve`].
    pub fn reports(&self) -> &[ImpactReport] {
        &self.reports
    }

    /// Work of the LZB attempts of the last [`ImpactGroups::resolve`], all
    /// groups together: impulse steps (accepted and rejected) times each
    /// impact's contact points ([`super::FallbackPolicy::max_work`]).
    pub fn work(&self) -> u64 {
        self.work
    }

    /// Whether the last [`ImpactGroups::resolve`], called with the work
    /// budget `given` ([`super::FallbackPolicy::max_work`]), gave the same
    /// result as a call with the smaller budget `budget` would have: then
    /// the impacts of a step that were solved side by side, each with the
    /// budget left at the start, keep the budget's sequential meaning
    /// without being solved again.
    ///
    /// Sufficient, not necessary: the budgets are equal, or every group
    /// finished by the law's first attempt ([`Resolution::Lzb`]) with room
    /// to spare under `budget`, or was a large group whose cap, not the
    /// budget, bounded its attempts. The reason is in the fallback policy's
    /// code ([`super::GroupSolver`]): the budget enters an attempt only as
    /// its step limit, `floor(left / points) − margin` steps (the margin
    /// covers the step and two settlings an attempt may take past its
    /// limit, `2 + 2·(4 + 4·points)/6`), and the resolvers compare their
    /// step counters with that limit and use it for nothing else (the
    /// time-domain resolver's `attempts + settling/6 > limit`, the impulse
    /// resolvers' `attempts > limit` and `steps ≥ limit`). A first attempt
    /// that finished with `s` steps charged (work `s·points`, every counter
    /// it checked at most `s + 1`) takes the same steps under any limit of
    /// at least `s + 1`, so any budget with `floor(budget/points) ≥ s + 1 +
    /// margin` gives the same bits. A large group's attempts are limited
    /// by the smaller of what is left and its cap (`cap = work/points`
    /// steps, less what the first attempt took for the second, each after
    /// a margin): with `floor(budget/points) ≥ cap + 2·margin` the cap is
    /// the smaller under either budget, whatever the outcome (with the
    /// progress probe before them, whose steps the cap pays too, `cap +
    /// 3·margin`: one more margin is kept after the probe; a large group
    /// that finished by the law needs one margin more than a small one, for
    /// the same reason). The groups of
    /// one call share the budget, each checked with what the groups before
    /// it left.
    ///
    /// ```
    /// use topple::impact::{Body, ContactMaterial};
    /// use topple::coupling::{ImpactGroups, PointContact, ToppleSettings};
    /// let mut bodies = [
    ///     Body::new(1.0, 0.004).with_velocity([1.0, 0.0]),
    ///     Body::new(1.0, 0.004).with_position([0.2, 0.0]),
    /// ];
    /// let contacts = [PointContact {
    ///     bodies: [Some(0), Some(1)], point: [0.1, 0.0], normal: [1.0, 0.0], dist: 0.0,
    ///     material: ContactMaterial::hertz(1e8), persistent: false,
    /// }];
    /// let mut settings = ToppleSettings::default();
    /// settings.fallback.max_work = Some(50_000);
    /// let mut groups = ImpactGroups::default();
    /// groups.resolve(&mut bodies, &contacts, &settings);
    /// let work = groups.work();
    /// assert!(groups.same_under(Some(50_000), Some(50_000)));
    /// assert!(groups.same_under(Some(50_000), Some(work + 100)));
    /// assert!(!groups.same_under(Some(50_000), Some(work)));
    /// ```
    pub fn same_under(&self, given: Option<u64>, budget: Option<u64>) -> bool {
        if given == budget {
            return true;
        }
        let (Some(given), Some(budget)) = (given, budget) else {
            return false; // a budget and none: the limits differ
        };
        let mut spent = 0u64;
        for (report, &work) in self.reports.iter().zip(&self.group_work) {
            let left = budget.saturating_sub(spent);
            if given.saturating_sub(spent) == left {
                return true; // the rest sees the same budget
            }
            let capped = report.large_group && self.cap_binds(report.contacts, left);
            let fits = report.resolution == Resolution::Lzb
                && lzb_fits(work, report.contacts, left, self.margins(report));
            if !capped && !fits {
                return false;
            }
            spent += work;
        }
        true
    }

    /// The free bodies of group `g` of the last call (indices into the body
    /// slice it was given), in index order.
    pub fn members(&self, g: usize) -> &[usize] {
        &self.body_order[self.body_start[g]..self.body_start[g + 1]]
    }

    /// The contacts of group `g` of the last call with their impulses.
    pub fn records(&self, g: usize) -> &[ContactRecord] {
        &self.records[self.contact_start[g]..self.contact_start[g + 1]]
    }

    /// Resolves every impact found in `contacts` and writes the post-impact
    /// velocities into `bodies`; returns the number of groups. Bodies with
    /// `fixed` never move and do not join groups. Never fails: a group the
    /// LZB law cannot finish goes through the fallback policy, and a group
    /// with invalid data keeps its velocities (see [`Resolution`]).
    pub fn resolve(
        &mut self,
        bodies: &mut [Body],
        contacts: &[PointContact],
        settings: &ToppleSettings,
    ) -> usize {
        self.reports.clear();
        self.records.clear();
        self.body_start.clear();
        self.body_start.push(0);
        self.contact_start.clear();
        self.contact_start.push(0);
        self.body_order.clear();
        self.work = 0;
        self.group_work.clear();
        self.large_group = settings.fallback.large_group;
        self.probe = settings.fallback.probe_large_groups;
        self.find_seeds(bodies, contacts, settings);
        if self.seeds.is_empty() {
            return 0; // the common case: nothing else is done
        }
        self.mark_window(bodies, contacts, settings);
        self.join_components(bodies, contacts, settings);
        let groups = self.number_groups(bodies, contacts);
        self.bucket(bodies, contacts, settings, groups);
        for g in 0..groups {
            self.solve_group(g, bodies, contacts, settings);
        }
        groups
    }

    /// Seeds: closed new contacts approaching fast enough.
    fn find_seeds(&mut self, bodies: &[Body], contacts: &[PointContact], s: &ToppleSettings) {
        self.seeds.clear();
        for (k, c) in contacts.iter().enumerate() {
            if let Some(approach) = seed_approach(bodies, c, s) {
                self.seeds.push((k, approach));
            }
        }
    }

    /// The window: free bodies within `max_group_hops` closed contacts of a
    /// body of a seed contact (breadth first); those outside act as absent.
    fn mark_window(&mut self, bodies: &[Body], contacts: &[PointContact], s: &ToppleSettings) {
        let n = bodies.len();
        let tol = s.patch.closed_tolerance;
        let free = |i: Option<usize>| i.filter(|&i| !bodies[i].fixed);
        self.inside.clear();
        self.inside.resize(n, s.max_group_hops.is_none());
        let Some(hops) = s.max_group_hops else {
            return;
        };
        self.adj_start.clear();
        self.adj_start.resize(n + 1, 0);
        let links = || {
            contacts
                .iter()
                .filter(move |c| c.dist <= tol)
                .filter_map(move |c| Some((free(c.bodies[0])?, free(c.bodies[1])?)))
        };
        for (a, b) in links() {
            self.adj_start[a + 1] += 1;
            self.adj_start[b + 1] += 1;
        }
        for i in 0..n {
            self.adj_start[i + 1] += self.adj_start[i];
        }
        self.adj.clear();
        self.adj.resize(self.adj_start[n], 0);
        self.cursor_b.clone_from(&self.adj_start);
        for (a, b) in links() {
            self.adj[self.cursor_b[a]] = b;
            self.cursor_b[a] += 1;
            self.adj[self.cursor_b[b]] = a;
            self.cursor_b[b] += 1;
        }
        self.depth.clear();
        self.depth.resize(n, NONE);
        self.queue.clear();
        for &(k, _) in &self.seeds {
            for i in contacts[k].bodies.iter().filter_map(|&i| free(i)) {
                if self.depth[i] == NONE {
                    self.depth[i] = 0;
                    self.queue.push(i);
                }
            }
        }
        let mut head = 0;
        while head < self.queue.len() {
            let i = self.queue[head];
            head += 1;
            self.inside[i] = true;
            if self.depth[i] < hops {
                for a in self.adj_start[i]..self.adj_start[i + 1] {
                    let j = self.adj[a];
                    if self.depth[j] == NONE {
                        self.depth[j] = self.depth[i] + 1;
                        self.queue.push(j);
                    }
                }
            }
        }
    }

    /// A free body inside the window, else `None`.
    #[inline]
    fn member(&self, bodies: &[Body], i: Option<usize>) -> Option<usize> {
        i.filter(|&i| !bodies[i].fixed && self.inside[i])
    }

    /// A contact reaching a free body outside the window is left out (not
    /// made a wall: a wall there could wedge the window shut).
    #[inline]
    fn crosses(&self, bodies: &[Body], c: &PointContact) -> bool {
        c.bodies
            .iter()
            .any(|&i| i.is_some_and(|i| !bodies[i].fixed && !self.inside[i]))
    }

    /// The union-find root of a contact's group, if it touches a member.
    #[inline]
    fn root_of(&mut self, bodies: &[Body], c: &PointContact) -> Option<usize> {
        let i = self
            .member(bodies, c.bodies[0])
            .or(self.member(bodies, c.bodies[1]))?;
        Some(find(&mut self.parent, i))
    }

    /// Connected components of window bodies through closed contacts.
    fn join_components(&mut self, bodies: &[Body], contacts: &[PointContact], s: &ToppleSettings) {
        self.parent.clear();
        self.parent.extend(0..bodies.len());
        for c in contacts
            .iter()
            .filter(|c| c.dist <= s.patch.closed_tolerance)
        {
            let (Some(a), Some(b)) = (
                self.member(bodies, c.bodies[0]),
                self.member(bodies, c.bodies[1]),
            ) else {
                continue;
            };
            let (ra, rb) = (find(&mut self.parent, a), find(&mut self.parent, b));
            if ra != rb {
                self.parent[ra.max(rb)] = ra.min(rb);
            }
        }
    }

    /// Numbers the seeded components in order of first seed (deterministic);
    /// returns how many there are.
    fn number_groups(&mut self, bodies: &[Body], contacts: &[PointContact]) -> usize {
        self.group_of_root.clear();
        self.group_of_root.resize(bodies.len(), NONE);
        self.group_speed.clear();
        for s in 0..self.seeds.len() {
            let (k, speed) = self.seeds[s];
            let Some(r) = self.root_of(bodies, &contacts[k]) else {
                continue; // a seed always has a free body; kept total anyway
            };
            if self.group_of_root[r] == NONE {
                self.group_of_root[r] = self.group_speed.len();
                self.group_speed.push(0.0);
            }
            let g = self.group_of_root[r];
            self.group_speed[g] = self.group_speed[g].max(speed);
        }
        self.group_speed.len()
    }

    /// The group of body `i`, if it is in one.
    #[inline]
    fn group_of_body(&mut self, bodies: &[Body], i: usize) -> Option<usize> {
        self.member(bodies, Some(i))?;
        let g = self.group_of_root[find(&mut self.parent, i)];
        (g != NONE).then_some(g)
    }

    /// The group of a closed contact that takes part, if any.
    #[inline]
    fn group_of_contact(
        &mut self,
        bodies: &[Body],
        c: &PointContact,
        s: &ToppleSettings,
    ) -> Option<usize> {
        if c.dist > s.patch.closed_tolerance || self.crosses(bodies, c) {
            return None;
        }
        let r = self.root_of(bodies, c)?;
        let g = self.group_of_root[r];
        (g != NONE).then_some(g)
    }

    /// Buckets bodies and closed contacts by group (counting sort).
    fn bucket(
        &mut self,
        bodies: &[Body],
        contacts: &[PointContact],
        s: &ToppleSettings,
        groups: usize,
    ) {
        self.body_start.clear();
        self.body_start.resize(groups + 1, 0);
        self.contact_start.clear();
        self.contact_start.resize(groups + 1, 0);
        for i in 0..bodies.len() {
            if let Some(g) = self.group_of_body(bodies, i) {
                self.body_start[g + 1] += 1;
            }
        }
        for c in contacts {
            if let Some(g) = self.group_of_contact(bodies, c, s) {
                self.contact_start[g + 1] += 1;
            }
        }
        for g in 0..groups {
            self.body_start[g + 1] += self.body_start[g];
            self.contact_start[g + 1] += self.contact_start[g];
        }
        self.body_order.clear();
        self.body_order.resize(self.body_start[groups], 0);
        self.contact_order.clear();
        self.contact_order.resize(self.contact_start[groups], 0);
        let mut cursor_b = std::mem::take(&mut self.cursor_b);
        let mut cursor_c = std::mem::take(&mut self.cursor_c);
        cursor_b.clone_from(&self.body_start);
        cursor_c.clone_from(&self.contact_start);
        for i in 0..bodies.len() {
            if let Some(g) = self.group_of_body(bodies, i) {
                self.body_order[cursor_b[g]] = i;
                cursor_b[g] += 1;
            }
        }
        for (k, c) in contacts.iter().enumerate() {
            if let Some(g) = self.group_of_contact(bodies, c, s) {
                self.contact_order[cursor_c[g]] = k;
                cursor_c[g] += 1;
            }
        }
        self.cursor_b = cursor_b;
        self.cursor_c = cursor_c;
    }

    /// Solves group `g` by the fallback policy, writes its velocities back and
    /// records its report and contact impulses.
    fn solve_group(
        &mut self,
        g: usize,
        bodies: &mut [Body],
        contacts: &[PointContact],
        s: &ToppleSettings,
    ) {
        self.local.resize(bodies.len(), NONE);
        self.group_bodies.clear();
        for &i in &self.body_order[self.body_start[g]..self.body_start[g + 1]] {
            self.local[i] = self.group_bodies.len();
            self.group_bodies.push(bodies[i]);
        }
        self.group_contacts.clear();
        for &k in &self.contact_order[self.contact_start[g]..self.contact_start[g + 1]] {
            let c = &contacts[k];
            let map = |i: Option<usize>| {
                i.filter(|&i| !bodies[i].fixed && self.inside[i])
                    .map(|i| self.local[i])
            };
            self.group_contacts.push(Contact::new(
                [map(c.bodies[0]), map(c.bodies[1])],
                c.point,
                c.normal,
                c.material,
            ));
        }
        // the groups of one call share the work budget
        let policy = super::FallbackPolicy {
            max_work: s.fallback.max_work.map(|w| w.saturating_sub(self.work)),
            ..s.fallback
        };
        let impact = s.impact_settings();
        let result = self.solver.solve_into(
            &self.group_bodies,
            &self.group_contacts,
            &impact,
            &policy,
            &mut self.outcome,
        );
        self.work += self.solver.last_work();
        self.group_work.push(self.solver.last_work());
        let resolution = result.unwrap_or(Resolution::Rejected);
        let out = &self.outcome;
        let members = &self.body_order[self.body_start[g]..self.body_start[g + 1]];
        if resolution != Resolution::Rejected {
            for (&i, v) in members.iter().zip(&out.bodies) {
                bodies[i].velocity = v.velocity;
                bodies[i].angular_velocity = v.angular_velocity;
            }
        }
        for (j, &k) in self.contact_order[self.contact_start[g]..self.contact_start[g + 1]]
            .iter()
            .enumerate()
        {
            let c = &contacts[k];
            let impulse = out
                .contacts
                .get(j)
                .filter(|_| resolution != Resolution::Rejected);
            self.records.push(ContactRecord {
                bodies: c.bodies,
                point: c.point,
                normal: c.normal,
                normal_impulse: impulse.map_or(0.0, |p| p.normal_impulse),
                tangent_impulse: impulse.map_or(0.0, |p| p.tangent_impulse),
            });
        }
        let ke_before: f64 = self.group_bodies.iter().map(Body::kinetic_energy).sum();
        self.reports.push(ImpactReport {
            bodies: self.group_bodies.len(),
            contacts: self.group_contacts.len(),
            approach_speed: self.group_speed[g],
            kinetic_energy_before: ke_before,
            kinetic_energy_after: if resolution == Resolution::Rejected {
                ke_before
            } else {
                out.kinetic_energy_after
            },
            steps: if resolution == Resolution::Rejected {
                0
            } else {
                out.steps
            },
            resolution,
            large_group: self.solver.last_was_large(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(x: f64, vx: f64) -> Body {
        Body::new(1.0, 0.004)
            .with_position([x, 0.0])
            .with_velocity([vx, 0.0])
    }

    fn touch(a: usize, b: usize, x: f64, persistent: bool) -> PointContact {
        PointContact {
            bodies: [Some(a), Some(b)],
            point: [x, 0.0],
            normal: [1.0, 0.0],
            dist: 0.0,
            material: ContactMaterial::hertz(1e8).with_restitution(0.0),
            persistent,
        }
    }

    #[test]
    fn separate_pairs_are_separate_groups_and_conserve_momentum() {
        // pair (0, 1) approaching, pair (2, 3) approaching, far apart
        let mut bodies = [
            ball(0.0, 1.0),
            ball(0.2, 0.0),
            ball(5.0, 0.0),
            ball(5.2, -2.0),
        ];
        let contacts = [touch(0, 1, 0.1, false), touch(2, 3, 5.1, false)];
        let mut groups = ImpactGroups::default();
        let n = groups.resolve(&mut bodies, &contacts, &ToppleSettings::default());
        let reports = groups.reports();
        assert_eq!(n, 2);
        assert_eq!((reports[0].bodies, reports[1].bodies), (2, 2));
        // e = 0 between equal masses: both move at the mean velocity
        for (pair, mean) in [([0, 1], 0.5), ([2, 3], -1.0)] {
            for i in pair {
                assert!(
                    (bodies[i].velocity[0] - mean).abs() < 1e-3,
                    "{i}: {:?}",
                    bodies[i]
                );
            }
        }
    }

    #[test]
    fn persistent_contacts_and_slow_approaches_start_nothing() {
        let mut bodies = [ball(0.0, 1.0), ball(0.2, 0.0)];
        let mut groups = ImpactGroups::default();
        let settings = ToppleSettings::default();
        let persistent = [touch(0, 1, 0.1, true)];
        assert_eq!(groups.resolve(&mut bodies, &persistent, &settings), 0);
        bodies[0].velocity[0] = 0.5 * settings.min_approach_speed;
        let slow = [touch(0, 1, 0.1, false)];
        assert_eq!(groups.resolve(&mut bodies, &slow, &settings), 0);
        assert!(groups.reports().is_empty());
    }

    #[test]
    fn fixed_bodies_do_not_join_groups_and_windows_cut_chains() {
        // 0 → 1 touching a fixed wall 2 that also touches 3 (at rest)
        let mut bodies = [
            ball(0.0, 1.0),
            ball(0.2, 0.0),
            Body::fixed(),
            ball(0.6, 0.0),
        ];
        bodies[2].position = [0.4, 0.0];
        let contacts = [
            touch(0, 1, 0.1, false),
            touch(1, 2, 0.3, false),
            touch(2, 3, 0.5, false),
        ];
        let mut groups = ImpactGroups::default();
        groups.resolve(&mut bodies, &contacts, &ToppleSettings::default());
        let r = groups.reports()[0];
        assert_eq!((r.bodies, r.contacts), (2, 2));
        assert_eq!(bodies[3].velocity, [0.0, 0.0]);
        // chain 0-1-2-3-4 of free balls; a window of 1 contact keeps 0, 1, 2
        let mut chain: Vec<Body> = (0..5)
            .map(|i| ball(0.2 * i as f64, if i == 0 { 1.0 } else { 0.0 }))
            .collect();
        let links: Vec<PointContact> = (0..4)
            .map(|i| touch(i, i + 1, 0.2 * i as f64 + 0.1, false))
            .collect();
        let settings = ToppleSettings {
            max_group_hops: Some(1),
            ..ToppleSettings::default()
        };
        groups.resolve(&mut chain, &links, &settings);
        let r = groups.reports()[0];
        assert_eq!((r.bodies, r.contacts), (3, 2));
        assert_eq!(groups.members(0), &[0, 1, 2]);
        assert_eq!(chain[3].velocity, [0.0, 0.0]);
    }

    /// `resolve` under a work budget of `work`, the whole group (no
    /// window): the velocities, reports and work.
    fn solved(
        bodies: &[Body],
        contacts: &[PointContact],
        work: u64,
    ) -> (Vec<Body>, Vec<ImpactReport>, u64, ImpactGroups) {
        let settings = ToppleSettings {
            fallback: super::super::FallbackPolicy {
                max_work: Some(work),
                ..super::super::FallbackPolicy::default()
            },
            max_group_hops: None,
            ..ToppleSettings::default()
        };
        let mut groups = ImpactGroups::default();
        let mut out = bodies.to_vec();
        groups.resolve(&mut out, contacts, &settings);
        (out, groups.reports().to_vec(), groups.work(), groups)
    }

    /// The smallest budget `same_under` accepts for the result solved with
    /// `given` gives that result's bits; for a group ended by the law and
    /// for a large group its cap ended plastic.
    #[test]
    fn the_smallest_budget_same_under_accepts_gives_the_same_bits() {
        // the captured pile landing (15 boxes, 33 points): a large group
        let input: serde_json::Value = serde_json::from_str(include_str!(
            "../../tests/data/pile-landing-33-contacts.json"
        ))
        .expect("the captured impact");
        let bodies: Vec<Body> = serde_json::from_value(input["bodies"].clone()).expect("bodies");
        let pile: Vec<Contact> =
            serde_json::from_value(input["contacts"].clone()).expect("contacts");
        let pile: Vec<PointContact> = pile
            .iter()
            .map(|c| PointContact {
                bodies: c.bodies,
                point: c.point,
                normal: c.normal,
                dist: 0.0,
                material: c.material,
                persistent: false,
            })
            .collect();
        // a cradle of 4 balls ended by the law
        let mut cradle: Vec<Body> = (0..4).map(|i| ball(0.2 * i as f64, 0.0)).collect();
        cradle[0].velocity[0] = 1.0;
        let links: Vec<PointContact> = (0..3)
            .map(|i| touch(i, i + 1, 0.2 * i as f64 + 0.1, false))
            .collect();
        let given = 50_000;
        for (name, bodies, contacts, large) in [
            ("pile", &bodies, &pile, true),
            ("cradle", &cradle, &links, false),
        ] {
            let (v0, r0, w0, groups) = solved(bodies, contacts, given);
            assert_eq!(r0.len(), 1, "{name}");
            assert_eq!(r0[0].large_group, large, "{name}");
            if large {
                assert_eq!(r0[0].resolution, Resolution::Plastic, "{name}");
            } else {
                assert_eq!(r0[0].resolution, Resolution::Lzb, "{name}");
            }
            let least = (0..=given)
                .find(|&w| groups.same_under(Some(given), Some(w)))
                .expect("the budget itself");
            assert!(least < given, "{name}: {least}");
            assert!(!groups.same_under(Some(given), Some(least - 1)), "{name}");
            let (v1, r1, w1, _) = solved(bodies, contacts, least);
            assert_eq!((&v0, &r0, w0), (&v1, &r1, w1), "{name} at {least}");
        }
    }
}
