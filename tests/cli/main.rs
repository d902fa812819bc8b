//! The `topple` command: reports, files, bad input, determinism.
//!
//! One test binary per layer (so each links the crate once); each file below
//! was a test binary of its own and keeps its tests and tolerances.

mod bad_input;
mod bench;
mod chain_engines;
mod chain_theory;
mod determinism;
mod impact;
mod malformed_input;
mod paper_files;
mod paper_resume;
mod snapshots;
mod theory;
