//! The physics hook: per-pair friction for Rapier's own solver on the pairs
//! topple manages, with Rapier's restitution off and, in topple mode, the
//! contact points that approach faster than the impact threshold taken from
//! Rapier's solver, unless they belong to a lasting contact (a touching point
//! Rapier already had at its last contact update). Rapier would stop those inelastically (a speculative
//! point at the instant the gap closes, a touching point at once); topple
//! resolves them instead, at the instant the pair closes
//! ([`super::ToppleRapier`]). The hook notes each pair it took points from:
//! those pairs are the impact candidates of the step. A managed pair topple
//! cannot resolve ([`super::support`]) and every managed pair once the step's
//! work budget is spent get Rapier's own response, with the pair's friction
//! and restitution, as in native Rapier.

use std::collections::HashSet;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use super::backend::geometry::NEW_CONTACT_BIT;
use super::backend::math::Real;
use super::backend::prelude::{
    ColliderHandle, ContactModificationContext, PhysicsHooks, RigidBody, RigidBodyHandle,
    SolverFlags, Vector,
};

use super::support::{self, Notice};
use crate::coupling::{MaterialId, MaterialTable, PairMaterial};
use crate::rapier::ImpactResponse;

/// Materials of the managed colliders, read by the hook during Rapier's step.
/// [`super::ToppleRapier::step`] hands it to Rapier; a caller that runs
/// Rapier's pipeline itself hands over [`super::ToppleRapier::hooks`].
///
/// ```
/// use topple::rapier2d_f64::prelude::*;
/// use topple::coupling::{PairMaterial, ToppleSettings};
/// use topple::impact::ContactMaterial;
/// use topple::rapier::f64::ToppleRapier;
/// let mut colliders = ColliderSet::new();
/// let c = colliders.insert(ColliderBuilder::ball(0.1));
/// let mut topple = ToppleRapier::new(ToppleSettings::default());
/// let m = topple.add_material(PairMaterial { impact: ContactMaterial::hertz(1e9), smooth_friction: 0.4 });
/// topple.manage(&mut colliders, c, m);
/// assert_eq!(topple.hooks().material_of(c), Some(m));
/// assert_eq!(topple.hooks().pair(c, c).unwrap().smooth_friction, 0.4);
/// ```
#[derive(Debug)]
pub struct ToppleHooks {
    pub(crate) table: MaterialTable,
    collider_material: Vec<u16>,
    pub(crate) mode: ImpactResponse,
    /// Points approaching faster than this (world units per second) are
    /// topple's: the step's impact threshold
    /// ([`super::scale::effective`]).
    pub(crate) min_approach_speed: f64,
    /// The threshold of a pair with e > 0 that Rapier has not held lately
    /// (world units per second): that of one Rapier step of the
    /// frame's sub-steps ([`super::scale::rebound_threshold`]), at most
    /// `min_approach_speed` (docs/bevy.md, "Rebounds and chatter").
    pub(crate) rebound_speed: f64,
    /// The frame being stepped (never 0): stamped into the manifold of each
    /// pair Rapier holds ([`ToppleHooks::held_lately`]).
    frame: u32,
    /// The step's work budget is spent: every pair gets Rapier's own
    /// response until the step ends.
    pub(crate) stand_aside: bool,
    /// Pairs the hook took points from during the current step.
    taken: Mutex<Vec<u64>>,
    /// Managed colliders met in pairs topple leaves to Rapier, this step.
    left: Mutex<Vec<Notice>>,
    /// Those reported already (not pushed again).
    pub(crate) reported: HashSet<Notice>,
    /// Managed pairs that approached faster than the threshold and got
    /// Rapier's response (left to Rapier, or the budget was spent), so far.
    native: AtomicU64,
}

const UNMANAGED: u16 = u16::MAX;

/// Frames before the present one in which a push of Rapier's contact
/// solver still counts the pair as held (docs/bevy.md, "Rebounds and
/// chatter": one frame, measured against 2 and 4 on the Table 1 rows).
pub(crate) const HELD_FRAMES: u32 = 1;

/// A collider pair as one number (arena indices, smaller first).
#[inline]
pub(crate) fn pair_key(a: ColliderHandle, b: ColliderHandle) -> u64 {
    let (a, b) = (a.into_raw_parts().0 as u64, b.into_raw_parts().0 as u64);
    (a.min(b) << 32) | a.max(b)
}

impl ToppleHooks {
    pub(crate) fn new(mode: ImpactResponse) -> Self {
        ToppleHooks {
            table: MaterialTable::default(),
            collider_material: Vec::new(),
            mode,
            min_approach_speed: 0.0,
            rebound_speed: 0.0,
            frame: 1,
            stand_aside: false,
            taken: Mutex::new(Vec::new()),
            left: Mutex::new(Vec::new()),
            reported: HashSet::new(),
            native: AtomicU64::new(0),
        }
    }

    /// Starts a frame (a step of the caller): the impact threshold of pairs
    /// Rapier holds and the lower one of pairs it has not held lately
    /// (world units per second).
    pub(crate) fn begin_frame(&mut self, threshold: f64, rebound: f64) {
        self.min_approach_speed = threshold;
        self.rebound_speed = rebound.min(threshold);
        self.frame = self.frame.wrapping_add(1).max(1);
    }

    /// Whether Rapier's contact solver pushed on a manifold (any of its
    /// points) in this frame or the [`HELD_FRAMES`] before it, from the stamp
    /// the hook leaves in its `user_data` ([`ToppleHooks::modify`]).
    #[inline]
    pub(crate) fn held_lately(&self, stamp: u32) -> bool {
        stamp != 0 && self.frame.wrapping_sub(stamp) <= HELD_FRAMES
    }

    /// The impact threshold (world units per second) of a manifold with
    /// this stamp between materials of this restitution: the frame's while
    /// Rapier holds the pair or lately has, and for a plastic pair (e = 0,
    /// where Rapier's own response, restitution 0 with Coulomb friction, is
    /// the law's answer to a slow approach); the rebound threshold for a
    /// pair with e > 0 that Rapier has not held lately (docs/bevy.md,
    /// "Rebounds and chatter").
    #[inline]
    pub(crate) fn threshold_of(&self, stamp: u32, restitution: f64) -> f64 {
        if restitution <= 0.0 || self.held_lately(stamp) {
            self.min_approach_speed
        } else {
            self.rebound_speed
        }
    }

    /// Managed pairs that approached faster than the impact threshold and
    /// got Rapier's own response instead of topple's, since creation.
    pub(crate) fn native_impacts(&self) -> u64 {
        self.native.load(Ordering::Relaxed)
    }

    /// Moves the notices of the step into `out` (appended, possibly repeated).
    pub(crate) fn take_left(&self, out: &mut Vec<Notice>) {
        let mut left = self.left.lock().unwrap_or_else(|e| e.into_inner());
        out.append(&mut left);
    }

    pub(crate) fn set(&mut self, collider: ColliderHandle, material: Option<MaterialId>) {
        let i = collider.into_raw_parts().0 as usize;
        if self.collider_material.len() <= i {
            self.collider_material.resize(i + 1, UNMANAGED);
        }
        self.collider_material[i] = material.map_or(UNMANAGED, |m| m.0);
    }

    /// Moves the pairs noted during the step into `out` (appended).
    pub(crate) fn take_noted(&self, out: &mut Vec<u64>) {
        let mut taken = self.taken.lock().unwrap_or_else(|e| e.into_inner());
        out.append(&mut taken);
    }

    /// Who resolves impacts.
    pub fn mode(&self) -> ImpactResponse {
        self.mode
    }

    /// The material of a collider, if topple manages it.
    #[inline]
    pub fn material_of(&self, collider: ColliderHandle) -> Option<MaterialId> {
        match self
            .collider_material
            .get(collider.into_raw_parts().0 as usize)
        {
            Some(&m) if m != UNMANAGED => Some(MaterialId(m)),
            _ => None,
        }
    }

    /// The pair material of two colliders, if topple manages both.
    #[inline]
    pub fn pair(&self, a: ColliderHandle, b: ColliderHandle) -> Option<&PairMaterial> {
        Some(self.table.pair(self.material_of(a)?, self.material_of(b)?))
    }

    /// What the hook does to one managed pair's solver contacts (see the
    /// module docs); public so that an app with hooks of its own can call it
    /// from them. Returns `false` for a pair topple does not manage.
    pub fn modify(&self, context: &mut ContactModificationContext) -> bool {
        let Some(pair) = self.pair(context.collider1, context.collider2) else {
            return false;
        };
        *context.friction = pair.smooth_friction as Real;
        if self.mode == ImpactResponse::Native {
            *context.restitution = pair.impact.restitution as Real;
            return true;
        }
        let n = *context.normal;
        let bodies = context.bodies;
        // each body looked up once per pair, not once per point
        let body = |h: Option<RigidBodyHandle>| h.and_then(|h| bodies.get(h));
        let (b1, b2) = (body(context.rigid_body1), body(context.rigid_body2));
        let velocity = |rb: Option<&RigidBody>, p: Vector| {
            rb.map(|rb| rb.velocity_at_point(p)).unwrap_or_default()
        };
        // Rapier pushed on the pair in its last step: stamp the frame
        if context.manifold.points.iter().any(|p| p.data.impulse > 0.0) {
            *context.user_data = self.frame;
        }
        let support = if self.stand_aside {
            Err(None)
        } else {
            support::pair(
                context.bodies,
                context.colliders,
                context.collider1,
                context.collider2,
            )
        };
        // a composite shape keeps the frame's threshold: parry can miss a
        // sub-shape's points at the gaps where the pass resolves an impact
        // (a flat face across a polyline's vertex), and a slow approach the
        // pass cannot resolve must stay Rapier's
        let threshold = match support {
            Ok(support::Geometry::Convex) => {
                self.threshold_of(*context.user_data, pair.impact.restitution)
            }
            _ => self.min_approach_speed,
        } as Real;
        // Rapier's own notion of a lasting contact: the point carried an
        // impulse in Rapier's last step and touches. Its approach in
        // discrete time (of order g·Δt and v_t·ω·Δt on a sliding or
        // pivoting contact) is Rapier's to hold; so is every point slower
        // than the pair's threshold: the frame's while Rapier holds the pair
        // or lately has (chatter of its soft contact) and for a plastic
        // pair, the sub-step's once it has not (a rebound or a landing).
        let rapiers = |c: &super::backend::prelude::SolverContact| {
            let lasting = c.contact_id[0] & NEW_CONTACT_BIT == 0 && c.dist <= 0.0;
            let vn = (velocity(b2, c.anchor2) - velocity(b1, c.anchor1)).dot(n);
            lasting || vn >= -threshold
        };
        if let Err(notice) = support {
            // Rapier's, as native Rapier
            *context.restitution = pair.impact.restitution as Real;
            if let Some(n) = notice.filter(|n| !self.reported.contains(n)) {
                self.left.lock().unwrap_or_else(|e| e.into_inner()).push(n);
            }
            if !context.solver_contacts.iter().all(rapiers) {
                self.native.fetch_add(1, Ordering::Relaxed);
            }
            return true;
        }
        *context.restitution = 0.0;
        let before = context.solver_contacts.len();
        context.solver_contacts.retain(|c| rapiers(c));
        if context.solver_contacts.len() < before {
            let key = pair_key(context.collider1, context.collider2);
            self.taken
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(key);
        }
        true
    }
}

impl PhysicsHooks for ToppleHooks {
    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        self.modify(context);
    }
}

/// topple's hook in front of an app's own: topple modifies the managed
/// pairs' solver contacts first, then the app's hook sees every pair.
pub struct ChainedHooks<'a> {
    /// topple's hook.
    pub topple: &'a ToppleHooks,
    /// The app's hook.
    pub user: &'a dyn PhysicsHooks,
}

impl PhysicsHooks for ChainedHooks<'_> {
    fn filter_contact_pair(
        &self,
        context: &super::backend::prelude::PairFilterContext,
    ) -> Option<SolverFlags> {
        self.user.filter_contact_pair(context)
    }

    fn filter_intersection_pair(
        &self,
        context: &super::backend::prelude::PairFilterContext,
    ) -> bool {
        self.user.filter_intersection_pair(context)
    }

    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        self.topple.modify(context);
        self.user.modify_solver_contacts(context);
    }
}
