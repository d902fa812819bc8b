//! The Rapier plugin in both builds, the scenes and the stress sweep's checks, against closed forms, conservation laws and the reference engine.
//!
//! One test binary per layer (so each links the crate once); each file below
//! was a test binary of its own and keeps its tests and tolerances.

mod budget;
mod cadence;
mod costs;
mod cradle;
mod determinism;
mod dominoes;
mod drop;
mod fallen_baseline;
mod game_rate;
mod parallel;
mod rebound;
mod shapes;
mod sleeping;
mod soak;
mod soft_contact;
mod stack;
mod stress_checks;
mod substeps;
mod vs_reference;
mod warm_start;
