#!/usr/bin/env bash
# RUSTC_WORKSPACE_WRAPPER of .ci/run: every rustc call for one of topple's
# own targets goes through clippy-driver (rustc with clippy's lints, which
# lints while it compiles; the arguments in CLIPPY_ARGS), and the targets
# below are compiled without optimisation. Cargo calls it as
# `rustc_wrapper.sh <rustc> <arguments>`.
#
# Without optimisation (`-C opt-level=0`, with debug assertions and overflow
# checks kept off as in `release`, so the code and its `cfg`s are those of
# the release build): targets CI compiles and lints but runs for seconds at
# most, or not at all. Together they were ≈ 300 s of CPU of a cold run at
# opt-level 3, a sixth of it (docs/ci.md):
# - the four windowed examples (each compiles Bevy's generic systems and
#   plugins in its own crate; CI runs them for a few hundred frames under
#   Xvfb, with Bevy's render stack at opt-level 0 already: Cargo.toml);
# - the benchmarks (CI compiles them; `cargo bench` builds them with the
#   `bench` profile and without this wrapper);
# - the harnesses of the library's and the command's unit tests (32 and 4
#   tests, 0.1 s), of tests/bevy (10 tests of Bevy apps, whose Bevy crates
#   are at opt-level 0 already), tests/cli (it runs the `topple` command,
#   which keeps opt-level 3) and tests/module_graph (reads the sources).
# The library, the `topple` command and the test binaries that run the
# long physics checks (tests/impact, tests/reference, tests/rapier) keep
# opt-level 3. Rust does not contract floating-point operations nor
# reassociate them at any optimisation level, so results are the same.
set -euo pipefail
driver=${CLIPPY_DRIVER:?"CLIPPY_DRIVER: the clippy-driver to run (.ci/run sets it)"}

src="" test=0
for arg in "$@"; do
    case $arg in
        --test) test=1 ;;
        *.rs) src=$arg ;;
    esac
done
unoptimised=0
case /$src in
    */examples/dominoes.rs | */examples/cradle.rs | */examples/domino_show.rs | */examples/pile.rs) unoptimised=1 ;;
    */benches/*.rs) unoptimised=1 ;;
    */tests/bevy/main.rs | */tests/cli/main.rs | */tests/module_graph.rs) unoptimised=1 ;;
    */src/lib.rs | */src/main.rs) [ "$test" = 1 ] && unoptimised=1 ;;
esac
if [ "$unoptimised" = 1 ]; then
    exec "$driver" "$@" -C opt-level=0 -C debug-assertions=off -C overflow-checks=off
fi
exec "$driver" "$@"
