#!/usr/bin/env bash
# Quick start, command 2: install the dependencies, build everything, and run the whole test suite —
# three times over:
#   1. as built (build/, or $IMPETUS_BUILD_DIR);
#   2. again under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/, IMPETUS_SANITIZE=ON, -O1 -g1):
#      any report fails the run (halt_on_error, leaks included);
#   3. a bounded fuzz run: every libFuzzer target for $IMPETUS_FUZZ_SECONDS (default 30) seconds from its
#      seed corpus and kept regressions (scripts/fuzz.sh; clang, build-fuzz/ or $IMPETUS_FUZZ_BUILD_DIR).
# Extra arguments go to ctest in both test passes (e.g. -R Cli). IMPETUS_SANITIZE_TESTS=0 skips pass 2,
# IMPETUS_FUZZ_SECONDS=0 skips pass 3.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh" -DIMPETUS_BUILD_TESTS=ON -DIMPETUS_BUILD_BENCHMARKS=ON  # benchmarks are built so they keep compiling
build=${IMPETUS_BUILD_DIR:-$root/build}
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" "$@"

if [ "${IMPETUS_SANITIZE_TESTS:-1}" != "0" ]; then
  start=$(date +%s)
  asan=${IMPETUS_ASAN_BUILD_DIR:-$root/build-asan}
  IMPETUS_BUILD_DIR=$asan "$root/scripts/build.sh" -DIMPETUS_SANITIZE=ON -DIMPETUS_BUILD_TESTS=ON \
    -DIMPETUS_BUILD_BENCHMARKS=OFF
  built=$(date +%s)
  # A report of either sanitizer stops the process with a non-zero status, so the test fails. The
  # embedding example is left out: it is an outside project built without the sanitizer, which cannot
  # load a sanitized libimpetus_engine.so ("ASan runtime does not come first").
  ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:check_initialization_order=1 \
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 LSAN_OPTIONS=suppressions=$root/fuzz/lsan.supp \
    ctest --test-dir "$asan" --output-on-failure -j "$(nproc)" -E "^example_embed_installed$" "$@"
  echo "test.sh: sanitizer pass: build $(( built - start )) s, tests $(( $(date +%s) - built )) s"
fi

if [ "${IMPETUS_FUZZ_SECONDS:-30}" != "0" ]; then
  # Every target, the mesh formats included: assimp runs in its own process (assets/README.md), so an
  # input that crashes assimp is a clear error, not a crash of the fuzzer. 9 targets, $(nproc) at a time.
  "$root/scripts/fuzz.sh" --time "${IMPETUS_FUZZ_SECONDS:-30}"
fi
