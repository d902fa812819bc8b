//! What topple costs on top of Rapier per step, criterion-measured in one run
//! so that the ratios compare like with like (`cargo bench --bench
//! rapier_row`):
//!
//! - `resting`: 100 Domino T blocks standing on the ground, kept awake, no
//!   impact: topple's overhead when nothing happens (the record of the awake
//!   poses and the cheap reach test of each body);
//! - `front`: the same row toppling at s/h 0.45 (ideal material), the 30
//!   steps of 1/60 s after the first second of the wave (the world is
//!   re-built and run to that instant outside the timing): the cost of half a
//!   second of a toppling front, about 15 blocks and their impacts.
//!
//! Each for native Rapier and topple, in both Rapier builds.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};

use topple::rapier::scene::{ImpactResponse, Scene};

const DT: f64 = 1.0 / 60.0;

fn row(push: f64) -> Scene {
    toml::from_str(&format!(
        "duration = 10.0\n[solver]\ndt = {DT}\n\
         [row]\npreset = \"T\"\nn = 100\nspacing = 0.45\npush = {push}\nideal = true\n"
    ))
    .unwrap()
}

macro_rules! per_build {
    ($name:ident, $build:ident) => {
        fn $name(c: &mut Criterion) {
            use topple::rapier::$build::build;
            let mut group = c.benchmark_group(concat!("rapier_row_", stringify!($build)));
            for engine in [ImpactResponse::Native, ImpactResponse::Topple] {
                // resting: a push too small to topple block 1, bodies kept awake
                let mut sw = build(&row(1e-3), engine).unwrap();
                for (_, h, _) in &sw.bodies {
                    sw.world.bodies[*h]
                        .activation_mut()
                        .normalized_linear_threshold = -1.0;
                    sw.world.bodies[*h].activation_mut().angular_threshold = -1.0;
                }
                for _ in 0..30 {
                    sw.step();
                }
                group.bench_function(format!("resting/{}", engine.name()), |b| {
                    b.iter(|| sw.step().len())
                });
                // front: 1 s into the wave (about 25 blocks down)
                group.bench_function(format!("front/{}", engine.name()), |b| {
                    b.iter_batched_ref(
                        || {
                            let mut sw = build(&row(1.0), engine).unwrap();
                            for _ in 0..60 {
                                sw.step();
                            }
                            sw
                        },
                        |sw| (0..30).map(|_| sw.step().len()).sum::<usize>(),
                        BatchSize::LargeInput,
                    )
                });
            }
            group.finish();
        }
    };
}

per_build!(rapier_row_f64, f64);
per_build!(rapier_row_f32, f32);

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = rapier_row_f64, rapier_row_f32
}
criterion_main!(benches);
