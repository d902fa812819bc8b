//! The stress sweep (`topple stress`): seeded combinations of engine,
//! preset, s/h, μ1, μ2, e1, e2, push, time step, row length and small
//! perturbations of the blocks, each run checked against bookkeeping of its
//! own: finite states, no impact creating energy, energy and momentum kept in
//! elastic frictionless impacts, no penetration beyond tolerance, no fallen
//! block standing up again, every run within its budget.
//!
//! | item | file | role |
//! | --- | --- | --- |
//! | [`SplitMix64`], [`Combo`], [`draw`] | `combo.rs` | the seeded draw of one combination |
//! | [`Observation`], [`RowWatch`] | `observe.rs` | what a run shows, measured from the block states |
//! | [`run_combo`] | `engines.rs` | one combination through its engine, observed step by step |
//! | [`sweep`], [`table`], [`tolerance`] | `sweep.rs` | many combinations in parallel; the violations and the table |
//!
//! Impacts are checked by [`crate::impact::audit`], which recomputes every
//! accepted impact from its input and impulses.
//!
//! ```no_run
//! use topple::stress::{sweep, table, SweepSpec};
//! let spec = SweepSpec::quick(1);
//! let r = sweep(&spec, None, |_, _| {});
//! println!("{}", table(&spec, &r));
//! assert_eq!(r.counted().count(), 0);
//! ```

mod combo;
mod engines;
mod observe;
pub mod scene;
pub mod soak;
mod sweep;

pub use combo::{draw, reproduce, Combo, SplitMix64, StressEngine};
pub use engines::run_combo;
pub use observe::{
    NativeRockBack, Observation, RowWatch, FALLEN_TILT, LYING_GAP, LYING_TIME, ROW_NEARBY_PUSH,
};
pub use sweep::{
    combos_of, sweep, table, tolerance, violations, Kind, SweepResult, SweepSpec, Violation,
};
