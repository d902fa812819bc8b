//! Domino X with Table 1's parameters: the natural speed of the row
//! run through Rapier with topple's impacts against the paper's model (the
//! reference engine), which shares only the resolver and the presets with it.
//! Native Rapier's result is printed for the record.

use topple::domino::{Preset, RowSpec};
use topple::rapier::scene::run_row;
use topple::rapier::scene::{ImpactResponse, SolverSpec, WorkBudget};
use topple::rapier::Precision;
use topple::reference::{Integrator, Settings};

/// s/h 0.35 on 30 blocks and s/h 0.18 on 60 (its wave needs about 20 blocks
/// to settle, and the blocks ahead of it fall asleep in Rapier after 0.5 s,
/// from block 30 on: the longer row also covers sleeping blocks being struck).
/// One test per row, so that libtest runs them on both cores.
mod domino_x_table1_natural_speed_within_5_percent_of_the_reference_engine {
    #[test]
    fn sh_0_35_30_blocks() {
        super::compare(0.35, 30);
    }
    #[test]
    fn sh_0_18_60_blocks() {
        super::compare(0.18, 60);
    }
}

fn compare(spacing_ratio: f64, n: usize) {
    let p = Preset::X.params();
    let row = RowSpec::new(p, spacing_ratio * p.block.height, n, 1.0);
    let reference = topple::reference::run(
        &row,
        &Settings {
            integrator: Integrator::Paper { dt: 2e-4 },
            ..Settings::default()
        },
    )
    .unwrap();
    let expected = reference.report.natural_speed.unwrap();
    let solver = SolverSpec {
        dt: 2e-4,
        max_group_hops: Some(8),
        // an accuracy run against the reference: every impact to its end
        max_work: WorkBudget::Unbounded,
        ..SolverSpec::default()
    };
    let topple = run_row(
        &row,
        ImpactResponse::Topple,
        Precision::F64,
        solver.clone(),
        20.0,
        |_| {},
    )
    .unwrap();
    let native = run_row(
        &row,
        ImpactResponse::Native,
        Precision::F64,
        solver,
        20.0,
        |_| {},
    )
    .unwrap();
    let got = topple.natural_speed.unwrap();
    eprintln!(
        "Domino X, Table 1, s/h {spacing_ratio}, {n} blocks: reference {expected:.4}, topple {got:.4} ({:+.1}%), native Rapier {:?}",
        100.0 * (got / expected - 1.0),
        native.natural_speed
    );
    assert!(
        (got / expected - 1.0).abs() < 0.05,
        "topple {got} vs reference {expected}"
    );
}
