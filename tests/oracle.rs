//! Checks the test oracle itself against published values.
mod common;
