//! The physics hook: per-pair materials for Rapier's own solver, with its
//! restitution switched off and its speculative contacts dropped on the pairs
//! topple manages, so that no impact is counted twice.

use rapier2d_f64::prelude::{
    ColliderHandle, ContactModificationContext, PhysicsHooks, RigidBodyHandle, Vector,
};

use super::material::{MaterialId, MaterialTable, PairMaterial};

/// Who resolves impacts on managed pairs.
///
/// ```
/// use topple::rapier::{HookMode, ToppleRapier, ToppleSettings};
/// assert_eq!(ToppleRapier::new(ToppleSettings::default()).hooks().mode(), HookMode::Topple);
/// assert_eq!(ToppleRapier::native().hooks().mode(), HookMode::Native);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HookMode {
    /// topple resolves impacts; Rapier keeps resting contact with restitution 0
    /// and without the contact points that are still open (speculative) or
    /// approach faster than topple's impact threshold: Rapier would stop those
    /// inelastically at the moment of touching, before topple sees them.
    Topple,
    /// Rapier resolves impacts itself with the pair's restitution; the hook
    /// only sets friction and restitution per pair (native Rapier response).
    Native,
}

/// Materials of the managed colliders, read by the hook during Rapier's step.
/// Hand it to `PhysicsPipeline::step` (see [`super::ToppleRapier::hooks`]).
///
/// ```
/// use rapier2d_f64::prelude::*;
/// use topple::impact::ContactMaterial;
/// use topple::rapier::{PairMaterial, ToppleRapier, ToppleSettings};
/// let mut colliders = ColliderSet::new();
/// let c = colliders.insert(ColliderBuilder::ball(0.1));
/// let mut topple = ToppleRapier::new(ToppleSettings::default());
/// let m = topple.add_material(PairMaterial { impact: ContactMaterial::hertz(1e9), smooth_friction: 0.4 });
/// topple.manage(&mut colliders, c, m);
/// assert_eq!(topple.hooks().material_of(c), Some(m));
/// assert_eq!(topple.hooks().pair(c, c).unwrap().smooth_friction, 0.4);
/// ```
#[derive(Clone, Debug)]
pub struct ToppleHooks {
    pub(crate) table: MaterialTable,
    collider_material: Vec<u16>,
    pub(crate) mode: HookMode,
    pub(crate) min_approach_speed: f64,
    /// Pairs closed at the last resolve pass, sorted (see [`super::pair_key`]).
    closed: Vec<u64>,
}

const UNMANAGED: u16 = u16::MAX;

impl ToppleHooks {
    pub(crate) fn new(mode: HookMode) -> Self {
        ToppleHooks {
            table: MaterialTable::default(),
            collider_material: Vec::new(),
            mode,
            min_approach_speed: 0.0,
            closed: Vec::new(),
        }
    }

    pub(crate) fn set(&mut self, collider: ColliderHandle, material: MaterialId) {
        let i = collider.into_raw_parts().0 as usize;
        if self.collider_material.len() <= i {
            self.collider_material.resize(i + 1, UNMANAGED);
        }
        self.collider_material[i] = material.0;
    }

    /// Was this pair closed at the last resolve pass?
    #[inline]
    pub(crate) fn was_closed(&self, key: u64) -> bool {
        self.closed.binary_search(&key).is_ok()
    }

    /// Makes `now` (the pairs closed at this pass) the persistent set, adding
    /// the previously closed pairs for which `skipped` holds (not queried).
    pub(crate) fn keep_sleeping_closed(
        &mut self,
        now: &mut Vec<u64>,
        skipped: impl Fn(u64) -> bool,
    ) {
        now.extend(self.closed.iter().copied().filter(|&k| skipped(k)));
        now.sort_unstable();
        now.dedup();
        std::mem::swap(&mut self.closed, now);
    }

    /// Who resolves impacts.
    pub fn mode(&self) -> HookMode {
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
}

impl PhysicsHooks for ToppleHooks {
    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        let Some(pair) = self.pair(context.collider1, context.collider2) else {
            return;
        };
        *context.friction = pair.smooth_friction;
        match self.mode {
            HookMode::Topple => {
                *context.restitution = 0.0;
                let n = *context.normal;
                let bodies = context.bodies;
                let velocity = |h: Option<RigidBodyHandle>, p: Vector| {
                    h.and_then(|h| bodies.get(h))
                        .map(|rb| rb.velocity_at_point(p))
                        .unwrap_or_default()
                };
                // A persistent pair is Rapier's (resting or sliding contact).
                if self.was_closed(super::world::pair_key(context.collider1, context.collider2)) {
                    return;
                }
                let (b1, b2) = (context.rigid_body1, context.rigid_body2);
                let threshold = self.min_approach_speed;
                context.solver_contacts.retain(|c| {
                    let vn = (velocity(b2, c.anchor2) - velocity(b1, c.anchor1)).dot(n);
                    c.dist <= 0.0 && vn >= -threshold
                });
            }
            HookMode::Native => *context.restitution = pair.impact.restitution,
        }
    }
}
