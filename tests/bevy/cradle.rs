//! A cradle of five touching discs in a headless Bevy app (no gravity): with
//! topple's e = 1 impacts momentum and kinetic energy are conserved (laws
//! independent of the resolver), and the impact message carries the energy
//! the first disc brought in, ½ m v².

use std::time::Duration;

use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bevy_rapier2d::prelude::*;
use topple::bevy::{rapier_plugin, ToppleImpact, ToppleMaterial, TopplePlugin};
use topple::coupling::PairMaterial;
use topple::impact::ContactMaterial;

const MASS: f32 = 0.26;
const RADIUS: f32 = 0.02;
const V0: f32 = 1.0;

#[derive(Resource, Default)]
struct Seen(Vec<ToppleImpact>);

fn record(mut impacts: MessageReader<ToppleImpact>, mut seen: ResMut<Seen>) {
    seen.0.extend(impacts.read().cloned());
}

/// How the app steps physics.
#[derive(Clone, Copy, Debug)]
enum Stepping {
    /// `TimestepMode::Fixed` with this many sub-steps, in `PostUpdate`.
    Fixed(usize),
    /// `TimestepMode::Variable`.
    Variable,
    /// `TimestepMode::Interpolated`.
    Interpolated,
    /// Both plugins in `FixedUpdate` (Bevy's 64 Hz fixed clock).
    FixedSchedule,
}

fn cradle(topple: bool) -> (App, Vec<Entity>) {
    cradle_stepped(topple, Stepping::Fixed(1))
}

fn cradle_stepped(topple: bool, stepping: Stepping) -> (App, Vec<Entity>) {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin));
    match stepping {
        Stepping::FixedSchedule => app.add_plugins((
            rapier_plugin().in_fixed_schedule(),
            TopplePlugin::default().in_fixed_schedule(),
        )),
        _ => app.add_plugins((rapier_plugin(), TopplePlugin::default())),
    };
    let mode = match stepping {
        Stepping::Fixed(substeps) => TimestepMode::Fixed {
            dt: 1.0 / 60.0,
            substeps,
        },
        Stepping::Variable => TimestepMode::Variable {
            max_dt: 1.0 / 30.0,
            time_scale: 1.0,
            substeps: 1,
        },
        Stepping::Interpolated => TimestepMode::Interpolated {
            dt: 1.0 / 60.0,
            time_scale: 1.0,
            substeps: 1,
        },
        Stepping::FixedSchedule => TimestepMode::Fixed {
            dt: 1.0 / 64.0,
            substeps: 1,
        },
    };
    app.insert_resource(mode)
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
            1.0 / 60.0,
        )))
        .init_resource::<Seen>()
        .add_systems(PostUpdate, record.after(topple::bevy::ToppleSystems::Step));
    app.finish();
    app.cleanup();
    app.update();
    let world = app.world_mut();
    for mut config in world.query::<&mut RapierConfiguration>().iter_mut(world) {
        config.gravity = Vec2::ZERO;
    }
    let steel = PairMaterial {
        impact: ContactMaterial::hertz(1.0e10).with_restitution(1.0),
        smooth_friction: 0.0,
    };
    let balls = (0..5)
        .map(|i| {
            let mut e = world.spawn((
                RigidBody::Dynamic,
                Collider::ball(RADIUS),
                ColliderMassProperties::Mass(MASS),
                Restitution::coefficient(1.0),
                Friction::coefficient(0.0),
                Transform::from_xyz(i as f32 * 2.0 * RADIUS, 0.0, 0.0),
                Velocity::linear(Vec2::new(if i == 0 { V0 } else { 0.0 }, 0.0)),
            ));
            if topple {
                e.insert(ToppleMaterial(steel));
            }
            e.id()
        })
        .collect();
    (app, balls)
}

fn momentum_and_energy(app: &App, balls: &[Entity]) -> (f32, f32) {
    balls.iter().fold((0.0, 0.0), |(p, e), &b| {
        let v = app.world().get::<Velocity>(b).unwrap();
        (
            p + MASS * v.linear.x,
            e + 0.5 * MASS * v.linear.length_squared(),
        )
    })
}

#[test]
fn every_timestep_mode_steps_the_cradle_with_topple() {
    for stepping in [
        Stepping::Fixed(3),
        Stepping::Variable,
        Stepping::Interpolated,
        Stepping::FixedSchedule,
    ] {
        let (mut app, balls) = cradle_stepped(true, stepping);
        for _ in 0..30 {
            app.update();
        }
        let (p, e) = momentum_and_energy(&app, &balls);
        let (p0, e0) = (MASS * V0, 0.5 * MASS * V0 * V0);
        assert!((p / p0 - 1.0).abs() < 1e-5, "{stepping:?}: momentum {p}");
        assert!((e / e0 - 1.0).abs() < 1e-5, "{stepping:?}: energy {e}");
        let last = app.world().get::<Velocity>(balls[4]).unwrap().linear.x;
        assert!(last > 0.9 * V0, "{stepping:?}: last disc {last}");
        assert!(
            !app.world().resource::<Seen>().0.is_empty(),
            "{stepping:?}: no impact message"
        );
    }
}

#[test]
fn topple_cradle_keeps_momentum_and_energy() {
    let (mut app, balls) = cradle(true);
    for _ in 0..30 {
        app.update();
    }
    let (p, e) = momentum_and_energy(&app, &balls);
    let (p0, e0) = (MASS * V0, 0.5 * MASS * V0 * V0);
    assert!((p / p0 - 1.0).abs() < 1e-5, "momentum {p} vs {p0}");
    assert!((e / e0 - 1.0).abs() < 1e-5, "energy {e} vs {e0}");
    // the wave went through: the last disc carries most of it
    let last = app.world().get::<Velocity>(balls[4]).unwrap().linear.x;
    assert!(last > 0.9 * V0, "last disc {last}");
    let seen = &app.world().resource::<Seen>().0;
    assert!(!seen.is_empty(), "no impact message");
    let first = &seen[0];
    let ke = 0.5 * f64::from(MASS) * f64::from(V0).powi(2);
    assert!(
        (first.report.kinetic_energy_before / ke - 1.0).abs() < 1e-5,
        "{} vs {ke}",
        first.report.kinetic_energy_before
    );
    assert!(first.energy_dissipated().abs() < 1e-6 * ke);
    assert!(first.involves_pair(balls[0], balls[1]));
}

#[test]
fn colliders_without_a_material_stay_plain_rapier() {
    let (mut app, balls) = cradle(false);
    for _ in 0..30 {
        app.update();
    }
    let (p, e) = momentum_and_energy(&app, &balls);
    eprintln!(
        "native cradle after 0.5 s: momentum {:.4} %, energy {:.4} % of the start",
        100.0 * p / (MASS * V0),
        100.0 * e / (0.5 * MASS * V0 * V0)
    );
    // plain Rapier keeps momentum (its contact impulses are pairwise)
    assert!((p / (MASS * V0) - 1.0).abs() < 1e-3);
    assert!(app.world().resource::<Seen>().0.is_empty());
}
