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
//! velocities are written back. A physics engine adapter (the rapier2d-f64 one
//! in [`crate::rapier::ToppleRapier`], later a Bevy/f32 one) only has to fill
//! the two slices.

use crate::impact::{
    Body, Contact, ContactMaterial, ImpactError, ImpactOutcome, ImpactSettings, ImpactSolver,
};

use super::patch::PatchRule;

/// A contact point between two bodies (indices into the body slice; `None` is
/// the fixed world) at the current positions.
///
/// ```
/// use topple::impact::{Body, ContactMaterial};
/// use topple::rapier::{normal_velocity, PointContact};
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

/// Settings of the impact pass.
///
/// ```
/// use topple::rapier::ToppleSettings;
/// let s = ToppleSettings::default();
/// assert_eq!(s.patch.lambda, 9);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToppleSettings {
    /// Settings handed to the LZB resolver (impulse step or tolerance).
    pub impact: ImpactSettings,
    /// Which manifold points are closed and how flat patches are subdivided.
    pub patch: PatchRule,
    /// A new closed contact starts an impact when it approaches faster than
    /// this (m/s). Slower approaches are left to the engine's contact solver.
    /// Keep it above about 2|g|Δt, the approach a resting contact picks up in
    /// one step.
    pub min_approach_speed: f64,
    /// The window of an impact: only free bodies within this many closed
    /// contacts of the bodies that started it take part, and contacts with
    /// bodies beyond are left out (like the paper's active window κ). `None`:
    /// the whole connected group.
    pub max_group_hops: Option<usize>,
}

impl Default for ToppleSettings {
    fn default() -> Self {
        ToppleSettings {
            impact: ImpactSettings::default(),
            patch: PatchRule::default(),
            min_approach_speed: 1e-3,
            max_group_hops: None,
        }
    }
}

/// What one resolved impact did.
///
/// ```
/// let r = topple::rapier::ImpactReport::default();
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
    /// Kinetic energy of the group before and after (J).
    pub kinetic_energy_before: f64,
    /// Kinetic energy of the group after the impact (J).
    pub kinetic_energy_after: f64,
    /// Impulse steps taken by the resolver.
    pub steps: usize,
}

const NONE: usize = usize::MAX;

/// Finds impact groups and solves them; keeps every buffer between calls, so
/// a steady scene allocates nothing.
///
/// ```
/// use topple::impact::{Body, ContactMaterial};
/// use topple::rapier::{ImpactGroups, PointContact, ToppleSettings};
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
/// let mut reports = Vec::new();
/// groups.resolve(&mut bodies, &contacts, &ToppleSettings::default(), &mut reports).unwrap();
/// assert_eq!(reports.len(), 1);
/// assert!((bodies[1].velocity[0] - 1.0).abs() < 1e-3);
/// ```
#[derive(Debug, Default)]
pub struct ImpactGroups {
    solver: ImpactSolver,
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
    /// The resolver's output, reused so that a steady scene allocates nothing.
    outcome: ImpactOutcome,
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
pub(crate) fn seed_approach(
    bodies: &[Body],
    c: &PointContact,
    settings: &ToppleSettings,
) -> Option<f64> {
    if c.dist > settings.patch.closed_tolerance || c.persistent {
        return None;
    }
    let free = |i: Option<usize>| i.is_some_and(|i| !bodies[i].fixed);
    let vn = normal_velocity(bodies, c);
    (vn < -settings.min_approach_speed && (free(c.bodies[0]) || free(c.bodies[1]))).then_some(-vn)
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
    /// input form (after an error: the group that failed).
    pub fn last_group(&self) -> (&[Body], &[Contact]) {
        (&self.group_bodies, &self.group_contacts)
    }

    /// Resolves every impact found in `contacts` and writes the post-impact
    /// velocities into `bodies`; appends one report per group to `reports` and
    /// returns the number of groups. Bodies with `fixed` never move and do not
    /// join groups.
    pub fn resolve(
        &mut self,
        bodies: &mut [Body],
        contacts: &[PointContact],
        settings: &ToppleSettings,
        reports: &mut Vec<ImpactReport>,
    ) -> Result<usize, ImpactError> {
        let tol = settings.patch.closed_tolerance;
        let free = |i: Option<usize>, bodies: &[Body]| i.filter(|&i| !bodies[i].fixed);
        let n = bodies.len();

        // Seeds: closed contacts approaching fast enough. Nothing else is done
        // when there are none (the common case).
        self.seeds.clear();
        for (k, c) in contacts.iter().enumerate() {
            if let Some(approach) = seed_approach(bodies, c, settings) {
                self.seeds.push((k, approach));
            }
        }
        if self.seeds.is_empty() {
            return Ok(0);
        }

        // The window: free bodies within `max_group_hops` closed contacts of a
        // body of a seed contact; those outside act as the fixed world.
        self.inside.clear();
        self.inside.resize(n, settings.max_group_hops.is_none());
        if let Some(hops) = settings.max_group_hops {
            self.adj_start.clear();
            self.adj_start.resize(n + 1, 0);
            for c in contacts.iter().filter(|c| c.dist <= tol) {
                if let (Some(a), Some(b)) = (free(c.bodies[0], bodies), free(c.bodies[1], bodies)) {
                    self.adj_start[a + 1] += 1;
                    self.adj_start[b + 1] += 1;
                }
            }
            for i in 0..n {
                self.adj_start[i + 1] += self.adj_start[i];
            }
            self.adj.clear();
            self.adj.resize(self.adj_start[n], 0);
            self.cursor_b.clone_from(&self.adj_start);
            for c in contacts.iter().filter(|c| c.dist <= tol) {
                if let (Some(a), Some(b)) = (free(c.bodies[0], bodies), free(c.bodies[1], bodies)) {
                    self.adj[self.cursor_b[a]] = b;
                    self.cursor_b[a] += 1;
                    self.adj[self.cursor_b[b]] = a;
                    self.cursor_b[b] += 1;
                }
            }
            self.depth.clear();
            self.depth.resize(n, NONE);
            self.queue.clear();
            for &(k, _) in &self.seeds {
                for i in contacts[k].bodies.iter().filter_map(|&i| free(i, bodies)) {
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
        let inside = &self.inside;
        let free = |i: Option<usize>, bodies: &[Body]| i.filter(|&i| !bodies[i].fixed && inside[i]);
        // A contact reaching a free body outside the window is left out (not
        // made a wall: a wall there could wedge the window shut).
        let crosses = |c: &PointContact, bodies: &[Body]| {
            c.bodies
                .iter()
                .any(|&i| i.is_some_and(|i| !bodies[i].fixed && !inside[i]))
        };

        // Connected components of free bodies through closed contacts.
        self.parent.clear();
        self.parent.extend(0..n);
        for c in contacts.iter().filter(|c| c.dist <= tol) {
            if let (Some(a), Some(b)) = (free(c.bodies[0], bodies), free(c.bodies[1], bodies)) {
                let (ra, rb) = (find(&mut self.parent, a), find(&mut self.parent, b));
                if ra != rb {
                    self.parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
        let root_of = |parent: &mut Vec<usize>, c: &PointContact, bodies: &[Body]| {
            free(c.bodies[0], bodies)
                .or(free(c.bodies[1], bodies))
                .map(|i| find(parent, i))
        };

        // Number the seeded components in order of first seed (deterministic).
        self.group_of_root.clear();
        self.group_of_root.resize(n, NONE);
        self.group_speed.clear();
        for s in 0..self.seeds.len() {
            let (k, speed) = self.seeds[s];
            let r = root_of(&mut self.parent, &contacts[k], bodies).expect("seed has a free body");
            if self.group_of_root[r] == NONE {
                self.group_of_root[r] = self.group_speed.len();
                self.group_speed.push(0.0);
            }
            let g = self.group_of_root[r];
            self.group_speed[g] = self.group_speed[g].max(speed);
        }
        let groups = self.group_speed.len();

        // Bucket bodies and closed contacts by group (counting sort).
        self.body_start.clear();
        self.body_start.resize(groups + 1, 0);
        self.contact_start.clear();
        self.contact_start.resize(groups + 1, 0);
        for (i, b) in bodies.iter().enumerate() {
            if !b.fixed && inside[i] {
                let g = self.group_of_root[find(&mut self.parent, i)];
                if g != NONE {
                    self.body_start[g + 1] += 1;
                }
            }
        }
        for c in contacts
            .iter()
            .filter(|c| c.dist <= tol && !crosses(c, bodies))
        {
            if let Some(r) = root_of(&mut self.parent, c, bodies) {
                let g = self.group_of_root[r];
                if g != NONE {
                    self.contact_start[g + 1] += 1;
                }
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
        {
            // Fill, using copies of the start offsets as cursors.
            self.cursor_b.clone_from(&self.body_start);
            self.cursor_c.clone_from(&self.contact_start);
            let (cursor_b, cursor_c) = (&mut self.cursor_b, &mut self.cursor_c);
            for (i, b) in bodies.iter().enumerate() {
                if !b.fixed && inside[i] {
                    let g = self.group_of_root[find(&mut self.parent, i)];
                    if g != NONE {
                        self.body_order[cursor_b[g]] = i;
                        cursor_b[g] += 1;
                    }
                }
            }
            for (k, c) in contacts
                .iter()
                .enumerate()
                .filter(|(_, c)| c.dist <= tol && !crosses(c, bodies))
            {
                if let Some(r) = root_of(&mut self.parent, c, bodies) {
                    let g = self.group_of_root[r];
                    if g != NONE {
                        self.contact_order[cursor_c[g]] = k;
                        cursor_c[g] += 1;
                    }
                }
            }
        }

        // Solve each group.
        self.local.clear();
        self.local.resize(n, NONE);
        for g in 0..groups {
            self.group_bodies.clear();
            for &i in &self.body_order[self.body_start[g]..self.body_start[g + 1]] {
                self.local[i] = self.group_bodies.len();
                self.group_bodies.push(bodies[i]);
            }
            self.group_contacts.clear();
            for &k in &self.contact_order[self.contact_start[g]..self.contact_start[g + 1]] {
                let c = &contacts[k];
                let map = |i: Option<usize>| free(i, bodies).map(|i| self.local[i]);
                self.group_contacts.push(Contact::new(
                    [map(c.bodies[0]), map(c.bodies[1])],
                    c.point,
                    c.normal,
                    c.material,
                ));
            }
            self.solver.solve_into(
                &self.group_bodies,
                &self.group_contacts,
                &settings.impact,
                &mut self.outcome,
            )?;
            let out = &self.outcome;
            for (&i, v) in self.body_order[self.body_start[g]..self.body_start[g + 1]]
                .iter()
                .zip(&out.bodies)
            {
                bodies[i].velocity = v.velocity;
                bodies[i].angular_velocity = v.angular_velocity;
            }
            reports.push(ImpactReport {
                bodies: self.group_bodies.len(),
                contacts: self.group_contacts.len(),
                approach_speed: self.group_speed[g],
                kinetic_energy_before: out.kinetic_energy_before,
                kinetic_energy_after: out.kinetic_energy_after,
                steps: out.steps,
            });
        }
        Ok(groups)
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
        let mut reports = Vec::new();
        let n = ImpactGroups::default()
            .resolve(
                &mut bodies,
                &contacts,
                &ToppleSettings::default(),
                &mut reports,
            )
            .unwrap();
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
        let mut reports = Vec::new();
        let mut groups = ImpactGroups::default();
        let settings = ToppleSettings::default();
        let persistent = [touch(0, 1, 0.1, true)];
        assert_eq!(
            groups
                .resolve(&mut bodies, &persistent, &settings, &mut reports)
                .unwrap(),
            0
        );
        bodies[0].velocity[0] = 0.5 * settings.min_approach_speed;
        let slow = [touch(0, 1, 0.1, false)];
        assert_eq!(
            groups
                .resolve(&mut bodies, &slow, &settings, &mut reports)
                .unwrap(),
            0
        );
        assert!(reports.is_empty());
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
        let mut reports = Vec::new();
        let mut groups = ImpactGroups::default();
        groups
            .resolve(
                &mut bodies,
                &contacts,
                &ToppleSettings::default(),
                &mut reports,
            )
            .unwrap();
        assert_eq!((reports[0].bodies, reports[0].contacts), (2, 2));
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
        reports.clear();
        groups
            .resolve(&mut chain, &links, &settings, &mut reports)
            .unwrap();
        assert_eq!((reports[0].bodies, reports[0].contacts), (3, 2));
        assert_eq!(chain[3].velocity, [0.0, 0.0]);
    }
}
