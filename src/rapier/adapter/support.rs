//! Which managed pairs topple resolves, and which it leaves to Rapier.
//!
//! topple resolves an impact between two colliders it manages when it can
//! read their contact geometry from parry and when every body that takes
//! part can be moved by an impulse the way the LZB resolver assumes (a planar
//! body with one mass and one moment of inertia). Everything else stays
//! Rapier's, with the pair's friction and restitution, exactly as in native
//! Rapier; the hook then leaves the pair's contact points to Rapier's solver
//! and the adapter reports the collider once ([`Notice`]):
//!
//! | what | topple | reason if left |
//! | --- | --- | --- |
//! | ball, cuboid, capsule, segment, triangle, convex polygon, half-space, round cuboid, round triangle, round convex polygon | LZB, λ points where two flat faces meet | |
//! | compound, polyline, trimesh, heightfield (as ground or on a body) | LZB per sub-shape manifold, λ points on each flat patch | |
//! | voxels, custom shapes | Rapier | [`LeftToRapier::Shape`] |
//! | sensors | never touch anything | [`LeftToRapier::Sensor`] |
//! | dynamic body | free body of the impact; locked rotation or zero inertia: it cannot turn (its inertia is taken as [`LOCKED_INERTIA`] × m r²) | |
//! | fixed body, kinematic or zero-mass body at rest | a wall (infinite mass) | |
//! | kinematic or zero-mass dynamic body that moves | Rapier | [`LeftToRapier::Driven`] |
//! | dynamic body with one translation locked, or translations locked and rotation free | Rapier | [`LeftToRapier::LockedAxes`] |
//! | two free bodies of different dominance groups | Rapier | [`LeftToRapier::Dominance`] |
//!
//! Joints are Rapier's: jointed bodies take part in impacts as free bodies
//! (an impact is instantaneous) and the joint solver holds them together
//! afterwards.

use super::backend::math::Vector;
use super::backend::parry::shape::{Shape, ShapeType};
use super::backend::prelude::{Collider, ColliderHandle, ColliderSet, RigidBody, RigidBodySet};
use crate::rapier::LeftToRapier;

/// A managed collider whose impacts (all of them, or those with one other
/// collider) topple leaves to Rapier; reported once per collider and reason
/// by [`super::ToppleRapier::take_notices`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Notice {
    /// The collider.
    pub collider: ColliderHandle,
    /// Its shape (parry's name of the shape type).
    pub shape: &'static str,
    /// Why.
    pub reason: LeftToRapier,
}

/// A body that cannot turn (locked rotation, or zero moment of inertia) is
/// given this many times m r² (r: its bounding radius) as its moment of
/// inertia: the resolver needs a finite one, and its angular velocity change
/// is then below 10⁻¹² of a free body's.
pub const LOCKED_INERTIA: f64 = 1e12;

/// How parry gives a pair's contact geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Geometry {
    /// One manifold (`contact_manifold_convex_convex`).
    Convex,
    /// One manifold per pair of sub-shapes (`contact_manifolds`).
    Composite,
}

/// parry's name of a shape type.
pub(crate) fn shape_name(shape: &dyn Shape) -> &'static str {
    match shape.shape_type() {
        ShapeType::Ball => "ball",
        ShapeType::Cuboid => "cuboid",
        ShapeType::Capsule => "capsule",
        ShapeType::Segment => "segment",
        ShapeType::Triangle => "triangle",
        ShapeType::Voxels => "voxels",
        ShapeType::TriMesh => "trimesh",
        ShapeType::Polyline => "polyline",
        ShapeType::HalfSpace => "half-space",
        ShapeType::HeightField => "heightfield",
        ShapeType::Compound => "compound",
        ShapeType::ConvexPolygon => "convex polygon",
        ShapeType::RoundCuboid => "round cuboid",
        ShapeType::RoundTriangle => "round triangle",
        ShapeType::RoundConvexPolygon => "round convex polygon",
        ShapeType::Custom => "custom shape",
    }
}

/// How topple reads a shape, or why it cannot.
pub(crate) fn geometry(shape: &dyn Shape) -> Result<Geometry, LeftToRapier> {
    match shape.shape_type() {
        ShapeType::Voxels | ShapeType::Custom => Err(LeftToRapier::Shape(shape_name(shape))),
        ShapeType::Compound | ShapeType::TriMesh | ShapeType::Polyline | ShapeType::HeightField => {
            Ok(Geometry::Composite)
        }
        _ => Ok(Geometry::Convex),
    }
}

/// How a body takes part in an impact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    /// Moved by the impact.
    Free,
    /// Does not move: infinite mass, at rest.
    Wall,
    /// Its pairs are Rapier's.
    Left(LeftToRapier),
}

/// The role of a body in an impact (see the module table).
pub(crate) fn role(rb: &RigidBody) -> Role {
    if rb.is_fixed() {
        return Role::Wall;
    }
    let still = rb.linvel() == Vector::ZERO && rb.angvel() == 0.0;
    if rb.is_kinematic() {
        return if still {
            Role::Wall
        } else {
            Role::Left(LeftToRapier::Driven)
        };
    }
    let m = rb.mass_properties();
    match (m.effective_inv_mass.x > 0.0, m.effective_inv_mass.y > 0.0) {
        (true, true) => Role::Free,
        (false, false) if m.effective_world_inv_inertia > 0.0 => {
            Role::Left(LeftToRapier::LockedAxes)
        }
        (false, false) if still => Role::Wall,
        (false, false) if rb.mass() > 0.0 => Role::Left(LeftToRapier::LockedAxes),
        (false, false) => Role::Left(LeftToRapier::Driven),
        _ => Role::Left(LeftToRapier::LockedAxes),
    }
}

/// Whether topple resolves the impacts of two managed colliders: `Ok` with
/// the way to read their geometry, or the collider (of the two) topple
/// leaves to Rapier and why. Two walls are never an impact pair. The hook
/// asks this of every managed pair at every Rapier step, so each collider
/// and body is looked up once.
pub(crate) fn pair(
    bodies: &RigidBodySet,
    colliders: &ColliderSet,
    a: ColliderHandle,
    b: ColliderHandle,
) -> Result<Geometry, Option<Notice>> {
    let (Some(ca), Some(cb)) = (colliders.get(a), colliders.get(b)) else {
        return Err(None);
    };
    if ca.parent().is_some() && ca.parent() == cb.parent() {
        return Err(None); // one body's own colliders
    }
    let notice = |h: ColliderHandle, co: &Collider, reason| {
        Err(Some(Notice {
            collider: h,
            shape: shape_name(co.shape()),
            reason,
        }))
    };
    for (h, co) in [(a, ca), (b, cb)] {
        if co.is_sensor() {
            return notice(h, co, LeftToRapier::Sensor);
        }
    }
    let mut composite = false;
    for (h, co) in [(a, ca), (b, cb)] {
        match geometry(co.shape()) {
            Ok(g) => composite |= g == Geometry::Composite,
            Err(reason) => return notice(h, co, reason),
        }
    }
    let body = |co: &Collider| co.parent().and_then(|h| bodies.get(h));
    let (ba, bb) = (body(ca), body(cb));
    // a collider without a body is a wall
    let (ra, rb) = (ba.map_or(Role::Wall, role), bb.map_or(Role::Wall, role));
    for (h, co, r) in [(a, ca, ra), (b, cb, rb)] {
        if let Role::Left(reason) = r {
            return notice(h, co, reason);
        }
    }
    match (ra, rb) {
        (Role::Wall, Role::Wall) => return Err(None),
        (Role::Free, Role::Free) => {
            let group = |b: Option<&RigidBody>| b.map_or(0, RigidBody::dominance_group);
            if group(ba) != group(bb) {
                return notice(a, ca, LeftToRapier::Dominance);
            }
        }
        _ => {}
    }
    Ok(if composite {
        Geometry::Composite
    } else {
        Geometry::Convex
    })
}
