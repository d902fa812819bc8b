#!/usr/bin/env bash
# Prints the directory cargo builds into for this workspace, as cargo itself
# resolves it (CARGO_TARGET_DIR, build.target-dir in a config file, or
# ./target), so the CI scripts find the binaries wherever cargo puts them.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo metadata --format-version 1 --no-deps --offline 2>/dev/null \
    | python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])'
