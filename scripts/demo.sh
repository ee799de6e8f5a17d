#!/usr/bin/env bash
# Quick start, command 1: install the dependencies, build, run the bundled demo scene, and write its run as
# a glTF file and a viewer page (build/demo/demo.glb, build/demo/demo.html) to open in a browser.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh" -DIMPETUS_BUILD_TESTS=OFF
build=${IMPETUS_BUILD_DIR:-$root/build}
mkdir -p "$build/demo"
"$build/bin/impetus" plugins
"$build/bin/impetus" run --duration 3 --every 10 --out "$build/demo/demo.glb" --overwrite "$@"
"$build/bin/impetus" view "$build/demo/demo.glb" --out "$build/demo/demo.html" --overwrite
