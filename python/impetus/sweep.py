"""Sweeps: every combination a grid file names, one run per task, on Dask distributed (README.md, "Sweeps").

    python3 -m impetus.sweep GRID.yaml --out results.json [--scheduler tcp://HOST:8786] [--workers N]
                             [--serial] [--overwrite] [--timeout S]
    python3 -m impetus.sweep --accuracy [--quick] [--filter TEXT]... [--bench PATH] --out accuracy.json [...]

Without --scheduler the runs go to an in-process LocalCluster with one single-threaded worker process per
core (or --workers N), on the loopback interface; with it, to a running cluster (`dask scheduler` on one
machine, `dask worker tcp://HOST:8786` on each of the others, every one with the same Impetus build and
the scenes at the same paths). --serial runs them one after another in this process, without Dask.

A grid file (YAML):

    scenes: [../assets/scenes/demo.yaml]        # paths relative to the grid file
    overrides:                                  # each key a list of values: the product over keys
      modules.resolver: [ledas, mirtich]
      dt: [0.001, 0.002]
    steps: [500]                                # or duration: [0.5, 1.0] (seconds); default steps [1000]
    repetitions: 1                              # each combination this many times
    probes:                                     # values read at the end of each run (optional)
      - {name: ball_height, body: ball, quantity: position, component: 2}
      - {name: energy, quantity: kinetic_energy}

Each result records its inputs, `ok` and `error`, the run summary (`impetus run --json`'s document), the
probes, the wall time and the worker. A run that fails is a recorded failure; a worker that dies has its
runs retried elsewhere by the scheduler, and every run appears once. The numbers are the same run serially
or on any cluster; only the timings differ (`wall_s`, and the summary's `wall_time_s`, `time_per_step_s`
and `module_time_s`).

--accuracy runs the accuracy suite (bench_accuracy, benchmarks/accuracy) one scenario per task and writes
the document `bench_accuracy --out` writes, which scripts/accuracy.py reads unchanged, so the stability
atlas can be regenerated on a cluster.
"""

import argparse
import itertools
import json
import math
import numbers
import os
import socket
import subprocess
import sys
import tempfile
import time

import impetus

GRID_KEYS = ("scenes", "overrides", "steps", "duration", "repetitions", "probes")
PROBE_KEYS = ("name", "quantity", "body", "component")
BODY_QUANTITIES = ("position", "orientation", "velocity", "angular_velocity")
WORLD_QUANTITIES = ("kinetic_energy", "potential_energy", "linear_momentum", "angular_momentum", "max_penetration",
                    "contacts", "time", "step_count")
TIMING_FIELDS = ("wall_s", "wall_time_s", "time_per_step_s", "module_time_s")


class GridError(impetus.Error):
    """A grid file that cannot be run, naming the file and the defect."""


def _list(value):
    return value if isinstance(value, list) else [value]


def load_grid(path):
    """Reads and checks a grid file; returns the runs it names (dicts with an `id`, in a fixed order)."""
    import yaml  # Debian's python3-yaml

    path = os.path.abspath(os.fspath(path))
    where = os.path.basename(path)
    try:
        with open(path, encoding="utf-8") as f:
            grid = yaml.safe_load(f)
    except OSError as e:
        raise GridError(f"{path}: cannot be read: {e.strerror}") from None
    except yaml.YAMLError as e:
        raise GridError(f"{path}: not YAML: {e}") from None
    if not isinstance(grid, dict):
        raise GridError(f"{path}: a grid is a mapping of {', '.join(GRID_KEYS)}")
    for key in grid:
        if key not in GRID_KEYS:
            raise GridError(f"{where}: unknown key '{key}'; expected one of: {', '.join(GRID_KEYS)}")
    if "scenes" not in grid or not _list(grid["scenes"]):
        raise GridError(f"{where}: 'scenes' names no scene")
    folder = os.path.dirname(path)
    scenes = [os.path.normpath(os.path.join(folder, str(s))) for s in _list(grid["scenes"])]
    overrides = grid.get("overrides") or {}
    if not isinstance(overrides, dict):
        raise GridError(f"{where}: 'overrides' is a mapping of dotted keys to lists of values")
    if "steps" in grid and "duration" in grid:
        raise GridError(f"{where}: give 'steps' or 'duration', not both")
    lengths = []
    for value in _list(grid.get("steps", [1000])) if "duration" not in grid else []:
        if not isinstance(value, numbers.Integral) or isinstance(value, bool) or value < 0:
            raise GridError(f"{where}: steps {value!r}: must be a non-negative integer")
        lengths.append({"steps": int(value)})
    for value in _list(grid.get("duration", [])):
        if not isinstance(value, numbers.Real) or isinstance(value, bool) or not math.isfinite(value) or value < 0:
            raise GridError(f"{where}: duration {value!r}: must be a non-negative number of seconds")
        lengths.append({"duration": float(value)})
    repetitions = grid.get("repetitions", 1)
    if not isinstance(repetitions, numbers.Integral) or isinstance(repetitions, bool) or repetitions < 1:
        raise GridError(f"{where}: repetitions {repetitions!r}: must be a positive integer")
    probes = _list(grid.get("probes", []))
    for probe in probes:
        _check_probe(where, probe)

    keys = list(overrides)
    runs = []
    for scene in scenes:
        for values in itertools.product(*(_list(overrides[k]) for k in keys)):
            chosen = dict(zip(keys, values))
            try:  # the scene and its overrides are checked here, before any run starts
                impetus.load_scene(scene, chosen)
            except impetus.Error as e:
                raise GridError(f"{where}: {e}") from None
            for length in lengths:
                for repetition in range(repetitions):
                    runs.append({"id": len(runs), "scene": scene, "overrides": chosen, **length,
                                 "repetition": repetition, "probes": probes})
    return runs


def _check_probe(where, probe):
    if not isinstance(probe, dict):
        raise GridError(f"{where}: a probe is a mapping of {', '.join(PROBE_KEYS)}")
    for key in probe:
        if key not in PROBE_KEYS:
            raise GridError(f"{where}: probe {probe.get('name', '?')}: unknown key '{key}'; "
                            f"expected one of: {', '.join(PROBE_KEYS)}")
    if "name" not in probe or "quantity" not in probe:
        raise GridError(f"{where}: a probe needs a 'name' and a 'quantity'")
    quantity = probe["quantity"]
    if quantity in BODY_QUANTITIES:
        if "body" not in probe:
            raise GridError(f"{where}: probe {probe['name']}: '{quantity}' needs a 'body'")
    elif quantity in WORLD_QUANTITIES:
        if "body" in probe:
            raise GridError(f"{where}: probe {probe['name']}: '{quantity}' is the world's, not a body's")
    else:
        raise GridError(f"{where}: probe {probe['name']}: unknown quantity '{quantity}'; expected one of: "
                        f"{', '.join(BODY_QUANTITIES + WORLD_QUANTITIES)}")
    if "component" in probe and probe["component"] not in (0, 1, 2, 3):
        raise GridError(f"{where}: probe {probe['name']}: component must be 0, 1, 2 (or 3 for orientation)")


def _probe(world, probe):
    quantity = probe["quantity"]
    if quantity in BODY_QUANTITIES:
        names = world.names
        if probe["body"] not in names:
            raise impetus.Error(f"probe {probe['name']}: no body named '{probe['body']}'")
        value = world.state()[quantity][names.index(probe["body"])].tolist()
    elif quantity == "time":
        value = world.time
    elif quantity == "step_count":
        value = world.step_count
    else:
        value = impetus.measure(world)[quantity]
        value = list(value) if isinstance(value, tuple) else value
    if "component" in probe:
        value = value[probe["component"]]
    return value


def _worker_name():
    try:
        from distributed import get_worker
        return get_worker().address
    except (ImportError, ValueError):
        return f"{socket.gethostname()}:{os.getpid()} (serial)"


def run_one(run):
    """One run of a sweep (a Dask task): never raises for a failing run, which is recorded as such."""
    start = time.perf_counter()
    result = {key: run[key] for key in ("id", "scene", "overrides", "repetition") if key in run}
    result.update({key: run[key] for key in ("steps", "duration") if key in run})
    try:
        scene = impetus.load_scene(run["scene"], run["overrides"])
        world = impetus.World(scene)
        steps = run["steps"] if "steps" in run else int(math.floor(run["duration"] / world.dt + 0.5))
        world.step(steps)
        result["ok"] = True
        result["error"] = None
        result["summary"] = impetus.summary(world)
        result["probes"] = {p["name"]: _probe(world, p) for p in run["probes"]}
    except Exception as e:  # noqa: BLE001 — any failure of the run is its result
        result.update(ok=False, error=f"{type(e).__name__}: {e}" if not isinstance(e, impetus.Error) else str(e),
                      summary=None, probes={})
    result["wall_s"] = time.perf_counter() - start
    result["worker"] = _worker_name()
    return result


class Progress:
    """Runs done, failed and remaining, on stderr: one updating line on a terminal, a line per tenth
    otherwise."""

    def __init__(self, total, stream=sys.stderr):
        self.total, self.done, self.failed, self.stream = total, 0, 0, stream
        self.tty = stream.isatty()
        self.last_tenth = -1

    def add(self, ok):
        self.done += 1
        self.failed += 0 if ok else 1
        text = f"runs: {self.done - self.failed} done, {self.failed} failed, {self.total - self.done} remaining"
        if self.tty:
            self.stream.write("\r" + text + ("\n" if self.done == self.total else ""))
        elif self.done * 10 // max(self.total, 1) != self.last_tenth:
            self.last_tenth = self.done * 10 // max(self.total, 1)
            self.stream.write(text + "\n")
        self.stream.flush()


def run_grid(runs, client=None, progress=None):
    """Runs every run: on `client` (a distributed.Client) or, with None, one after another here. Returns
    the results in run order, each exactly once."""
    progress = progress or Progress(len(runs), stream=open(os.devnull, "w"))
    results = {}
    task = run_accuracy_scenario if runs and "accuracy" in runs[0] else run_one
    if client is None:
        for run in runs:
            results[run["id"]] = task(run)
            progress.add(results[run["id"]]["ok"])
    else:
        from distributed import as_completed
        futures = [client.submit(task, run, key=f"impetus-run-{run['id']}-{os.getpid()}", pure=False)
                   for run in runs]
        for future in as_completed(futures):
            result = future.result()
            if result["id"] not in results:  # a retried run reports once
                results[result["id"]] = result
                progress.add(result["ok"])
    return [results[run["id"]] for run in runs]


def default_bench():
    """bench_accuracy beside this package in the build tree (build/python/impetus -> build/bin), else PATH."""
    beside = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", "..", "bin", "bench_accuracy"))
    return beside if os.path.exists(beside) else "bench_accuracy"


def accuracy_runs(bench, quick=False, filters=(), budget=None):
    """One task per scenario of the accuracy suite (`bench_accuracy --list`), those whose id contains one of
    `filters` if any are given."""
    try:
        listing = subprocess.run([bench, "--list"], capture_output=True, text=True, timeout=120, check=True).stdout
    except (OSError, subprocess.SubprocessError) as e:
        raise impetus.Error(f"--bench {bench}: cannot list the accuracy suite ({e}); build with "
                            "-DIMPETUS_BUILD_BENCHMARKS=ON or pass --bench") from None
    ids = [line.split()[0] for line in listing.splitlines() if line.strip()]
    if filters:
        ids = [i for i in ids if any(f in i for f in filters)]
        if not ids:
            raise impetus.Error(f"--filter {' '.join(filters)}: no scenario of the accuracy suite matches")
    return [{"id": n, "accuracy": scenario, "bench": os.path.abspath(bench) if os.path.exists(bench) else bench,
             "quick": quick, "budget": budget} for n, scenario in enumerate(ids)]


def run_accuracy_scenario(run):
    """One scenario of the accuracy suite (a Dask task): bench_accuracy on it alone, in a child process."""
    start = time.perf_counter()
    result = {"id": run["id"], "scenario": run["accuracy"], "ok": False, "error": None, "document": None}
    with tempfile.TemporaryDirectory(prefix="impetus_accuracy_") as folder:
        out = os.path.join(folder, "part.json")
        command = [run["bench"], "--filter", run["accuracy"], "--out", out] + (["--quick"] if run["quick"] else [])
        if run["budget"]:
            command += ["--budget", str(run["budget"])]
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=3600)
            if done.returncode != 0:
                result["error"] = f"bench_accuracy exited with {done.returncode}: {done.stderr.strip()[-2000:]}"
            else:
                with open(out, encoding="utf-8") as f:
                    document = json.load(f)
                # --filter matches by substring: keep the scenario whose id is this task's.
                document["scenarios"] = [s for s in document["scenarios"] if s["id"] == run["accuracy"]]
                result.update(ok=len(document["scenarios"]) == 1, document=document)
                if not result["ok"]:
                    result["error"] = f"bench_accuracy wrote no scenario '{run['accuracy']}'"
        except (OSError, subprocess.SubprocessError, ValueError) as e:
            result["error"] = f"{type(e).__name__}: {e}"
    result["wall_s"] = time.perf_counter() - start
    result["worker"] = _worker_name()
    return result


def merge_accuracy(results, where):
    """The parts as one `bench_accuracy --out` document (the first part's settings, the scenarios in the
    suite's order), with the failures listed."""
    parts = [r for r in results if r["ok"]]
    if not parts:
        raise impetus.Error("no scenario of the accuracy suite ran: " + "; ".join(
            f"{r['scenario']}: {r['error']}" for r in results[:3]))
    document = dict(parts[0]["document"])
    document["scenarios"] = [r["document"]["scenarios"][0] for r in parts]
    document["total_wall_s"] = sum(r["document"]["total_wall_s"] for r in parts)
    document["generated_utc"] = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    document["ran_on"] = where
    document["failed"] = [{"scenario": r["scenario"], "error": r["error"]} for r in results if not r["ok"]]
    return document


def strip_timings(value):
    """A result (or results) without its timing fields: what must be identical however the sweep ran."""
    if isinstance(value, list):
        return [strip_timings(v) for v in value]
    if isinstance(value, dict):
        return {k: strip_timings(v) for k, v in value.items() if k not in TIMING_FIELDS and k != "worker"}
    return value


def _client(scheduler, workers, timeout):
    from distributed import Client, LocalCluster
    if scheduler:
        try:
            return Client(scheduler, timeout=timeout), None
        except (OSError, TimeoutError) as e:
            raise impetus.Error(f"--scheduler {scheduler}: no answer within {timeout} s ({e})") from None
    n = workers or os.cpu_count() or 1
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address=None, silence_logs=50)
    return Client(cluster), cluster


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m impetus.sweep", description=__doc__.split("\n")[0])
    parser.add_argument("grid", nargs="?", help="the grid file (YAML)")
    parser.add_argument("--out", required=True, help="the results (JSON)")
    parser.add_argument("--accuracy", action="store_true", help="run the accuracy suite, one scenario per task")
    parser.add_argument("--quick", action="store_true", help="with --accuracy: bench_accuracy --quick")
    parser.add_argument("--filter", action="append", default=[],
                        help="with --accuracy: only scenarios whose id contains TEXT (repeatable)")
    parser.add_argument("--budget", type=float, help="with --accuracy: bench_accuracy --budget S")
    parser.add_argument("--bench", help="with --accuracy: the bench_accuracy program (default: the build's)")
    parser.add_argument("--scheduler", help="a running Dask scheduler, tcp://HOST:8786 (default: a local cluster)")
    parser.add_argument("--workers", type=int, help="worker processes of the local cluster (default: one per core)")
    parser.add_argument("--serial", action="store_true", help="run here, one run after another, without Dask")
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds to wait for --scheduler (default 10)")
    parser.add_argument("--overwrite", action="store_true", help="allow --out to replace an existing file")
    args = parser.parse_args(argv)
    try:
        if args.workers is not None and args.workers < 1:
            raise impetus.Error(f"--workers {args.workers}: must be at least 1")
        if args.serial and (args.scheduler or args.workers):
            raise impetus.Error("--serial runs without Dask: it takes neither --scheduler nor --workers")
        if bool(args.grid) == args.accuracy:
            raise impetus.Error("give a grid file or --accuracy (one of them)")
        if not args.accuracy and (args.quick or args.filter or args.budget or args.bench):
            raise impetus.Error("--quick, --filter, --budget and --bench go with --accuracy")
        grid = args.grid or args.bench or default_bench()
        out = os.path.abspath(args.out)
        if os.path.isdir(out):
            raise impetus.Error(f"--out {args.out}: is a directory")
        if os.path.exists(out) and not args.overwrite:
            raise impetus.Error(f"--out {args.out}: file exists; pass --overwrite to replace it")
        if not os.path.isdir(os.path.dirname(out)):
            raise impetus.Error(f"--out {args.out}: the folder '{os.path.dirname(out)}' does not exist")
        if os.path.exists(out) and os.path.exists(grid) and os.path.samefile(out, grid):
            raise impetus.Error(f"--out {args.out}: is the file being read")
        if args.accuracy:
            runs = accuracy_runs(args.bench or default_bench(), args.quick, args.filter, args.budget)
        else:
            runs = load_grid(args.grid)
        progress = Progress(len(runs))
        start = time.perf_counter()
        if args.serial:
            results = run_grid(runs, None, progress)
            where = "serial"
        else:
            client, cluster = _client(args.scheduler, args.workers, args.timeout)
            try:
                where = args.scheduler or f"LocalCluster ({len(client.scheduler_info()['workers'])} workers)"
                results = run_grid(runs, client, progress)
            finally:
                client.close()
                if cluster is not None:
                    cluster.close()
        if args.accuracy:
            document = merge_accuracy(results, where)
        else:
            document = {"grid": os.path.abspath(args.grid), "impetus": impetus.__version__, "ran_on": where,
                        "wall_s": time.perf_counter() - start, "runs": results}
        with open(out + ".part", "w", encoding="utf-8") as f:
            json.dump(document, f, indent=1)
        os.replace(out + ".part", out)
        failed = sum(not r["ok"] for r in results)
        print(f"{len(results)} runs ({failed} failed) on {where}: {args.out}")
        for r in results:
            if not r["ok"] and args.accuracy:
                print(f"impetus.sweep: {r['scenario']}: {r['error']}", file=sys.stderr)
        return 1 if args.accuracy and failed else 0
    except impetus.Error as e:
        print(f"impetus.sweep: error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
