//! The reference engine (the paper's model) and the theory models, against independent solutions and the published values of the test oracle (tests/common).
//!
//! One test binary per layer (so each links the crate once); each file below
//! was a test binary of its own and keeps its tests and tolerances.

#[path = "../common/mod.rs"]
mod common;
mod contacts;
mod ground;
mod smooth;
mod theory;
mod trends;
mod wave;

use topple::domino::RowSpec;
use topple::reference::{run, Settings};

/// The natural speeds v̂_na of `row` run with settings `a` and with `b`,
/// and the impact fallbacks of both runs together.
fn natural_speeds(row: &RowSpec, a: &Settings, b: &Settings) -> (f64, f64, usize) {
    let ra = run(row, a).unwrap().report;
    let rb = run(row, b).unwrap().report;
    (
        ra.natural_speed.unwrap(),
        rb.natural_speed.unwrap(),
        ra.impact_fallbacks + rb.impact_fallbacks,
    )
}
