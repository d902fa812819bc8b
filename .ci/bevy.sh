#!/usr/bin/env bash
# The Bevy examples in a real window under Xvfb with software Vulkan: installs
# what a fresh Debian machine lacks, builds the examples with the target dir
# and features of .ci/run, runs `dominoes --screenshot` and checks the image
# against the rows' state the example wrote beside it.
set -euo pipefail
cd "$(dirname "$0")/.."

need=(xvfb xauth mesa-vulkan-drivers libvulkan1 libx11-xcb1 libxcursor1 libxi6
      libxkbcommon-x11-0 libxrandr2 libwayland-client0)
missing=()
for p in "${need[@]}"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi

cargo build --locked --release --features bevy --examples
# where cargo put them (CARGO_TARGET_DIR honoured); .ci/run exports it
TARGET_DIR=${TARGET_DIR:-$(.ci/target_dir.sh)}
ex="$TARGET_DIR/release/examples"

out=$(mktemp -d)
export XDG_RUNTIME_DIR="$out"
icd=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
[ -f "$icd" ] && export VK_ICD_FILENAMES="$icd"

echo "headless_row (topple and native, ideal Domino T, s/h 0.45, 1/60 s)"
"$ex"/headless_row --preset t --ideal --n 60
"$ex"/headless_row --preset t --ideal --n 60 --native

echo "dominoes --screenshot under Xvfb"
timeout 300 xvfb-run -a -s "-screen 0 1280x720x24" \
    "$ex"/dominoes --screenshot "$out/dominoes.png" --frames 50
python3 .ci/check_screenshot.py "$out/dominoes.png"

echo "cradle --screenshot under Xvfb"
timeout 300 xvfb-run -a -s "-screen 0 1280x720x24" \
    "$ex"/cradle --screenshot "$out/cradle.png" --frames 120
test -s "$out/cradle.png"

echo "domino_show --screenshot under Xvfb (6 fronts in pixel units)"
timeout 300 xvfb-run -a -s "-screen 0 1280x720x24" \
    "$ex"/domino_show --screenshot "$out/domino_show.png" --frames 120
python3 .ci/check_screenshot.py "$out/domino_show.png"

echo "pile --screenshot under Xvfb"
timeout 300 xvfb-run -a -s "-screen 0 1280x720x24" \
    "$ex"/pile --screenshot "$out/pile.png" --frames 240
test -s "$out/pile.png"
rm -rf "$out"
