#!/usr/bin/env bash
# The checks of the library built without default features, in a target
# directory of their own (argument 1, else lib-alone/ in cargo's target dir):
# `cargo package` verified and the dependency lines of README.md and
# docs/bevy.md; clippy on the library alone with each feature set that
# picks code; the unit tests without default features. They share no
# compiled unit with the tests' build (other features of serde, clap, glam,
# nalgebra …, check builds, the dev profile), so .ci/run starts them beside
# the tests' run, the stress sweep and the Bevy stage, which leave part of
# the two cores idle. Runs alone as well: `.ci/lib_alone.sh [target dir]`.
set -euo pipefail
cd "$(dirname "$0")/.."
STAGE_PREFIX="[lib-alone] "
source .ci/stage.sh

TARGET_DIR=${1:-$(.ci/target_dir.sh)/lib-alone}
export TARGET_DIR CARGO_TARGET_DIR="$TARGET_DIR"
# plain rustc and cargo clippy here: the wrapper of .ci/run is for the
# tests' build
unset RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS

stage "cargo package (verified without default features); the dependency lines of README.md and docs/bevy.md resolve"
.ci/check_dependency_lines.sh

# Each feature that picks code builds and lints alone (cargo hack is not
# installed here: an explicit list; `cli`, `plots`, `scene-files` are covered
# by the tests' build). A Bevy game's set, `bevy` alone, differs from the
# tests' build only in the `f64` and `parallel` code, which the `f32` set
# checks; that src/bevy/ uses neither is checked by tests/module_graph.rs (a
# `bevy` alone set here would check Bevy's ~300 crates a second time).
# (`parallel` alone is left out: its rayon code is linted by the tests'
# build and the stand-in without it by the empty set.)
for set in "" "f32" "f64"; do
    stage "cargo clippy --lib --no-default-features --features '$set'"
    cargo clippy --locked --release --lib --no-default-features --features "$set" -- -D warnings
done
# ...and the unit tests pass without Rapier and rayon (runs refused with
# SceneError::NotBuilt, the sweeps in turn). In the dev profile (debug
# assertions and overflow checks on): this feature set's serde, clap,
# criterion and proptest differ in features from the full build's, so they
# are compiled again either way, and unoptimised that takes two thirds of
# the CPU (docs/ci.md).
stage "cargo test --profile dev --lib --no-default-features"
cargo test --locked --profile dev --lib --no-default-features
stage "done"
