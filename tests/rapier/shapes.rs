//! Every collider shape a game puts a material on, in plain Rapier (f64):
//! resolved by the LZB law (a body landing flat keeps e² of its kinetic
//! energy, the closed form of a one-degree-of-freedom impact, and does not
//! turn), or left to Rapier with one notice naming the collider and why;
//! never a pass through the ground. And the same world in metres and in
//! pixels (length unit 100) moves the same, scaled.

use topple::coupling::{PairMaterial, ToppleSettings};
use topple::impact::ContactMaterial;
use topple::rapier::f64::{Notice, ToppleRapier};
use topple::rapier::LeftToRapier;
use topple::rapier2d_f64::prelude::*;

const DT: f64 = 1.0 / 60.0;
const E: f64 = 0.5;

fn material() -> PairMaterial {
    PairMaterial {
        impact: ContactMaterial::hertz(1e8)
            .with_restitution(E)
            .with_friction(0.5, 0.6),
        smooth_friction: 0.5,
    }
}

/// A world of length unit `l` (m per unit… a typical size) with gravity
/// 9.81·l, topple with its default settings, and one material.
fn world(l: f64) -> (PhysicsWorld, ToppleRapier, topple::coupling::MaterialId) {
    let mut w = PhysicsWorld {
        gravity: Vector::new(0.0, -9.81 * l),
        ..PhysicsWorld::default()
    };
    w.integration_parameters.dt = DT;
    w.integration_parameters.length_unit = l;
    let mut topple = ToppleRapier::new(ToppleSettings::default());
    let m = topple.add_material(material());
    (w, topple, m)
}

/// Grounds with their top face at y = 0 (length unit 1).
fn grounds() -> Vec<(&'static str, ColliderBuilder)> {
    let v = |x: f64, y: f64| Vector::new(x, y);
    vec![
        (
            "cuboid",
            ColliderBuilder::cuboid(5.0, 0.5).translation(v(0.0, -0.5)),
        ),
        (
            "segment",
            ColliderBuilder::segment(v(-5.0, 0.0), v(5.0, 0.0)),
        ),
        (
            "polyline",
            ColliderBuilder::polyline(vec![v(-5.0, 0.0), v(0.0, 0.0), v(5.0, 0.0)], None),
        ),
        (
            "heightfield",
            ColliderBuilder::heightfield(vec![0.0; 11], v(10.0, 1.0)),
        ),
        (
            "trimesh",
            ColliderBuilder::trimesh(
                vec![v(-5.0, -1.0), v(5.0, -1.0), v(5.0, 0.0), v(-5.0, 0.0)],
                vec![[0, 1, 2], [0, 2, 3]],
            )
            .expect("a valid mesh"),
        ),
        (
            "half-space",
            ColliderBuilder::halfspace(topple::rapier2d_f64::na::Unit::new_unchecked(Vector::Y)),
        ),
    ]
}

/// Bodies with a flat bottom 0.1 below their centre (or a ball of radius
/// 0.1), symmetric about x = 0 (length unit 1).
fn bodies() -> Vec<(&'static str, ColliderBuilder)> {
    let v = |x: f64, y: f64| Vector::new(x, y);
    vec![
        ("ball", ColliderBuilder::ball(0.1)),
        ("cuboid", ColliderBuilder::cuboid(0.2, 0.1)),
        ("capsule", ColliderBuilder::capsule_x(0.2, 0.1)),
        (
            "convex polygon",
            ColliderBuilder::convex_hull(&[v(-0.3, -0.1), v(0.3, -0.1), v(0.2, 0.1), v(-0.2, 0.1)])
                .expect("convex"),
        ),
        (
            "round cuboid",
            ColliderBuilder::round_cuboid(0.18, 0.08, 0.02),
        ),
        (
            "compound",
            ColliderBuilder::compound(vec![
                (Pose::translation(-0.15, 0.0), SharedShape::cuboid(0.1, 0.1)),
                (Pose::translation(0.15, 0.0), SharedShape::cuboid(0.1, 0.1)),
            ]),
        ),
        (
            "triangle",
            ColliderBuilder::triangle(v(-0.2, -0.1), v(0.2, -0.1), v(0.0, 0.1)),
        ),
    ]
}

/// Drops a body at 2 m/s from 0.01 above the ground, centred at x = 0.5:
/// its base (at most 0.6 wide) lies within one segment of the polyline and
/// one cell of the heightfield (vertices at whole x). Returns the kinetic
/// energy ratio of its first impact, its angular velocity after it, the
/// notices, and the lowest its bottom went below the ground.
fn drop(ground: ColliderBuilder, body: ColliderBuilder) -> (Option<f64>, f64, Vec<Notice>, f64) {
    drop_at(ground, body, 0.5)
}

/// [`drop`] centred at `x`.
fn drop_at(
    ground: ColliderBuilder,
    body: ColliderBuilder,
    x: f64,
) -> (Option<f64>, f64, Vec<Notice>, f64) {
    let (mut w, mut topple, m) = world(1.0);
    let (_, g) = w.insert(RigidBodyBuilder::fixed(), ground);
    topple.manage(&mut w.colliders, g, m);
    let (b, c) = w.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(x, 0.11))
            .linvel(Vector::new(0.0, -2.0)),
        body,
    );
    topple.manage(&mut w.colliders, c, m);
    let (mut ratio, mut spin, mut lowest) = (None, 0.0f64, 0.0f64);
    let mut notices = Vec::new();
    for _ in 0..60 {
        topple.step(&mut w);
        notices.extend(topple.take_notices());
        if ratio.is_none()
            && let Some(r) = topple.last_impacts().first()
        {
            ratio = Some(r.kinetic_energy_after / r.kinetic_energy_before);
            spin = w.bodies[b].angvel().abs();
        }
        let aabb = w.colliders[c].compute_aabb();
        lowest = lowest.min(aabb.mins.y);
    }
    (ratio, spin, notices, -lowest)
}

/// Known misses (not yet mended): a compound of two boxes landing flat on
/// a polyline or heightfield. parry's GJK returns no points for one box
/// against its segment at the gap near 10⁻⁹ where topple resolves the
/// impact (in either order of the shapes), so the impact takes one box's
/// face only and the body lands tilted (kinetic energy ratio 0.50 instead
/// of e² = 0.25, 1.7 rad/s). A compound on a segment, a cuboid or a mesh is
/// read right.
const KNOWN_PARTIAL: [(&str, &str); 2] = [("compound", "polyline"), ("compound", "heightfield")];

#[test]
fn every_shape_on_every_ground_lands_with_the_closed_form() {
    let mut failures = Vec::new();
    for (gname, ground) in grounds() {
        for (bname, body) in bodies() {
            let (ratio, spin, notices, _) = drop(ground.clone(), body);
            let what = format!("{bname} on {gname}");
            let Some(ratio) = ratio else {
                failures.push(format!("{what}: no topple impact"));
                continue;
            };
            if KNOWN_PARTIAL.contains(&(bname, gname)) {
                // resolved as a tilted landing: no energy made
                if ratio > 1.0 + 1e-9 || !notices.is_empty() {
                    failures.push(format!("{what}: energy ratio {ratio}, {notices:?}"));
                }
                continue;
            }
            // a flat landing: v' = e v, so the kinetic energy keeps e²
            if (ratio - E * E).abs() >= 2e-3 {
                failures.push(format!("{what}: energy ratio {ratio}"));
            }
            if spin >= 1e-6 {
                failures.push(format!("{what}: turns at {spin} rad/s"));
            }
            if !notices.is_empty() {
                failures.push(format!("{what}: {notices:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Nothing goes into the ground deeper than twice Rapier's allowed
/// penetration (0.005 of the length unit) over a second of bounces.
#[test]
fn every_shape_on_every_ground_stays_out_of_it() {
    let mut failures = Vec::new();
    for (gname, ground) in grounds() {
        for (bname, body) in bodies() {
            let (_, _, _, depth) = drop(ground.clone(), body);
            let limit = 0.01;
            if depth >= limit {
                failures.push(format!("{bname} on {gname}: {depth} m into the ground"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A known limit: a flat face landing across a vertex of a polyline or
/// heightfield. parry's internal-edge filter drops the points of one
/// segment at the gaps near 10⁻⁹ where topple resolves the impact, so that
/// side is resolved a moment later, as a slightly tilted landing: not the
/// closed form, but no energy is created, and nothing goes through.
#[test]
fn a_flat_face_across_a_ground_vertex_is_safe() {
    for (gname, ground) in grounds() {
        for (bname, body) in bodies() {
            let (ratio, _, notices, depth) = drop_at(ground.clone(), body, 0.05);
            let what = format!("{bname} on {gname} across x = 0");
            let ratio = ratio.unwrap_or_else(|| panic!("{what}: no topple impact"));
            assert!(ratio <= 1.0 + 1e-9, "{what}: energy ratio {ratio}");
            assert!(notices.is_empty(), "{what}: {notices:?}");
            assert!(depth < 0.01, "{what}: {depth} m into the ground");
        }
    }
}

#[test]
fn shapes_topple_cannot_read_are_left_to_rapier_with_one_notice() {
    let voxels = ColliderBuilder::voxels(
        Vector::new(0.1, 0.1),
        &[IVector::new(0, 0), IVector::new(1, 0)],
    );
    let (ratio, _, notices, depth) = drop(
        ColliderBuilder::cuboid(5.0, 0.5).translation(Vector::new(0.0, -0.5)),
        voxels,
    );
    assert_eq!(ratio, None, "topple resolved a voxel impact");
    assert_eq!(notices.len(), 1, "{notices:?}");
    assert_eq!(notices[0].reason, LeftToRapier::Shape("voxels"));
    assert!(depth < 0.05, "the voxels went {depth} m into the ground");
}

#[test]
fn sensors_kinematic_bodies_and_locked_axes() {
    // a sensor with a material: one notice, nothing resolved
    let (mut w, mut topple, m) = world(1.0);
    let (_, s) = w.insert(
        RigidBodyBuilder::fixed(),
        ColliderBuilder::cuboid(1.0, 1.0).sensor(true),
    );
    assert!(topple.manage(&mut w.colliders, s, m));
    let notices = topple.take_notices();
    assert_eq!(notices.len(), 1);
    assert_eq!(notices[0].reason, LeftToRapier::Sensor);

    // a kinematic paddle moving into a free ball (no gravity): Rapier's
    // response, one notice, the ball pushed away, never passed through
    let (mut w, mut topple, m) = world(1.0);
    w.gravity = Vector::ZERO;
    let (paddle, p) = w.insert(
        RigidBodyBuilder::kinematic_velocity_based().linvel(Vector::new(2.0, 0.0)),
        ColliderBuilder::cuboid(0.1, 0.5),
    );
    let (ball, b) = w.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.3, 0.0)),
        ColliderBuilder::ball(0.1),
    );
    topple.manage(&mut w.colliders, p, m);
    topple.manage(&mut w.colliders, b, m);
    let mut notices = Vec::new();
    for _ in 0..30 {
        topple.step(&mut w);
        notices.extend(topple.take_notices());
        let gap = w.bodies[ball].translation().x - w.bodies[paddle].translation().x;
        assert!(gap > 0.19, "the ball went into the paddle: gap {gap}");
    }
    assert_eq!(topple.stats().impacts, 0);
    assert_eq!(notices.len(), 1, "{notices:?}");
    assert_eq!(notices[0].reason, LeftToRapier::Driven);
    assert!(w.bodies[ball].linvel().x >= 2.0 - 1e-6);

    // a kinematic slab at rest is a wall: the LZB law, e² of the energy
    let (ratio, _, notices, _) = {
        let (mut w, mut topple, m) = world(1.0);
        let (_, g) = w.insert(
            RigidBodyBuilder::kinematic_position_based().translation(Vector::new(0.0, -0.5)),
            ColliderBuilder::cuboid(5.0, 0.5),
        );
        topple.manage(&mut w.colliders, g, m);
        let (_, c) = w.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.0, 0.11))
                .linvel(Vector::new(0.0, -2.0)),
            ColliderBuilder::cuboid(0.2, 0.1),
        );
        topple.manage(&mut w.colliders, c, m);
        let mut ratio = None;
        for _ in 0..10 {
            topple.step(&mut w);
            if ratio.is_none() {
                ratio = topple
                    .last_impacts()
                    .first()
                    .map(|r| r.kinetic_energy_after / r.kinetic_energy_before);
            }
        }
        (ratio, 0.0, topple.take_notices(), 0.0)
    };
    assert!((ratio.expect("an impact") - E * E).abs() < 2e-3);
    assert!(notices.is_empty());

    // locked rotation: resolved, cannot turn; one locked translation: Rapier's
    for (locks, resolved) in [
        (LockedAxes::ROTATION_LOCKED, true),
        (LockedAxes::TRANSLATION_LOCKED_X, false),
    ] {
        let (mut w, mut topple, m) = world(1.0);
        let (_, g) = w.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5)),
            ColliderBuilder::cuboid(5.0, 0.5),
        );
        topple.manage(&mut w.colliders, g, m);
        // dropped on a corner: a free box would turn
        let (b, c) = w.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(0.0, 0.2))
                .rotation(0.3)
                .linvel(Vector::new(0.0, -2.0))
                .locked_axes(locks),
            ColliderBuilder::cuboid(0.2, 0.1),
        );
        topple.manage(&mut w.colliders, c, m);
        let mut notices = Vec::new();
        for _ in 0..30 {
            topple.step(&mut w);
            notices.extend(topple.take_notices());
            assert!(
                w.colliders[c].compute_aabb().mins.y > -0.01,
                "{locks:?}: in the ground"
            );
        }
        if resolved {
            assert!(topple.stats().impacts > 0, "{locks:?}");
            assert!(notices.is_empty(), "{locks:?}: {notices:?}");
            assert_eq!(w.bodies[b].angvel(), 0.0);
        } else {
            assert_eq!(topple.stats().impacts, 0, "{locks:?}");
            assert_eq!(notices.len(), 1, "{locks:?}: {notices:?}");
            assert_eq!(notices[0].reason, LeftToRapier::LockedAxes);
        }
    }
}

/// A few boxes and a ball dropped on a ground (one on a corner), and a box
/// thrown at another in mid-air, in a world of length unit `l` (all lengths
/// times `l`). No body slides to rest on the ground within the test: Rapier
/// itself is not exactly scale-invariant there (a box sliding to rest at
/// 1/240 s steps differs by 3·10⁻⁶ m between the two scales in native
/// Rapier).
fn scaled_scene(l: f64) -> (PhysicsWorld, ToppleRapier, Vec<RigidBodyHandle>) {
    let (mut w, mut topple, m) = world(l);
    let v = |x: f64, y: f64| Vector::new(x * l, y * l);
    let (_, g) = w.insert(
        RigidBodyBuilder::fixed().translation(v(0.0, -0.5)),
        ColliderBuilder::cuboid(5.0 * l, 0.5 * l),
    );
    topple.manage(&mut w.colliders, g, m);
    let mut handles = Vec::new();
    let bodies = [
        (
            ColliderBuilder::cuboid(0.2 * l, 0.1 * l),
            v(-1.0, 0.5),
            0.0,
            v(0.0, 0.0),
        ),
        (
            ColliderBuilder::cuboid(0.1 * l, 0.1 * l),
            v(0.0, 0.8),
            0.4,
            v(0.0, 0.0),
        ),
        (
            ColliderBuilder::ball(0.1 * l),
            v(1.0, 1.0),
            0.0,
            v(0.0, 0.0),
        ),
        (
            ColliderBuilder::cuboid(0.1 * l, 0.1 * l),
            v(2.0, 2.0),
            0.0,
            v(3.0, 0.0),
        ),
        (
            ColliderBuilder::cuboid(0.1 * l, 0.1 * l),
            v(2.5, 2.0),
            0.0,
            v(0.0, 0.0),
        ),
    ];
    for (shape, at, angle, vel) in bodies {
        let (h, c) = w.insert(
            RigidBodyBuilder::dynamic()
                .translation(at)
                .rotation(angle)
                .linvel(vel),
            shape.density(1000.0 / (l * l)),
        );
        topple.manage(&mut w.colliders, c, m);
        handles.push(h);
    }
    (w, topple, handles)
}

#[test]
#[ignore = "known: frame 22, a box landing on its corner takes a different impact path at length unit 100 (ω differs by 0.7 %); identical to 10⁻¹⁴ before it"]
fn metres_and_pixels_give_the_same_motion_scaled() {
    let (mut m, mut tm, hm) = scaled_scene(1.0);
    let (mut p, mut tp, hp) = scaled_scene(100.0);
    let mut largest = 0.0f64;
    for frame in 0..60 {
        tm.step(&mut m);
        tp.step(&mut p);
        assert_eq!(
            tm.last_impacts().len(),
            tp.last_impacts().len(),
            "frame {frame}: the impacts differ"
        );
        for (&a, &b) in hm.iter().zip(&hp) {
            let (x, y) = (m.bodies[a].translation(), p.bodies[b].translation() / 100.0);
            largest = largest.max((x - y).length());
            let (wa, wb) = (m.bodies[a].angvel(), p.bodies[b].angvel());
            assert!(
                (wa - wb).abs() < 1e-6 * (1.0 + wa.abs()),
                "frame {frame}: ω {wa} vs {wb}"
            );
        }
    }
    assert!(tm.stats().impacts >= 5, "{:?}", tm.stats());
    assert_eq!(tm.stats().impacts, tp.stats().impacts);
    assert!(largest < 1e-9, "positions differ by {largest} m");
}
