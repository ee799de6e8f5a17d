#!/usr/bin/env bash
# Quick start, command 2: install the dependencies, build everything, and run the whole test suite.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh" -DIMPETUS_BUILD_TESTS=ON -DIMPETUS_BUILD_BENCHMARKS=ON  # benchmarks are built so they keep compiling
build=${IMPETUS_BUILD_DIR:-$root/build}
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" "$@"
