#!/usr/bin/env bash
# Quick start, command 1: install the dependencies, build, and run the bundled demo scene.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh" -DIMPETUS_BUILD_TESTS=OFF
build=${IMPETUS_BUILD_DIR:-$root/build}
"$build/bin/impetus" plugins
"$build/bin/impetus" run --duration 3 "$@"
