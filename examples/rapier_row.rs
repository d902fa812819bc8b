//! topple on plain Rapier, without Bevy: a row of Domino T blocks (Table 1
//! of the paper, the ideal material of its Fig. 5) built by hand in a
//! `rapier2d-f64` world, stepped at a game's 1/60 s, with the wave's speed
//! measured from the impacts topple reports and compared with the
//! cooperative model (the theory the paper compares with).
//!
//! ```sh
//! cargo run --release --example rapier_row            # 30 blocks at s/h 0.45
//! cargo run --release --example rapier_row -- 60 0.3  # n and s/h
//! ```

use topple::coupling::{PairMaterial, ToppleSettings};
use topple::domino::{ChainReport, Preset, RowSpec};
use topple::impact::ContactMaterial;
use topple::rapier::f64::ToppleRapier;
use topple::rapier2d_f64::prelude::*;
use topple::theory::{solve, Geometry, Model};

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let n: usize = parse(args.next(), 30, "n (number of blocks, 8 to 10000)")?;
    let ratio: f64 = parse(args.next(), 0.45, "s/h (0.05 to 0.9)")?;
    if !(8..=10_000).contains(&n) || !(0.05..=0.9).contains(&ratio) {
        return Err(format!(
            "need 8 ≤ n ≤ 10000 and 0.05 ≤ s/h ≤ 0.9 (got {n}, {ratio})"
        ));
    }
    let p = Preset::T.params().ideal(); // μ1 = 0, e1 = 0, μ2 = 0.9, e2 = 0
    let (h, d) = (p.block.height, p.block.thickness);
    let row = RowSpec::new(p, ratio * h, n, 1.0);

    // The world: Rapier's step, a length unit of one block and stiff contacts.
    let mut world = PhysicsWorld::default();
    world.integration_parameters.dt = 1.0 / 60.0;
    world.integration_parameters.length_unit = h;
    world
        .integration_parameters
        .contact_softness
        .natural_frequency = topple::rapier::ROW_CONTACT_HERTZ;
    world
        .integration_parameters
        .static_contact_softness
        .natural_frequency = 2.0 * topple::rapier::ROW_CONTACT_HERTZ;

    // topple's materials: block–block and block–ground, from Table 1.
    let mut topple = ToppleRapier::new(ToppleSettings {
        min_approach_speed: 2.0 * p.gravity / 60.0,
        ..ToppleSettings::default()
    });
    let table = |mu, mu_stick, e, k| {
        let law = ContactMaterial::hertz(k).with_exponent(p.alpha);
        PairMaterial::from_table(law, mu, mu_stick, e, p.impact_friction_factor)
    };
    let block = topple.add_material(table(p.mu1, p.mu1_stick, p.e1, p.k1));
    let ground = topple.add_material(table(p.mu2, p.mu2_stick, p.e2, p.k2));
    topple.set_pair_material(block, ground, table(p.mu2, p.mu2_stick, p.e2, p.k2));

    let (_, floor) = world.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -1.0)),
        ColliderBuilder::cuboid(1e3, 1.0),
    );
    topple.manage(&mut world.colliders, floor, ground);
    let mut blocks = Vec::with_capacity(n);
    for i in 0..n {
        let [x, y] = row.centre(i);
        let (v, w) = if i == 0 {
            row.initial_velocity()
        } else {
            ([0.0, 0.0], 0.0)
        };
        let (body, collider) = world.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(x, y))
                .linvel(Vector::new(v[0], v[1]))
                .angvel(w),
            ColliderBuilder::cuboid(0.5 * d, 0.5 * h).mass(p.block.mass),
        );
        topple.manage(&mut world.colliders, collider, block);
        blocks.push(body);
    }

    // Step until the last block is hit; a block is hit at the first impact
    // between it and the block behind it (topple reports the instant).
    let mut hit_times = vec![0.0];
    let mut time = 0.0;
    while hit_times.len() < n && time < 60.0 {
        topple.step(&mut world);
        for event in topple.last_events() {
            let next = blocks[hit_times.len()];
            let behind = blocks[hit_times.len() - 1];
            let struck = topple.event_contacts(event).iter().any(|c| {
                c.bodies == [Some(behind), Some(next)] || c.bodies == [Some(next), Some(behind)]
            });
            if struck && hit_times.len() < n {
                hit_times.push(time + event.time_in_step);
            }
        }
        time += 1.0 / 60.0;
    }
    let report = ChainReport::new("rapier", &row, hit_times);
    let geometry = Geometry::new(d / h, ratio).map_err(|e| e.to_string())?;
    let theory = solve(&Model::Cooperative, &geometry)
        .map_err(|e| e.to_string())?
        .natural_speed();
    let stats = topple.stats();
    println!(
        "{} of {n} blocks hit in {time:.2} s simulated; {} impacts, {} LZB steps",
        report.hit_times.len(),
        stats.impacts,
        stats.impulse_steps
    );
    match (report.natural_speed, theory) {
        (Some(v), Some(c)) => println!(
            "wave speed v/√(gh) = {v:.3}; cooperative model {c:.3} ({:+.1} %)",
            100.0 * (v - c) / c
        ),
        (v, c) => println!("wave speed {v:?}, cooperative model {c:?}"),
    }
    Ok(())
}

fn parse<T: std::str::FromStr>(arg: Option<String>, default: T, what: &str) -> Result<T, String> {
    match arg {
        None => Ok(default),
        Some(s) => s.parse().map_err(|_| format!("{what}: cannot read {s:?}")),
    }
}
