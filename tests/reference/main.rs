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
