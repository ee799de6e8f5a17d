#!/usr/bin/env bash
# Draws docs/images/viewer.png, the README's picture of the viewer page: the bundled demo's run, opened in
# headless Chromium at a fixed time and camera (the page's #time, #camera and #contacts options). Needs a
# build (scripts/build.sh) and Chromium (scripts/setup.sh installs it).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${IMPETUS_BUILD_DIR:-$root/build}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$build/bin/impetus" run --duration 3 --every 10 --out "$work/demo.html" > /dev/null
mkdir -p "$root/docs/images"
timeout 120 chromium --headless --no-sandbox --disable-gpu --enable-unsafe-swiftshader --disable-quic \
  --no-first-run --disable-background-networking --disable-component-update --disable-sync --hide-scrollbars \
  --host-resolver-rules='MAP * ~NOTFOUND' --user-data-dir="$work/profile" --window-size=1200,700 \
  --virtual-time-budget=10000 --screenshot="$root/docs/images/viewer.png" \
  "file://$work/demo.html#time=0.6&contacts&camera=0.5,-6.5,3.2,0.6,0,1.2" 2>/dev/null
echo "wrote $root/docs/images/viewer.png"
