#!/usr/bin/env bash
# Configures and builds Impetus into build/ (or $IMPETUS_BUILD_DIR). Extra arguments go to cmake.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${IMPETUS_BUILD_DIR:-$root/build}
werror=OFF
[ "${CI:-}" = "true" ] && werror=ON
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DIMPETUS_WERROR=$werror "$@"
cmake --build "$build" -j "$(nproc)"
