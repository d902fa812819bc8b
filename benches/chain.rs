//! Run time of the reference engine on short rows (criterion). The
//! work-precision and 100/1,000/10,000-block tables of the issue are not
//! produced by this bench yet.

use criterion::{criterion_group, criterion_main, Criterion};
use topple::domino::{Preset, RowSpec};
use topple::reference::{run, Settings};

fn bench(c: &mut Criterion) {
    let p = Preset::X.params().ideal();
    let row = RowSpec::new(p, 0.52 * p.block.height, 20, 1.0);
    let mut g = c.benchmark_group("chain_x_ideal_0.52_20_blocks");
    g.sample_size(10);
    g.bench_function("paper", |b| {
        b.iter(|| run(&row, &Settings::default()).unwrap())
    });
    g.bench_function("accurate_1e-8", |b| {
        b.iter(|| run(&row, &Settings::accurate(1e-8)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
