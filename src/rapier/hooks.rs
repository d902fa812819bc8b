//! The physics hook: per-pair materials for Rapier's own solver, with its
//! restitution switched off and its speculative contacts dropped on the pairs
//! topple manages, so that no impact is counted twice.

use rapier2d_f64::prelude::{ColliderHandle, ContactModificationContext, PhysicsHooks};

use super::material::{MaterialId, MaterialTable, PairMaterial};

/// Who resolves impacts on managed pairs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HookMode {
    /// topple resolves impacts; Rapier keeps resting contact with restitution 0
    /// and without speculative (still open) contact points, which would stop an
    /// approaching pair inelastically at the moment it touches.
    Topple,
    /// Rapier resolves impacts itself with the pair's restitution; the hook
    /// only sets friction and restitution per pair (native Rapier response).
    Native,
}

/// Materials of the managed colliders, read by the hook during Rapier's step.
#[derive(Clone, Debug)]
pub struct ToppleHooks {
    pub(crate) table: MaterialTable,
    collider_material: Vec<u16>,
    pub(crate) mode: HookMode,
}

const UNMANAGED: u16 = u16::MAX;

impl ToppleHooks {
    pub(crate) fn new(mode: HookMode) -> Self {
        ToppleHooks {
            table: MaterialTable::default(),
            collider_material: Vec::new(),
            mode,
        }
    }

    pub(crate) fn set(&mut self, collider: ColliderHandle, material: MaterialId) {
        let i = collider.into_raw_parts().0 as usize;
        if self.collider_material.len() <= i {
            self.collider_material.resize(i + 1, UNMANAGED);
        }
        self.collider_material[i] = material.0;
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
                context.solver_contacts.retain(|c| c.dist <= 0.0);
            }
            HookMode::Native => *context.restitution = pair.impact.restitution,
        }
    }
}
