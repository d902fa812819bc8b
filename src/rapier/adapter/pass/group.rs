//! The group of an impact: the bodies connected to the closing pairs
//! through closed contacts at the instant, and their contacts.

use super::super::backend::math::{Pose, Real};
use super::super::backend::prelude::{Collider, ColliderHandle, RigidBodyHandle};
use super::super::hooks::{pair_key, ToppleHooks};
use super::super::support::{self, LOCKED_INERTIA};
use crate::coupling::{
    for_each_contact_point, ManifoldPoint, PatchRule, PointContact, ToppleSettings,
};
use crate::impact::{Body, ContactMaterial};

use super::{body_index, closed_tolerance, dynamic_parent, unit, v2, ImpactPass, World, NO_SLOT};

impl ImpactPass {
    /// Adds a dynamic body to the group being built, at its state of time `t`.
    pub(super) fn add_body(
        &mut self,
        world: &World,
        h: RigidBodyHandle,
        t: f64,
        depth: usize,
    ) -> usize {
        let i = body_index(h);
        if self.slot.len() <= i {
            self.slot.resize(i + 1, NO_SLOT);
        }
        if self.slot[i] != NO_SLOT {
            return self.slot[i] as usize;
        }
        let rb = &world.bodies[h];
        let path = self.build_path(h, rb);
        let (com, angle) = path.at(t, self.motion.dt);
        let (velocity, angular_velocity) = if path.changed {
            (path.velocity, path.angular_velocity)
        } else {
            (v2(rb.linvel()), f64::from(rb.angvel()))
        };
        let inv_i = f64::from(rb.mass_properties().effective_world_inv_inertia);
        let mass = f64::from(rb.mass());
        let inertia = if inv_i > 0.0 {
            1.0 / inv_i
        } else {
            // a body that cannot turn (support::LOCKED_INERTIA)
            let r = self.radius(world, h, rb).max(world.length_unit);
            LOCKED_INERTIA * mass * r * r
        };
        self.slot[i] = self.bodies.len() as u32;
        self.bodies.push(Body {
            mass,
            inertia,
            position: com,
            angle,
            velocity,
            angular_velocity,
            fixed: false,
        });
        self.handles.push(h);
        self.depth.resize(self.handles.len(), 0);
        self.depth[self.handles.len() - 1] = depth;
        self.slot[i] as usize
    }

    /// Breadth first from the seed bodies: every managed pair of a group
    /// body (Rapier's narrow-phase pairs and this step's candidates) is
    /// queried at time `t`; a dynamic body it closes with joins the group
    /// while within the impact window (`max_group_hops`); pairs with bodies
    /// beyond are left out.
    pub(super) fn expand_group(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        s: &ToppleSettings,
        t: f64,
    ) {
        let hops = s.max_group_hops.unwrap_or(usize::MAX);
        let mut next = 0;
        while next < self.handles.len() {
            let (h, depth) = (self.handles[next], self.depth[next]);
            next += 1;
            let rb = &world.bodies[h];
            for &c in rb.colliders() {
                self.neighbours(world, c);
                for f in 0..self.found.len() {
                    let (other, active) = self.found[f];
                    // A pair Rapier holds in contact is touching at any
                    // instant of the step: the straight paths between the
                    // step's two poses open it by up to r·Δθ²/8 for a turning
                    // body, so its gap at `t` counts up to Rapier's
                    // prediction distance.
                    let touch = if active {
                        world.prediction.max(world.allowed)
                    } else {
                        world.allowed
                    };
                    self.note_reach(world, other);
                    let key = pair_key(c, other);
                    if self.queried.contains(&key) {
                        continue;
                    }
                    let other_body = world
                        .colliders
                        .get(other)
                        .and_then(|co| dynamic_parent(world, co));
                    if other_body.is_some_and(|o| self.slot_of(o).is_none()) && depth >= hops {
                        continue;
                    }
                    self.queried.push(key);
                    self.query_pair(world, hooks, s, [c, other], t, touch, true, depth + 1);
                }
            }
        }
        self.found.clear();
    }

    /// Fills `found` with the colliders collider `c` may touch: its pairs
    /// in Rapier's narrow phase (with whether Rapier holds them in
    /// contact), then this step's candidates.
    fn neighbours(&mut self, world: &World, c: ColliderHandle) {
        self.found.clear();
        for pair in world.narrow_phase.contact_pairs_with(c) {
            let other = if pair.collider1 == c {
                pair.collider2
            } else {
                pair.collider1
            };
            self.found.push((other, pair.has_any_active_contact()));
        }
        for k in &self.candidates {
            match k.colliders {
                [a, b] if a == c => self.found.push((b, false)),
                [a, b] if b == c => self.found.push((a, false)),
                _ => {}
            }
        }
    }

    /// The group slot of body `h`, if it is in the group being built.
    pub(super) fn slot_of(&self, h: RigidBodyHandle) -> Option<usize> {
        self.slot
            .get(body_index(h))
            .copied()
            .filter(|&s| s != NO_SLOT)
            .map(|s| s as usize)
    }

    /// Queries one managed convex pair at time `t`; its points with a gap of
    /// at most `touch` (m) become contacts (λ points on a flat patch), and a
    /// dynamic body of a closed pair that is not in the group yet joins it at
    /// `depth` contacts from the seeds. Returns whether it is closed.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn query_pair(
        &mut self,
        world: &World,
        hooks: &ToppleHooks,
        s: &ToppleSettings,
        [a, b]: [ColliderHandle; 2],
        t: f64,
        touch: f64,
        persistent: bool,
        depth: usize,
    ) -> bool {
        let Some(material) = hooks.pair(a, b).map(|m| m.impact) else {
            return false;
        };
        let (Some(ca), Some(cb)) = (world.colliders.get(a), world.colliders.get(b)) else {
            return false;
        };
        let Ok(geometry) = support::pair(world.bodies, world.colliders, a, b) else {
            return false; // Rapier's (support): not part of the impact
        };
        let (Some(pa), Some(pb)) = (
            self.collider_pose(world, a, t),
            self.collider_pose(world, b, t),
        ) else {
            return false;
        };
        let tol = closed_tolerance(s).max(touch);
        self.pairs_queried += 1;
        let count = self.manifolds_of(geometry, &pa, ca.shape(), &pb, cb.shape(), tol as Real);
        let closed = self.manifolds[..count]
            .iter()
            .any(|m| m.points.iter().any(|p| f64::from(p.dist) <= tol));
        if !closed {
            return false;
        }
        // the bodies join the group (a body new to it one hop further out)
        let mut join = |co: &Collider| {
            dynamic_parent(world, co).map(|h| match self.slot_of(h) {
                Some(slot) => slot,
                None => self.add_body(world, h, t, depth),
            })
        };
        let bodies = [join(ca), join(cb)];
        let rule = PatchRule {
            closed_tolerance: tol,
            flat_tolerance: s.patch.flat_tolerance.max(closed_tolerance(s)),
            ..s.patch
        };
        // the contact points are read off the smaller shape: a point on a
        // wide ground carries the f32 rounding of the ground's own extent
        // (6·10⁻⁵ of an ulp at 10³ units), which would shift a landing box's
        // λ points off its centre and turn it
        let first_smaller = ca.shape().compute_local_bounding_sphere().radius
            <= cb.shape().compute_local_bounding_sphere().radius;
        self.push_contacts(
            count,
            (pa, pb),
            bodies,
            material,
            &rule,
            persistent,
            first_smaller,
        );
        true
    }

    /// Turns the points of the first `count` manifolds of a closed pair at
    /// poses `pa`, `pb` into contacts between `bodies`: the midpoint of each
    /// point pair, the normal of the first shape, λ points on a flat patch
    /// ([`for_each_contact_point`]). The midpoint is taken half the gap off
    /// the point on the first shape if `first_smaller`, else on the second
    /// (in exact arithmetic the same point).
    #[allow(clippy::too_many_arguments)]
    fn push_contacts(
        &mut self,
        count: usize,
        (pa, pb): (Pose, Pose),
        bodies: [Option<usize>; 2],
        material: ContactMaterial,
        rule: &PatchRule,
        persistent: bool,
        first_smaller: bool,
    ) {
        for m in &self.manifolds[..count] {
            // points of a sub-shape are in its own frame
            let p1 = m.subshape_pos1().map_or(pa, |sub| pa * *sub);
            let p2 = m.subshape_pos2().map_or(pb, |sub| pb * *sub);
            let n1 = p1.transform_vector(m.local_n1).normalize();
            let normal = unit(v2(n1));
            self.points.clear();
            for p in &m.points {
                // local_n1 points from shape 1 to shape 2, dist > 0 a gap
                let half = 0.5 * p.dist;
                let mid = if first_smaller {
                    p1.transform_point(p.local_p1) + n1 * half
                } else {
                    p2.transform_point(p.local_p2) - n1 * half
                };
                self.points.push(ManifoldPoint {
                    point: v2(mid),
                    dist: f64::from(p.dist),
                });
            }
            let contacts = &mut self.contacts;
            for_each_contact_point(&self.points, rule, |point, dist| {
                contacts.push(PointContact {
                    bodies,
                    point,
                    normal,
                    // touching within `touch`: closed for the grouping stage
                    dist: dist.min(0.0),
                    material,
                    persistent,
                })
            });
        }
    }
}
