#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang + AddressSanitizer + UBSan) into build-fuzz/ (or
# $IMPETUS_FUZZ_BUILD_DIR) and runs each for a bounded time, $(nproc) at a time. Every run starts from
# the seed corpus (fuzz/corpus/<target>) and the kept crash inputs (fuzz/regressions/<target>); new
# inputs go to the build directory, never into the repository. Prints executions and crashes per target
# and fails if any target crashed; a crash input is left in <build>/fuzz-artifacts/<target>/ (reproduce
# with `<build>/bin/fuzz_<target> FILE`; once fixed, keep it in fuzz/regressions/<target>/).
#
#   scripts/fuzz.sh [--time SECONDS] [--seed N] [TARGET...]   # default: 60 s each, every target
#   targets: scene mesh_obj mesh_stl mesh_ply mesh_off mesh_gltf mesh_glb mesh_dae
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${IMPETUS_FUZZ_BUILD_DIR:-$root/build-fuzz}
seconds=60
seed=1
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --time) seconds=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(scene set mesh_obj mesh_stl mesh_ply mesh_off mesh_gltf mesh_glb mesh_dae)

werror=OFF
[ "${CI:-}" = "true" ] && werror=ON
start=$(date +%s)
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DIMPETUS_BUILD_FUZZERS=ON -DIMPETUS_BUILD_TESTS=OFF -DIMPETUS_BUILD_BENCHMARKS=OFF -DIMPETUS_WERROR=$werror >/dev/null
cmake --build "$build" -j "$(nproc)" --target impetus_fuzzers
echo "fuzz: build took $(( $(date +%s) - start )) s"

# A report stops the run (halt_on_error), and leaks count (detect_leaks).
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
# Known leaks inside libassimp (fuzz/lsan.supp says which and why).
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/fuzz/lsan.supp}
# The mesh targets import through the importer process, as a program does (assets/README.md). Its limits
# stay below libFuzzer's -timeout (30 s), so an input that makes assimp loop is the importer's clear error,
# not a fuzzer timeout; its memory is its own, outside -rss_limit_mb.
export IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS=${IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS:-10}
export IMPETUS_MESH_IMPORT_CPU_SECONDS=${IMPETUS_MESH_IMPORT_CPU_SECONDS:-5}

run_one() {
  local target=$1 build=$2 root=$3 seconds=$4 seed=$5
  local work="$build/fuzz-work/$target" artifacts="$build/fuzz-artifacts/$target/"
  local dict="$root/fuzz/$target.dict"
  case "$target" in mesh_glb) dict="$root/fuzz/mesh_gltf.dict" ;; esac
  rm -rf "$artifacts"
  mkdir -p "$work" "$artifacts"
  local args=(-max_total_time="$seconds" -seed="$seed" -timeout=30 -rss_limit_mb=2048 -print_final_stats=1
              -artifact_prefix="$artifacts")
  [ -f "$dict" ] && args+=(-dict="$dict")
  local log="$build/fuzz-work/$target.log" status=0
  local inputs=("$work" "$root/fuzz/corpus/$target")
  [ -d "$root/fuzz/regressions/$target" ] && inputs+=("$root/fuzz/regressions/$target")  # git keeps no empty ones
  "$build/bin/fuzz_$target" "${args[@]}" "${inputs[@]}" >"$log" 2>&1 || status=$?
  local runs crashes slow
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  # libFuzzer also writes slow-unit-* files (inputs that took long but passed): reported, not failures.
  slow=$(find "$artifacts" -type f -name 'slow-unit-*' | wc -l)
  crashes=$(find "$artifacts" -type f ! -name 'slow-unit-*' | wc -l)
  printf 'fuzz: %-10s %10s executions in %s s, %s crash inputs, %s slow inputs, exit %s\n' \
    "$target" "${runs:-?}" "$seconds" "$crashes" "$slow" "$status"
  if [ "$status" -ne 0 ]; then
    echo "fuzz: $target failed; the end of $log:"
    tail -40 "$log"
    return 1
  fi
}
export -f run_one
start=$(date +%s)
printf '%s\n' "${targets[@]}" | xargs -P "$(nproc)" -I{} bash -c 'run_one "$@"' _ {} "$build" "$root" "$seconds" "$seed"
echo "fuzz: ${#targets[@]} targets in $(( $(date +%s) - start )) s"
