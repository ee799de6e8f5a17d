#!/usr/bin/env bash
# Runs the benchmark suites and regenerates docs/benchmarks.md, docs/stability.md and docs/charts/.
#   bash scripts/bench.sh           full run (all scenes, 5 repetitions; tens of minutes on 2 cores)
#   bash scripts/bench.sh --quick   scenes up to 210 bodies, 3 repetitions, the accuracy suite's quick grid
# The JSON outputs go to docs/data/ (committed with the tables, so the figures can be checked).
# Assumes scripts/setup.sh has run (apt packages); builds into build/ (or $IMPETUS_BUILD_DIR).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${IMPETUS_BUILD_DIR:-$root/build}
quick=0
# Debian's python3 (with python3-matplotlib from setup.sh), even where another python3 comes first in PATH.
py=/usr/bin/python3
[ -x "$py" ] || py=python3
[ "${1:-}" = "--quick" ] && quick=1

"$root/scripts/build.sh" -DIMPETUS_BUILD_BENCHMARKS=ON >/dev/null
data="$root/docs/data"
mkdir -p "$data"
reps=${IMPETUS_BENCH_REPETITIONS:-5}
if [ $quick = 1 ]; then
  reps=3
  export IMPETUS_BENCH_MAX_BODIES=210
fi
run() {  # run NAME [extra args]: bench_NAME → docs/data/NAME.json
  local name=$1; shift
  echo "== bench_$name"
  "$build/bin/bench_$name" --benchmark_repetitions=$reps --benchmark_report_aggregates_only=true \
    --benchmark_min_time=0.1 --benchmark_format=console --benchmark_out_format=json \
    --benchmark_out="$data/$name.json" --benchmark_context=impetus_build_type=RelWithDebInfo "$@"
}
run resolve
run step
run detect
run model
if [ -x "$build/bin/bench_peers" ]; then
  run peers
  mkdir -p "$root/docs/charts"
  "$py" "$root/benchmarks/peers/report.py" "$data/peers.json" --chart "$root/docs/charts/peers.png" > "$root/docs/peers.md"
else rm -f "$data/peers.json"; echo "== bench_peers not built (no Bullet/ODE/MuJoCo): skipped"; fi
"$py" "$root/scripts/bench_report.py" "$data" "$root/docs"

if [ -x "$build/bin/bench_accuracy" ]; then
  echo "== bench_accuracy"
  accuracy_args=()
  [ $quick = 1 ] && accuracy_args+=(--quick)
  "$build/bin/bench_accuracy" "${accuracy_args[@]}" --out "$data/accuracy.json"
  # The same scenarios in Bullet, ODE and MuJoCo (built only when one is installed); accuracy.py merges
  # accuracy_peers.json found beside accuracy.json.
  if [ -x "$build/bin/bench_accuracy_peers" ]; then
    echo "== bench_accuracy_peers"
    "$build/bin/bench_accuracy_peers" "${accuracy_args[@]}" --out "$data/accuracy_peers.json"
  else rm -f "$data/accuracy_peers.json"; fi
  "$py" "$root/scripts/accuracy.py" "$data/accuracy.json" "$root/docs"
fi
