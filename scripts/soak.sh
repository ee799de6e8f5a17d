#!/usr/bin/env bash
# The long-run soak (not part of scripts/test.sh): builds impetus_soak (tests/reliability/soak.cpp) into
# build/ (or $IMPETUS_BUILD_DIR) and runs a resting pyramid of 55 spheres between walls and a 10-box
# stack for 10^6 steps each, checking for NaN, energy growth, memory growth and penetration. Extra
# arguments go to impetus_soak: --steps N, --every K, --case pyramid|stack|all, --resolver NAME.
# Takes about four minutes on one core after the build (209 µs and 16 µs per step, 2026-11-22).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${IMPETUS_BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DIMPETUS_BUILD_TESTS=ON >/dev/null
cmake --build "$build" -j "$(nproc)" --target impetus_soak impetus_integrator_momentum impetus_detector_fcl \
  impetus_resolver_ledas impetus_resolver_mirtich
"$build/bin/impetus_soak" "$@"
