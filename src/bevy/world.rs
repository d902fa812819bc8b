//! The per-context state: which Rapier context topple steps, its materials,
//! and the settings and statistics an app reads.

use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy_rapier2d::rapier::prelude::ColliderHandle;

use crate::coupling::{MaterialId, PairMaterial, ToppleSettings};
use crate::rapier::f32::ToppleRapier;
use crate::rapier::ToppleStats;

/// Opt-in per collider: the entity's collider takes part in LZB impacts with
/// this material (energetic restitution e, Coulomb friction μ and μₛ,
/// stiffness k and exponent α of the contact law, and the smooth-phase
/// friction Rapier uses between impacts). Entities without it stay plain
/// Rapier. Put it on the entity that holds the [`Collider`](bevy_rapier2d::prelude::Collider).
///
/// Two colliders of the same material use it as it is; two different
/// materials combine by [`PairMaterial::combine`] unless a pair rule is set
/// with [`ToppleConfig::set_pair`]. The number λ of contact points under a
/// flat face is one setting for the whole context
/// ([`ToppleSettings::patch`]).
///
/// ```
/// use topple::bevy::ToppleMaterial;
/// use topple::coupling::PairMaterial;
/// use topple::impact::ContactMaterial;
/// let steel = ToppleMaterial(PairMaterial {
///     impact: ContactMaterial::hertz(1e10).with_restitution(1.0),
///     smooth_friction: 0.0,
/// });
/// assert_eq!(steel.0.impact.restitution, 1.0);
/// ```
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct ToppleMaterial(pub PairMaterial);

/// Settings shared by every context topple steps, and the pair rules between
/// materials. Changing the resource applies it before the next step.
///
/// ```
/// use topple::bevy::ToppleConfig;
/// let config = ToppleConfig::default();
/// assert_eq!(config.settings.max_substep, Some(1.0 / 240.0));
/// ```
#[derive(Resource, Clone, Debug, Default)]
pub struct ToppleConfig {
    /// Settings of the impact pass (impact threshold, sub-steps, window,
    /// fallback policy, λ points).
    pub settings: ToppleSettings,
    /// Pair rules: the material used between colliders of the first two
    /// materials (in either order).
    pub pair_rules: Vec<(PairMaterial, PairMaterial, PairMaterial)>,
}

impl ToppleConfig {
    /// Sets the material used between colliders of materials `a` and `b`
    /// (replacing an earlier rule for the same two).
    pub fn set_pair(&mut self, a: PairMaterial, b: PairMaterial, rule: PairMaterial) {
        self.pair_rules
            .retain(|(x, y, _)| !((*x, *y) == (a, b) || (*x, *y) == (b, a)));
        self.pair_rules.push((a, b, rule));
    }
}

/// What topple did in the last frame, summed over the contexts it steps, and
/// the running totals.
///
/// ```
/// use topple::bevy::ToppleFrameStats;
/// assert_eq!(ToppleFrameStats::default().impacts, 0);
/// ```
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct ToppleFrameStats {
    /// Rapier steps taken this frame (sub-steps and splits included).
    pub rapier_steps: u64,
    /// Impact groups resolved this frame.
    pub impacts: u64,
    /// LZB impulse steps this frame.
    pub lzb_steps: u64,
    /// Impacts that went through the fallback policy this frame (held,
    /// plastic or rejected), those cut short by the work budget included.
    pub fallbacks: u64,
    /// Of the fallbacks, impacts of large groups
    /// ([`crate::coupling::FallbackPolicy::large_group`]: more free bodies
    /// than a domino front's window holds, some touching three or more
    /// others) whose LZB attempts ran out of their smaller allowance or
    /// failed: a pile solved plastic.
    pub large_group_fallbacks: u64,
    /// Work of the LZB resolver this frame: impulse steps times contact
    /// points, the unit of the budget
    /// ([`crate::coupling::FallbackPolicy::max_work`], per physics step).
    pub work: u64,
    /// Physics steps this frame whose work budget ran out (the rest of such
    /// a step is native Rapier).
    pub budget_spent: u64,
    /// Managed pairs that approached faster than the impact threshold and
    /// got Rapier's own response this frame (colliders topple leaves to
    /// Rapier, or after the budget ran out).
    pub native_impacts: u64,
    /// Impacts solved side by side with others of the same physics step
    /// this frame (docs/bevy.md, "Independent impacts side by side").
    pub batched_impacts: u64,
    /// Wall time of topple's own work this frame, Rapier excluded (s).
    pub topple_seconds: f64,
    /// Wall time of the whole physics step this frame, Rapier included (s).
    pub step_seconds: f64,
    /// Totals since start over every topple context.
    pub totals: ToppleStats,
}

/// On a Rapier context entity: topple steps this context (the adapter, its
/// interned materials and the colliders waiting for Rapier). [`crate::bevy::TopplePlugin`] puts
/// one on the default context; add one to another context to let topple
/// step it too. Contexts without it are stepped exactly as bevy_rapier does.
#[derive(Component, Debug)]
pub struct ToppleWorld {
    pub(crate) adapter: ToppleRapier,
    materials: Vec<(PairMaterial, MaterialId)>,
    rules_applied: usize,
    /// Entities whose collider Rapier had not created yet.
    pub(crate) pending: Vec<Entity>,
    /// The colliders topple manages, by entity: given back when the entity
    /// loses its material or is despawned (Rapier reuses the slot).
    pub(crate) managed: HashMap<Entity, ColliderHandle>,
}

impl Default for ToppleWorld {
    fn default() -> Self {
        ToppleWorld::new(ToppleSettings::default())
    }
}

impl ToppleWorld {
    /// A context stepped by topple with these settings.
    pub fn new(settings: ToppleSettings) -> Self {
        ToppleWorld {
            adapter: ToppleRapier::new(settings),
            materials: Vec::new(),
            rules_applied: 0,
            pending: Vec::new(),
            managed: HashMap::new(),
        }
    }

    /// The adapter (statistics, last impacts, settings).
    pub fn adapter(&self) -> &ToppleRapier {
        &self.adapter
    }

    /// Whether a physics step's independent impacts are solved in batches,
    /// side by side, or one instant at a time: the same bits either way
    /// ([`ToppleRapier::set_impact_batches`]; on by default).
    pub fn set_impact_batches(&mut self, on: bool) {
        self.adapter.set_impact_batches(on);
    }

    /// The id of a material, added on first use.
    pub(crate) fn material_id(&mut self, m: PairMaterial) -> MaterialId {
        if let Some((_, id)) = self.materials.iter().find(|(x, _)| *x == m) {
            return *id;
        }
        let id = self.adapter.add_material(m);
        self.materials.push((m, id));
        id
    }

    /// Applies the settings and any pair rules not applied yet.
    pub(crate) fn apply_config(&mut self, config: &ToppleConfig) {
        if *self.adapter.settings() != config.settings {
            self.adapter.set_settings(config.settings);
        }
        if self.rules_applied > config.pair_rules.len() {
            self.rules_applied = 0; // rules were removed: apply them all again
        }
        for &(a, b, rule) in &config.pair_rules[self.rules_applied..] {
            let (ia, ib) = (self.material_id(a), self.material_id(b));
            self.adapter.set_pair_material(ia, ib, rule);
        }
        self.rules_applied = config.pair_rules.len();
    }
}

/// On every Rapier context: the simulated time and the frame count, for
/// measures that need the instant of an event.
///
/// ```
/// use topple::bevy::PhysicsClock;
/// assert_eq!(PhysicsClock::default().time, 0.0);
/// ```
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct PhysicsClock {
    /// Simulated time at the end of the last frame (s).
    pub time: f64,
    /// Simulated time stepped in the last frame (s).
    pub last_frame: f64,
    /// Frames in which the context was stepped.
    pub frames: u64,
}
