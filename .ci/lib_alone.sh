#!/usr/bin/env bash
# The checks of the library built without default features, in a target
# directory of their own (argument 1, else lib-alone/ in cargo's target dir):
# `cargo package` and the dependency lines of README.md and docs/bevy.md;
# then, for each feature set that picks code (none, `f32` alone, `f64`
# alone), the packaged sources built, linted by clippy and their unit tests
# run. They share no compiled unit with the tests' build (other features of
# serde, clap, glam, nalgebra …, the dev profile), so .ci/run starts
# them at the lowest CPU priority (`nice -n 19`, SCHED_IDLE) beside its own
# stages: they take a core only when the build, the tests' run and the Bevy
# stage leave one idle. Runs alone as well: `.ci/lib_alone.sh [target
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
# Only when this script leads its session (started by setsid, as .ci/run
# does): run alone from a terminal, the group would be the terminal's
# session, which would stay at the lowest weight after the script.
stat=$(< /proc/$$/stat); read -r -a fields <<< "${stat##*) }"
if [[ "${fields[3]}" == "$$" && -w /proc/self/autogroup ]]; then
    echo 19 > /proc/self/autogroup 2>/dev/null || true
fi
STAGE_PREFIX="[lib-alone] "
source .ci/stage.sh

TARGET_DIR=${1:-$(.ci/target_dir.sh)/lib-alone}
export TARGET_DIR CARGO_TARGET_DIR="$TARGET_DIR"
# not the wrapper of .ci/run (it is for the tests' build): clippy-driver
# alone below
unset RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS
# The dev profile's builds below without debug information and without
# incremental compilation: neither changes the code nor its checks (debug
# assertions and overflow checks stay on), both cost CPU in a cold build
# that is thrown away (docs/ci.md).
export CARGO_PROFILE_DEV_DEBUG=0 CARGO_INCREMENTAL=0
# No unit test uses proptest or criterion: this cfg leaves them out of the
# dev-dependencies (Cargo.toml), and with them clap, regex and rand.
export RUSTFLAGS="${RUSTFLAGS:+$RUSTFLAGS }--cfg topple_lib_alone"

stage "cargo package (without default features); the dependency lines of README.md and docs/bevy.md resolve"
# `--no-verify`: the packaged sources are built and tested below, which is
# what cargo's verify step would build (the library, dev profile) and more
.ci/check_dependency_lines.sh --no-verify
version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)
unpacked=$(mktemp -d)
trap 'rm -rf "$unpacked"; rm -f "$stage_cpu_file"' EXIT
tar xzf "$TARGET_DIR/package/topple-$version.crate" -C "$unpacked"

# Each feature set that picks code, alone: the packaged sources (so the
# package is known to build: cargo package's verify step) built in the dev
# profile (debug assertions and overflow checks on), the library's unit
# tests run, and clippy -D warnings on everything that build compiles: the
# library itself (what `cargo clippy --lib` lints), its unit tests and
# tests/module_graph.rs (a test target that needs the library itself, so
# cargo builds and lints it). Clippy lints while it compiles, as in
# .ci/run: clippy-driver is the wrapper of the package's rustc calls, and
# there is no check build of the dependencies beside their build. The three
# sets share every
# dependency but the Rapier builds (cargo hack is not installed here: an
# explicit list; `cli`, `plots`, `scene-files` are covered by the tests'
# build):
# - none: no Rapier and no rayon (runs refused with SceneError::NotBuilt,
#   the sweeps in turn);
# - `f32` alone (rapier2d), and `f64` alone (rapier2d-f64).
# A Bevy game's set, `bevy` alone, differs from the tests' build only in the
# `f64` and `parallel` code, which the `f32` set checks; that src/bevy/ uses
# neither is checked by tests/module_graph.rs (a `bevy` alone set here would
# build Bevy's ~300 crates a second time). (`parallel` alone is left out: its
# rayon code is linted by the tests' build and the stand-in without it by
# the other sets.)
CLIPPY_DRIVER=$(rustup which clippy-driver 2>/dev/null || command -v clippy-driver) \
    || { echo "clippy-driver is missing: rustup component add clippy"; exit 1; }
# tests/module_graph.rs is built, not run: the tests' run runs it on the
# repository's sources, and its binary names the directory it was built
# from (CARGO_MANIFEST_DIR), which is a new temporary one each run while
# cargo, which hashes a path package without its path, may reuse the binary.
for set in "" "f32" "f64"; do
    stage "features '$set' alone: the packaged crate builds, linted (clippy -D warnings); its unit tests (cargo test --profile dev --lib)"
    args=(--locked --profile dev --no-default-features --features "$set"
          --manifest-path "$unpacked/topple-$version/Cargo.toml")
    RUSTC_WORKSPACE_WRAPPER="$CLIPPY_DRIVER" CLIPPY_ARGS="-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__" \
        cargo test "${args[@]}" --lib --test module_graph --no-run
    RUSTC_WORKSPACE_WRAPPER="$CLIPPY_DRIVER" CLIPPY_ARGS="-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__" \
        cargo test "${args[@]}" --lib
done
stage "done"
