//! The message a game reads for every impact topple resolved: which entities
//! took part, where, how hard, and how much energy went into the impact.

use bevy::prelude::*;
use bevy_rapier2d::prelude::*;
use bevy_rapier2d::rapier::prelude::{ColliderSet, RigidBodyHandle, RigidBodySet};

use crate::coupling::ImpactReport;
use crate::rapier::f32::ToppleRapier;
use crate::rapier::LeftToRapier;

/// One contact of a [`ToppleImpact`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpactPoint {
    /// The bodies' entities (`None`: a fixed body, the world).
    pub entities: [Option<Entity>; 2],
    /// Contact point, world frame (m).
    pub point: Vec2,
    /// Unit normal from the first body to the second.
    pub normal: Vec2,
    /// Normal impulse on the second body (N·s), ≥ 0.
    pub normal_impulse: f32,
    /// Tangential impulse on the second body along (−n_y, n_x) (N·s).
    pub tangent_impulse: f32,
}

/// A group of bodies whose impact topple resolved: sent once per group, in
/// the frame it happened (read it with `MessageReader<ToppleImpact>`).
///
/// ```
/// use topple::bevy::ToppleImpact;
/// fn clack(mut impacts: bevy::prelude::MessageReader<ToppleImpact>) {
///     for hit in impacts.read() {
///         let loudness = hit.contacts.iter().map(|c| c.normal_impulse).sum::<f32>();
///         let _ = (loudness, hit.energy_dissipated());
///     }
/// }
/// # let _ = clack;
/// ```
#[derive(Message, Clone, Debug, PartialEq)]
pub struct ToppleImpact {
    /// The Rapier context it happened in.
    pub context: Entity,
    /// The frame of that context ([`crate::bevy::PhysicsClock::frames`]).
    pub frame: u64,
    /// Instant of the impact from the start of the frame's physics step (s).
    pub time_in_frame: f64,
    /// The free bodies of the group.
    pub bodies: Vec<Entity>,
    /// Its contacts with the impulses they carried.
    pub contacts: Vec<ImpactPoint>,
    /// What the resolver did: energies before and after (J), impulse steps,
    /// fallback stage.
    pub report: ImpactReport,
}

impl ToppleImpact {
    /// Kinetic energy the impact took out of the group (J).
    pub fn energy_dissipated(&self) -> f64 {
        self.report.kinetic_energy_before - self.report.kinetic_energy_after
    }

    /// True when the entities `a` and `b` touched in this impact.
    pub fn involves_pair(&self, a: Entity, b: Entity) -> bool {
        self.contacts
            .iter()
            .any(|c| c.entities == [Some(a), Some(b)] || c.entities == [Some(b), Some(a)])
    }
}

/// The entity of a body: bevy_rapier keeps it in the body's user data.
fn body_entity(bodies: &RigidBodySet, h: RigidBodyHandle) -> Option<Entity> {
    bodies.get(h).map(|b| Entity::from_bits(b.user_data as u64))
}

/// The impacts of the adapter's last step as messages, `offset` (s) being
/// where that step started in the frame.
pub(crate) fn collect(
    adapter: &ToppleRapier,
    bodies: &RigidBodySet,
    context: Entity,
    frame: u64,
    offset: f64,
    out: &mut Vec<ToppleImpact>,
) {
    for ev in adapter.last_events() {
        let entities = adapter
            .event_bodies(ev)
            .iter()
            .filter_map(|&h| body_entity(bodies, h))
            .collect();
        let contacts = adapter
            .event_contacts(ev)
            .iter()
            .map(|c| ImpactPoint {
                entities: c.bodies.map(|b| b.and_then(|h| body_entity(bodies, h))),
                point: Vec2::new(c.point[0] as f32, c.point[1] as f32),
                normal: Vec2::new(c.normal[0] as f32, c.normal[1] as f32),
                normal_impulse: c.normal_impulse as f32,
                tangent_impulse: c.tangent_impulse as f32,
            })
            .collect();
        out.push(ToppleImpact {
            context,
            frame,
            time_in_frame: offset + ev.time_in_step,
            bodies: entities,
            contacts,
            report: ev.report,
        });
    }
}

/// A collider with a [`crate::bevy::ToppleMaterial`] whose impacts topple
/// leaves to Rapier (its shape, a sensor, a moving kinematic body, locked
/// axes, another dominance group: [`LeftToRapier`]); sent once per collider
/// and reason, with a warning in the log.
///
/// ```
/// use topple::bevy::ToppleNotice;
/// fn report(mut notices: bevy::prelude::MessageReader<ToppleNotice>) {
///     for n in notices.read() {
///         println!("{:?} ({}): {}", n.entity, n.shape, n.reason);
///     }
/// }
/// # let _ = report;
/// ```
#[derive(Message, Clone, Debug, PartialEq)]
pub struct ToppleNotice {
    /// The Rapier context.
    pub context: Entity,
    /// The collider's entity (`None` if it was despawned meanwhile).
    pub entity: Option<Entity>,
    /// parry's name of its shape.
    pub shape: &'static str,
    /// Why.
    pub reason: LeftToRapier,
}

/// Forwards Rapier's collision events of a topple context to bevy_rapier's
/// messages, as bevy_rapier does for the contexts it steps.
#[derive(Default)]
pub(crate) struct CollisionCollector {
    pub events: std::sync::Mutex<Vec<CollisionEvent>>,
}

impl bevy_rapier2d::rapier::pipeline::EventHandler for CollisionCollector {
    fn handle_collision_event(
        &self,
        _bodies: &RigidBodySet,
        colliders: &ColliderSet,
        event: bevy_rapier2d::rapier::geometry::CollisionEvent,
        _pair: Option<&bevy_rapier2d::rapier::geometry::ContactPair>,
    ) {
        use bevy_rapier2d::rapier::geometry::CollisionEvent as E;
        let entity = |h| {
            colliders
                .get(h)
                .map(|co| Entity::from_bits(co.user_data as u64))
        };
        let ev = match event {
            E::Started(a, b, f) => entity(a)
                .zip(entity(b))
                .map(|(a, b)| CollisionEvent::Started(a, b, f)),
            E::Stopped(a, b, f) => entity(a)
                .zip(entity(b))
                .map(|(a, b)| CollisionEvent::Stopped(a, b, f)),
        };
        if let (Some(ev), Ok(mut events)) = (ev, self.events.lock()) {
            events.push(ev);
        }
    }

    fn handle_contact_force_event(
        &self,
        _dt: bevy_rapier2d::rapier::math::Real,
        _bodies: &RigidBodySet,
        _colliders: &ColliderSet,
        _pair: &bevy_rapier2d::rapier::geometry::ContactPair,
        _total_force_magnitude: bevy_rapier2d::rapier::math::Real,
    ) {
    }
}
