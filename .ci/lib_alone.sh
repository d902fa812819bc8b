#!/usr/bin/env bash
# The checks of the library built without default features, in a target
# directory of their own (argument 1, else lib-alone/ in cargo's target dir):
# `cargo package` and the dependency lines of README.md and docs/bevy.md;
# the packaged sources built and their unit tests run without default
# features; clippy on the library alone with each feature set that picks
# code. They share no compiled unit with the tests' build (other features
# of serde, clap, glam, nalgebra …, check builds, the dev profile), so
# .ci/run starts them at the lowest CPU priority (`nice -n 19`) beside its
# own stages: they take the cores when the build, the tests' run and the
# Bevy stage leave one idle. Runs alone as well: `.ci/lib_alone.sh [target
# dir]`.
set -euo pipefail
cd "$(dirname "$0")/.."
# .ci/run starts this script in a session of its own (setsid, so that it can
# stop the whole lane at once). Where the kernel groups each session's
# processes for scheduling (autogroup, /proc/sys/kernel/sched_autogroup_enabled),
# nice ranks processes only inside their group and the lane's group would
# get a full half of the CPU against the main run's: the group's own weight
# goes to the lowest too (measured: the lane took a whole core for the first
# 199 s of a cold run and the tests' build took 596–640 s instead of 518 s).
if [[ -w /proc/self/autogroup ]]; then echo 19 > /proc/self/autogroup 2>/dev/null || true; fi
STAGE_PREFIX="[lib-alone] "
source .ci/stage.sh

TARGET_DIR=${1:-$(.ci/target_dir.sh)/lib-alone}
export TARGET_DIR CARGO_TARGET_DIR="$TARGET_DIR"
# plain rustc and cargo clippy here: the wrapper of .ci/run is for the
# tests' build
unset RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS
# The dev profile's builds below without debug information and without
# incremental compilation: neither changes the code nor its checks (debug
# assertions and overflow checks stay on), both cost CPU in a cold build
# that is thrown away (docs/ci.md).
export CARGO_PROFILE_DEV_DEBUG=0 CARGO_INCREMENTAL=0

stage "cargo package (without default features); the dependency lines of README.md and docs/bevy.md resolve"
# `--no-verify`: the packaged sources are built and tested below, which is
# what cargo's verify step would build (the library, dev profile) and more
.ci/check_dependency_lines.sh --no-verify
version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)
unpacked=$(mktemp -d)
trap 'rm -rf "$unpacked"; rm -f "$stage_cpu_file"' EXIT
tar xzf "$TARGET_DIR/package/topple-$version.crate" -C "$unpacked"

# The unit tests pass without Rapier and rayon (runs refused with
# SceneError::NotBuilt, the sweeps in turn), built from the packaged .crate
# (so the package is known to build: cargo package's verify step). In the
# dev profile (debug assertions and overflow checks on): this feature set's
# serde, clap, criterion and proptest differ in features from the full
# build's, so they are compiled again either way, and unoptimised that
# takes two thirds of the CPU (docs/ci.md).
stage "the packaged crate builds; its unit tests without default features (cargo test --profile dev --lib)"
cargo test --locked --profile dev --lib --no-default-features \
    --manifest-path "$unpacked/topple-$version/Cargo.toml"

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
stage "done"
