//! The Bevy plugin on scenes a game builds, with `TopplePlugin::default()`:
//! a box pyramid at rest in bevy_rapier's pixel units against native
//! bevy_rapier, a scene file spawned in metres and in pixels against each
//! other and against the closed form of a flat bounce, and a pile that
//! loses bodies mid-run beside a sensor and a kinematic body.

use crate::example_scenes as scenes;

use std::time::Duration;

use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bevy_rapier2d::plugin::RapierContextInitialization;
use bevy_rapier2d::prelude::*;
use scenes::Target;
use topple::bevy::{rapier_plugin, ImpactResponse, SceneSpawn, ToppleFrameStats, TopplePlugin};
use topple::rapier::scene::Scene;

/// Each box's position (px) and angle after `frames` frames of the 10-level
/// pyramid of 40 px boxes, with the frame statistics summed.
fn pyramid(physics: ImpactResponse, frames: usize) -> (Vec<(Vec2, f32)>, ToppleFrameStats) {
    let mut app = scenes::headless_app(physics);
    let mut boxes = Vec::new();
    scenes::spawn_in(&mut app, |c| {
        boxes = scenes::pyramid(
            c,
            Target {
                physics,
                context: None,
            },
            10,
            40.0,
        );
    });
    let mut sum = ToppleFrameStats::default();
    for _ in 0..frames {
        app.update();
        let s = app.world().resource::<ToppleFrameStats>();
        sum.impacts += s.impacts;
        sum.fallbacks += s.fallbacks;
        sum.native_impacts += s.native_impacts;
        sum.lzb_steps += s.lzb_steps;
    }
    let at = boxes
        .iter()
        .map(|&e| {
            let t = app.world().get::<Transform>(e).unwrap();
            (
                t.translation.truncate(),
                t.rotation.to_euler(EulerRot::ZYX).0,
            )
        })
        .collect();
    (at, sum)
}

#[test]
fn pixel_pyramid_at_rest_has_no_impacts_and_stands_as_native() {
    let frames = 180;
    let (native, _) = pyramid(ImpactResponse::Native, frames);
    let (topple, stats) = pyramid(ImpactResponse::Topple, frames);
    // the default threshold follows the scene (2|g|Δt in pixels): resting
    // contacts are not impacts
    assert_eq!(stats.impacts, 0, "{stats:?}");
    assert_eq!(stats.lzb_steps, 0, "{stats:?}");
    assert_eq!(stats.fallbacks, 0, "{stats:?}");
    assert_eq!(stats.native_impacts, 0, "{stats:?}");
    // and it stands where native bevy_rapier's stands: each box within
    // 0.1 px (0.25 % of its size) and 10⁻³ rad of native's
    let mut largest = (0.0f32, 0.0f32);
    for ((a, ta), (b, tb)) in native.iter().zip(&topple) {
        largest.0 = largest.0.max(a.distance(*b));
        largest.1 = largest.1.max((ta - tb).abs());
    }
    assert!(largest.0 < 0.1 && largest.1 < 1e-3, "{largest:?}");
    // native's own pyramid stands: within a pixel of where it started
    for (row, start) in [(0, 20.0), (9, 380.0)] {
        let i = (0..row).map(|r| 10 - r).sum::<usize>();
        assert!((native[i].0.y - start).abs() < 1.0, "{:?}", native[i]);
    }
}

/// The scene file of a flat box dropped on the ground (e = 0.5).
fn flat_drop() -> Scene {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/scenes/box-drop-flat.toml"
    ))
    .unwrap();
    toml::from_str(&text).unwrap()
}

/// The box's height (m) frame by frame at 1/60 s, the scene spawned at
/// `scale` world units per metre in a context of length unit `scale` (a
/// game's: 1 in metres, 100 in bevy_rapier's pixels), with
/// `TopplePlugin::default()`; and the impacts.
fn drop_in_bevy(scale: f32, frames: usize) -> (Vec<f32>, u64) {
    let (heights, impacts) = drop_in_bevy_with_impacts(&flat_drop(), scale, frames);
    (heights, impacts.len() as u64)
}

/// [`drop_in_bevy`] for any scene of one body, with the reports of its
/// impacts.
fn drop_in_bevy_with_impacts(
    scene: &Scene,
    scale: f32,
    frames: usize,
) -> (Vec<f32>, Vec<topple::coupling::ImpactReport>) {
    let spawn = SceneSpawn::new(scene).with_scale(scale);
    let mut params = spawn.integration_parameters();
    params.dt = 1.0 / 60.0;
    // a game's length unit: 1 in metres, 100 with `pixels_per_meter(100)`
    params.length_unit = scale;
    let init = RapierContextInitialization::InitializeDefaultRapierContext {
        integration_parameters: params,
        rapier_configuration: spawn.rapier_configuration(),
    };
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin))
        .add_plugins((
            rapier_plugin().with_custom_initialization(init),
            TopplePlugin::default(),
        ))
        .insert_resource(TimestepMode::Fixed {
            dt: 1.0 / 60.0,
            substeps: 1,
        })
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
            1.0 / 60.0,
        )));
    app.finish();
    app.cleanup();
    app.update();
    let spawned = {
        let world = app.world_mut();
        let mut commands = world.commands();
        let s = spawn.spawn(&mut commands).unwrap();
        world.flush();
        s
    };
    let body = spawned.bodies[0].1;
    let (mut heights, mut impacts) = (Vec::new(), Vec::new());
    for _ in 0..frames {
        app.update();
        let counted = app.world().resource::<ToppleFrameStats>().impacts;
        let reports: Vec<_> = app
            .world_mut()
            .resource_mut::<Messages<topple::bevy::ToppleImpact>>()
            .drain()
            .map(|i| i.report)
            .collect();
        assert_eq!(reports.len() as u64, counted);
        impacts.extend(reports);
        heights.push(app.world().get::<Transform>(body).unwrap().translation.y / scale);
    }
    (heights, impacts)
}

/// A rebound slower than the frame's impact threshold 2|g|Δt (0.33 m/s at
/// 1/60 s) is topple's when Rapier has not held the pair in this frame or
/// the last: a ball (r = 25 mm, the material of `flat_drop`, e = 0.5)
/// dropped from 0.2 m lands at v₀ = √(2 g h) ≈ 1.98 m/s, then at e v₀,
/// e² v₀, ... (ballistic flights return at the speed they left), and each
/// landing keeps e² of the kinetic energy. The fourth landing (0.25 m/s)
/// is below the frame's threshold, after a flight of 2v/g = 50 ms (three
/// frames); the frame's threshold would leave it to Rapier, which stops the
/// ball dead. A landing after a flight shorter than the rule's memory (this
/// frame and the last: 2v/g < 2Δt, v < gΔt = 0.16 m/s) may find the pair
/// still counted as held from the impact before, and is Rapier's: the fifth
/// (0.12 m/s) is (docs/bevy.md, "Rebounds and chatter"). (A box tilts a
/// little at each f32 bounce and lands on a corner after a few, so its
/// landings leave the closed form.)
#[test]
fn slow_rebounds_after_a_flight_are_resolved_by_the_law() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/scenes/box-drop-flat.toml"
    ))
    .unwrap()
    .replace(
        "shape = \"box\"\nsize = [0.10, 0.05]",
        "shape = \"ball\"\nradius = 0.025",
    );
    assert!(text.contains("radius = 0.025"));
    let ball: Scene = toml::from_str(&text).unwrap();
    let g = 9.81f64;
    let (e, v0): (f64, f64) = (0.5, (2.0 * g * 0.2).sqrt());
    let frame_threshold = 2.0 * g / 60.0;
    // the sub-step's threshold 2gΔt/4, and a flight longer than two frames
    let rebound_threshold = (2.0 * g / 240.0).max(g / 60.0);
    for scale in [1.0f32, 100.0] {
        let (_, impacts) = drop_in_bevy_with_impacts(&ball, scale, 90);
        let speeds: Vec<f64> = impacts
            .iter()
            .map(|r| r.approach_speed / f64::from(scale))
            .collect();
        // the landings above the sub-step's threshold after a flight
        // longer than the memory, in order
        let expected: Vec<f64> = (0..)
            .map(|k| v0 * e.powi(k))
            .take_while(|&v| v > rebound_threshold)
            .collect();
        assert_eq!(speeds.len(), expected.len(), "{speeds:?}");
        assert!(expected.iter().any(|&v| v < frame_threshold));
        for (k, (v, want)) in speeds.iter().zip(&expected).enumerate() {
            // Rapier's symplectic Euler over 1/240 s pieces returns a flight
            // at the speed it left to within g·h/2 (0.02 m/s)
            assert!(
                (v - want).abs() < 0.5 * g / 240.0,
                "landing {k}: {v} m/s, closed form {want}"
            );
            let r = &impacts[k];
            let ratio = r.kinetic_energy_after / r.kinetic_energy_before;
            assert!(
                (ratio - e * e).abs() < 1e-2,
                "landing {k} at {v} m/s kept {ratio} of its energy, e² = {}",
                e * e
            );
        }
    }
}

#[test]
fn a_scene_file_in_metres_and_in_pixels_gives_the_same_motion() {
    let frames = 60;
    let (m, im) = drop_in_bevy(1.0, frames);
    let (p, ip) = drop_in_bevy(100.0, frames);
    assert_eq!(im, ip);
    assert!(im >= 1, "the box lands with an impact");
    let largest = m
        .iter()
        .zip(&p)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    // f32: the two worlds round differently (an ulp of 0.2 m is 1.5·10⁻⁸
    // m, of 20 px 1.9·10⁻⁶ px), and each bounce's instant is found to
    // within the closed tolerance, so the bounces drift apart by a little:
    // measured 5·10⁻⁵ m after the second bounce, 0.2 % of the box's height.
    // 10⁻⁴ m (0.4 %) is far below what a wrong scaling of any setting gives
    // (the first bounce alone differed by 9 mm with a length unit of 0.05).
    assert!(largest < 1e-4, "heights differ by {largest} m");
    // the bounce against the closed form: dropped from a base height of
    // h = 0.2 m, it comes back to e² h = 0.05 m (e = 0.5, the flat base
    // meets the ground at once); sampled at 1/60 s the apex is read low
    // by at most v Δt near it, a few mm
    let half = 0.025;
    let landed = m.iter().position(|&y| y - half < 0.01).unwrap();
    let apex = m[landed..].iter().fold(0.0f32, |a, &y| a.max(y - half));
    assert!(
        (apex - 0.05).abs() < 0.005,
        "rebound apex {apex} m, expected 0.05 m"
    );
}

/// Bodies despawned in the middle of a pile's impacts, a sensor and a
/// moving kinematic body with materials: the app keeps running, nothing
/// becomes NaN, the sensor and the kinematic body are each named once in a
/// `ToppleNotice`, and impacts go on after the despawns.
#[test]
fn despawns_sensors_and_kinematic_bodies_in_a_pile() {
    let mut app = scenes::headless_app(ImpactResponse::Topple);
    let target = Target {
        physics: ImpactResponse::Topple,
        context: None,
    };
    let mut boxes = Vec::new();
    let (mut sensor, mut paddle) = (Entity::PLACEHOLDER, Entity::PLACEHOLDER);
    scenes::spawn_in(&mut app, |c| {
        boxes = scenes::pile_in_layers(c, target, 4, 10);
        let mut e = c.spawn((
            RigidBody::Fixed,
            Collider::cuboid(200.0, 20.0),
            Sensor,
            Transform::from_xyz(0.0, 60.0, 0.0),
        ));
        scenes::material(&mut e, target, scenes::Mat::WOOD);
        sensor = e.id();
        let mut e = c.spawn((
            RigidBody::KinematicVelocityBased,
            Collider::cuboid(40.0, 5.0),
            // down through the falling layers into the pile, 210 px in 85 frames
            Velocity::linear(Vec2::new(0.0, -150.0)),
            Transform::from_xyz(0.0, 240.0, 0.0),
        ));
        scenes::material(&mut e, target, scenes::Mat::WOOD);
        paddle = e.id();
    });
    let mut notices = Vec::new();
    let mut impacts = |app: &mut App, frames: usize| {
        (0..frames)
            .map(|_| {
                app.update();
                notices.extend(
                    app.world_mut()
                        .resource_mut::<Messages<topple::bevy::ToppleNotice>>()
                        .drain(),
                );
                app.world().resource::<ToppleFrameStats>().impacts
            })
            .sum::<u64>()
    };
    let before = impacts(&mut app, 25);
    for e in boxes.iter().step_by(3) {
        app.world_mut().despawn(*e);
    }
    let after = impacts(&mut app, 60);
    assert!(before > 0 && after > 0, "{before} {after}");
    for who in [sensor, paddle] {
        let n = notices.iter().filter(|n| n.entity == Some(who)).count();
        assert_eq!(n, 1, "{who}: {notices:?}");
    }
    let world = app.world_mut();
    let mut q = world.query::<(&Transform, &Velocity)>();
    for (t, v) in q.iter(world) {
        assert!(t.translation.is_finite() && v.linear.is_finite() && v.angular.is_finite());
    }
}

/// The frame statistics count the large groups the default policy ends
/// plastic (`FallbackPolicy::large_group`): in a pile dropped in layers,
/// each frame's `large_group_fallbacks` is the number of that frame's
/// `ToppleImpact` messages of large groups (more free bodies than the
/// policy's size, branched) that did not end by the law, some frames have them, and none of those
/// impacts created energy.
#[test]
fn large_groups_of_a_pile_end_plastic_and_are_counted() {
    use topple::bevy::ToppleImpact;
    use topple::coupling::{LargeGroup, Resolution};
    let mut app = scenes::headless_app(ImpactResponse::Topple);
    let target = Target {
        physics: ImpactResponse::Topple,
        context: None,
    };
    scenes::spawn_in(&mut app, |c| {
        scenes::pile_in_layers(c, target, 6, 10);
    });
    let large = LargeGroup::DEFAULT;
    let mut counted = 0;
    for frame in 0..120 {
        app.update();
        let messages: Vec<ToppleImpact> = app
            .world_mut()
            .resource_mut::<Messages<ToppleImpact>>()
            .drain()
            .collect();
        let plastic: Vec<&ToppleImpact> = messages
            .iter()
            .filter(|m| m.report.large_group && m.report.resolution != Resolution::Lzb)
            .collect();
        let stats = app.world().resource::<ToppleFrameStats>();
        assert_eq!(
            stats.large_group_fallbacks,
            plastic.len() as u64,
            "frame {frame}"
        );
        assert!(stats.large_group_fallbacks <= stats.fallbacks);
        for m in plastic {
            let r = &m.report;
            assert!(r.bodies > large.bodies, "frame {frame}: {r:?}");
            assert!(
                r.kinetic_energy_after <= r.kinetic_energy_before * (1.0 + 1e-9) + 1e-12,
                "frame {frame}: {r:?}"
            );
        }
        counted += stats.large_group_fallbacks;
    }
    assert!(counted > 0, "no large group ended plastic");
}
