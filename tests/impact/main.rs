//! The LZB resolver alone: closed forms, the compliant model integrated in time, properties of random impacts.
//!
//! One test binary per layer (so each links the crate once); each file below
//! was a test binary of its own and keeps its tests and tolerances.

mod alloc;
#[path = "../common/mod.rs"]
mod common;
mod friction;
mod group;
mod hertz;
mod properties;
mod rest;
mod single;
