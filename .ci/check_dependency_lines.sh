#!/usr/bin/env bash
# The crate packages and the packaged sources build: `cargo package` with its
# verify step, which unpacks the .crate and builds it, here without default
# features (the library alone: serde, serde_json, thiserror; well under a
# minute cold). The verify step builds in the `dev` profile, which nothing
# else in CI uses, so verifying the default features (both Rapier builds,
# clap, plotters) would compile them all a second time, minutes on two cores;
# docs/ci.md has the figures and the command. Cargo.toml's metadata is
# complete (cargo package warns otherwise). Then the dependency lines
# README.md and docs/bevy.md give users resolve against that package: a
# stand-in project with each line (the registry version replaced by the
# unpacked .crate's path) runs `cargo tree`. The Bevy line must pull in one
# Rapier build (rapier2d, not rapier2d-f64) and no command-line crate.
# Resolving uses the registry index already fetched (`--offline`).
# `--no-verify`: skip the verify step (.ci/lib_alone.sh builds and tests the
# unpacked .crate instead, which compiles the same sources).
set -euo pipefail
verify=(); [ "${1:-}" = "--no-verify" ] && verify=(--no-verify)
cd "$(dirname "$0")/.."
TARGET_DIR=${TARGET_DIR:-$(.ci/target_dir.sh)}

version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)
cargo package --locked --no-default-features --allow-dirty --quiet "${verify[@]}"
crate="$TARGET_DIR/package/topple-$version.crate"
[ -s "$crate" ] || { echo "no $crate after cargo package"; exit 1; }
size=$(stat -c %s "$crate")
echo "packaged $crate: $((size / 1024)) KiB"
[ "$size" -lt $((5 * 1024 * 1024)) ] || { echo "the package is over 5 MiB: check Cargo.toml's exclude list"; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tar xzf "$crate" -C "$work"
mkdir -p "$work/user/src"
echo 'fn main() {}' > "$work/user/src/main.rs"

for doc in README.md docs/bevy.md; do
    line=$(grep -m1 '^topple = {' "$doc") || { echo "$doc: no 'topple = { ... }' line"; exit 1; }
    dep=$(echo "$line" | sed "s|version = \"[0-9.]*\"|path = \"$work/topple-$version\"|")
    [ "$dep" != "$line" ] || { echo "$doc: the line names no version: $line"; exit 1; }
    printf '[package]\nname = "user"\nversion = "0.0.0"\nedition = "2021"\n\n[dependencies]\n%s\n' \
        "$dep" > "$work/user/Cargo.toml"
    rm -f "$work/user/Cargo.lock"
    tree=$(CARGO_TARGET_DIR="$work/target" cargo tree --quiet --offline --manifest-path "$work/user/Cargo.toml" \
        -e normal --prefix none)
    echo "$doc: $line"
    echo "$tree" | grep -E '^(rapier2d|rapier2d-f64|bevy|clap) ' | sed "s/ (\*)//" | sort -u | sed "s/^/    /"
    if [[ "$line" == *'"bevy"'* ]]; then
        echo "$tree" | grep -q '^rapier2d ' || { echo "$doc: no rapier2d under the Bevy line"; exit 1; }
        ! echo "$tree" | grep -q '^rapier2d-f64 ' || { echo "$doc: the Bevy line compiles rapier2d-f64 too"; exit 1; }
    fi
    ! echo "$tree" | grep -q '^clap ' || { echo "$doc: a library line compiles clap"; exit 1; }
done
