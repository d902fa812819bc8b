//! A column of boxes on the ground for the stepping tests (cadence, warm
//! start): built the same way, watched the same way, the deepest overlap
//! measured with parry's own contact query (independent of topple's pass
//! and of Rapier's solver).

use topple::coupling::{MaterialId, PairMaterial};
use topple::impact::ContactMaterial;
use topple::rapier::f64::ToppleRapier;
use topple::rapier2d_f64::parry::query;
use topple::rapier2d_f64::prelude::*;

/// Half side of a box of the column (m).
pub const HALF: f64 = 0.05;
/// Boxes in the column.
pub const LEVELS: usize = 4;

/// The column's material: Hertz stiffness 10⁸ N/m^1.5, μ 0.5, μ_s 0.6,
/// e 0.3, impact friction factor 1.
pub fn wood(topple: &mut ToppleRapier) -> MaterialId {
    topple.add_material(PairMaterial::from_table(
        ContactMaterial::hertz(1e8),
        0.5,
        0.6,
        0.3,
        1.0,
    ))
}

/// What a run of a column shows.
#[derive(Debug, Default)]
pub struct Run {
    /// Deepest overlap (m) of two neighbours in the column or of the
    /// bottom box and the ground, over the run.
    pub deepest: f64,
    /// Impact groups with a column body in them.
    pub stack_impacts: usize,
    /// Impacts topple resolved anywhere.
    pub impacts: usize,
    /// Rapier steps taken (topple's sub-steps and splits included).
    pub rapier_steps: u64,
}

impl Run {
    /// Records one step of `topple` on `world`: its impacts, those in
    /// `stack`, and the deepest overlap of `column`.
    pub fn watch(
        &mut self,
        topple: &ToppleRapier,
        world: &PhysicsWorld,
        stack: &[RigidBodyHandle],
        column: &[ColliderHandle],
    ) {
        self.impacts += topple.last_impacts().len();
        self.stack_impacts += stack_impacts(topple, stack);
        self.deepest = self
            .deepest
            .max(deepest_in_column(&world.colliders, column));
        self.rapier_steps = topple.stats().rapier_steps;
    }
}

/// A column of `levels` square boxes of half side `half` (m) on the ground
/// collider `ground`, of masses ratio^(k−2) kg from the bottom (k = 0) up,
/// each resting on the one below, off centre by 2 % of its side either
/// way, managed with `material`. Returns the bodies and the colliders, the
/// ground first.
pub fn column(
    world: &mut PhysicsWorld,
    topple: &mut ToppleRapier,
    ground: ColliderHandle,
    material: MaterialId,
    (half, levels, ratio): (f64, usize, f64),
) -> (Vec<RigidBodyHandle>, Vec<ColliderHandle>) {
    let mut bodies = Vec::new();
    let mut colliders = vec![ground];
    for k in 0..levels {
        let density = ratio.powi(k as i32 - 2) / (2.0 * half).powi(2);
        let x = 0.002 * if k % 2 == 0 { 1.0 } else { -1.0 };
        let (b, c) = world.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(x, half * (2 * k + 1) as f64)),
            ColliderBuilder::cuboid(half, half).density(density),
        );
        topple.manage(&mut world.colliders, c, material);
        bodies.push(b);
        colliders.push(c);
    }
    (bodies, colliders)
}

/// The impact events of the last step that moved a body of `stack`.
pub fn stack_impacts(topple: &ToppleRapier, stack: &[RigidBodyHandle]) -> usize {
    topple
        .last_events()
        .iter()
        .filter(|e| topple.event_bodies(e).iter().any(|b| stack.contains(b)))
        .count()
}

/// The deepest overlap (m) between consecutive colliders of `column` (the
/// ground first, then each box on the one below), 0 where none overlap.
pub fn deepest_in_column(set: &ColliderSet, column: &[ColliderHandle]) -> f64 {
    let mut deepest: f64 = 0.0;
    for pair in column.windows(2) {
        let (a, b) = (&set[pair[0]], &set[pair[1]]);
        let c = query::contact(a.position(), a.shape(), b.position(), b.shape(), 0.0)
            .expect("boxes and the ground have a contact query");
        if let Some(c) = c {
            deepest = deepest.max(-c.dist);
        }
    }
    deepest
}
