#!/usr/bin/env bash
# Checks that the CI scripts honour where cargo builds: .ci/target_dir.sh
# follows CARGO_TARGET_DIR (set, and unset), and no CI script names
# ./target/ itself.
set -euo pipefail
cd "$(dirname "$0")/.."
fail() { echo "check_target_dir: $*" >&2; exit 1; }

elsewhere=$(mktemp -d)
got=$(CARGO_TARGET_DIR="$elsewhere" .ci/target_dir.sh)
[ "$got" = "$elsewhere" ] || fail "with CARGO_TARGET_DIR=$elsewhere it says $got"
rmdir "$elsewhere"

got=$(env -u CARGO_TARGET_DIR .ci/target_dir.sh)
[ "$got" = "$(pwd)/target" ] || grep -qs "target-dir" .cargo/config.toml \
    || fail "without CARGO_TARGET_DIR it says $got, not $(pwd)/target"

if grep -nE '(^|[^A-Za-z_$/])\.?/?target/(release|debug)' .ci/run .ci/bevy.sh; then
    fail "a CI script names ./target/ directly: use \$TARGET_DIR from .ci/target_dir.sh"
fi
echo "check_target_dir: ok (CARGO_TARGET_DIR honoured, no ./target/ in .ci/run or .ci/bevy.sh)"
