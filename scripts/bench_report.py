#!/usr/bin/env python3
"""Turns the benchmark suites' JSON output into docs/benchmarks.md and the scaling charts.

Usage: bench_report.py DATA_DIR DOCS_DIR

DATA_DIR holds Google Benchmark JSON files (--benchmark_format=json): resolve.json, step.json,
detect.json, dynamic.json (bench_step's dynamic rows) and, when the peers benchmark was built, peers.json
and dynamic_peers.json (its rows on the dynamic scenes). Medians are used where the run had
repetitions (aggregate "median"), else the single run. Writes DOCS_DIR/benchmarks.md and
DOCS_DIR/charts/scaling.{png,svg} (and peers.{png,svg} with peers.json; dynamic_heap.{png,svg}, the heap
family's whole-step time against bodies, with dynamic.json or dynamic_peers.json). Charts need matplotlib; without
it the tables are still written and the charts are skipped with a message.
"""
import json
import math
import os
import platform
import re
import subprocess
import sys

# The paper's table (sec. 5; docs/conventions.md, "Benchmark scenes"): name, bodies, contacts, seconds,
# and the Impetus scene that reproduces it.
PAPER = [
    ("Line", 10, 10, 0.00085, "line_10_e0"),
    ("Line", 100, 100, 0.2415, "line_100_e0"),
    ("Pyramid", 6, 9, 0.00013, "pyramid_3"),
    ("Pyramid", 10, 18, 0.00017, "pyramid_4"),
    ("Pyramid", 55, 135, 0.0023, "pyramid_10"),
    ("Pyramid", 210, 570, 6.501, "pyramid_20"),
]
RESOLVERS = ["ledas", "ledas_paper", "mirtich"]
LABELS = {"ledas": "ledas complementary", "ledas_paper": "ledas paper mode", "mirtich": "mirtich (sequential)"}
UNIT = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def load(path):
    """Rows of a Google Benchmark JSON file by run name: the median aggregate, else the single run."""
    if not os.path.exists(path):
        return None
    with open(path) as f:
        data = json.load(f)
    rows = {}
    for b in data.get("benchmarks", []):
        name = re.sub(r"/min_time:[^/]*", "", b.get("run_name", b["name"]))
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        if "error_occurred" in b and b["error_occurred"]:
            rows[name] = {"error": b.get("error_message", "error")}
            continue
        row = dict(b)
        # CPU time of the (single-threaded) run: robust on a shared machine; wall time kept beside it.
        row["seconds"] = b["cpu_time"] * UNIT[b.get("time_unit", "ns")]
        row["wall_seconds"] = b["real_time"] * UNIT[b.get("time_unit", "ns")]
        rows[name] = row
    return {"context": data.get("context", {}), "rows": rows}


def seconds(t):
    """A time in the unit that reads best."""
    if t is None or (isinstance(t, float) and math.isnan(t)):
        return "—"
    if t >= 1:
        return f"{t:.3g} s"
    if t >= 1e-3:
        return f"{t * 1e3:.3g} ms"
    return f"{t * 1e6:.3g} µs"


def sci(x):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    return "0" if x == 0 else f"{x:.1e}"


def speedup(x):
    return f"{x:,.0f}×" if x >= 10 else f"{x:.2g}×"


def fit_exponent(points):
    """Least-squares slope k of log t = k log n + c over (n, t) points; None for fewer than 3."""
    pts = [(math.log(n), math.log(t)) for n, t in points if n > 0 and t > 0]
    if len(pts) < 3:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in pts)
    return sxy / sxx


def frictional(scene):
    """Whether a scene name is a frictional row (…_mu<μ>): those have their own section."""
    return "_mu" in scene


def scene_order(scene):
    """Pyramids, then lines, then the other families (stacks, walls) by name; by size within a family."""
    m = re.match(r"(pyramid|line|[a-z]+)_(\d+)(?:_e(\d))?", scene)
    if not m:
        return (2, scene, 0, "")
    rank = {"pyramid": 0, "line": 1}.get(m.group(1), 2)
    return (rank, m.group(1), int(m.group(2)), scene)


def machine(context):
    """One line describing the machine, the compiler and the benchmark library's context."""
    # The CPU the benchmarks ran on (scripts/bench.sh records it in the context); data without it were
    # produced before it was recorded, and the machine that runs this report may be another one.
    cpu = context.get("cpu_model") or "CPU not recorded"
    try:
        compiler = subprocess.run(["c++", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    except (OSError, IndexError):
        compiler = "unknown compiler"
    distro = ""
    try:
        with open("/etc/os-release") as f:
            distro = dict(l.rstrip().split("=", 1) for l in f if "=" in l).get("PRETTY_NAME", "").strip('"')
    except OSError:
        pass
    return (f"{cpu}, {context.get('num_cpus', '?')} cores at {context.get('mhz_per_cpu', '?')} MHz, {distro}, "
            f"{compiler}, Impetus built {context.get('impetus_build_type', '?')}, run {context.get('date', '?')}; "
            f"one thread")


def by_scene(rows, family):
    """{resolver: {scene: row}} for rows named family/resolver/scene."""
    out = {}
    for name, row in rows.items():
        parts = name.split("/")
        if len(parts) != 3 or parts[0] != family:
            continue
        out.setdefault(parts[1], {})[parts[2]] = row
    return out


def paper_table(res):
    lines = ["| Scene | Bodies | Contacts (paper) | Paper (s) | " +
             " | ".join(f"{LABELS[r]}: time · speed-up · residual" for r in RESOLVERS) + " |",
             "|---|---:|---:|---:|" + "---|" * len(RESOLVERS)]
    for name, bodies, contacts, t_paper, scene in PAPER:
        cells = []
        for r in RESOLVERS:
            row = res.get(r, {}).get(scene)
            if not row or "error" in row:
                cells.append("—")
                continue
            exact = ("exact" if row.get("exact", 0) >= 1
                     else f"residual {sci(row.get('residual'))}, complementarity {sci(row.get('complementarity'))}")
            cells.append(f"{seconds(row['seconds'])} · {speedup(t_paper / row['seconds'])} · {exact}")
        lines.append(f"| {name} | {bodies} | {contacts} | {t_paper} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def full_table(res):
    scenes = sorted({s for r in res.values() for s in r if not frictional(s)}, key=scene_order)
    lines = ["| Scene | Bodies | Contacts | Resolver | Time (median) | Rounds / impulses | Pulling | "
             "Residual (m/s) | Complementarity | Exact | Not converged |",
             "|---|---:|---:|---|---:|---:|---:|---:|---:|:-:|:-:|"]
    for scene in scenes:
        for r in RESOLVERS:
            row = res.get(r, {}).get(scene)
            if not row:
                continue
            if "error" in row:
                lines.append(f"| {scene} | | | {r} | error: {row['error']} | | | | | | |")
                continue
            lines.append(
                f"| {scene} | {row['bodies']:.0f} | {row['contacts']:.0f} | {r} | {seconds(row['seconds'])} | "
                f"{row['rounds']:,.0f} | {row['pulling']:,.0f} | {sci(row['residual'])} | "
                f"{sci(row['complementarity'])} | {'yes' if row['exact'] >= 1 else 'no'} | "
                f"{'yes' if row['non_converged'] > 0 else ''} |")
    return "\n".join(lines)


def scaling(res):
    """{resolver: {"pyramid": k, "line_e0": k, "line_e1": k}} fitted over contacts."""
    fits = {}
    for r, scenes in res.items():
        fam = {"pyramid": [], "line_e0": [], "line_e1": []}
        for scene, row in scenes.items():
            if "error" in row or frictional(scene):
                continue
            key = "pyramid" if scene.startswith("pyramid") else ("line_e1" if scene.endswith("_e1") else "line_e0")
            fam[key].append((row["contacts"], row["seconds"]))
        fits[r] = {k: fit_exponent(v) for k, v in fam.items()}
    return fits


def friction_rows(res):
    """The frictional rows (scene names …_mu<μ>) as (sort keys…, family, μ, scene, resolver, row): pyramids
    first, then by μ falling, size, resolver."""
    entries = []
    for r, scenes in res.items():
        for scene, row in scenes.items():
            m = re.match(r"(pyramid|line)_(\d+)(?:_e\d)?_mu([0-9.]+)$", scene)
            if m and "error" not in row:
                entries.append((m.group(1) != "pyramid", -float(m.group(3)), int(m.group(2)),
                                RESOLVERS.index(r), m.group(1), m.group(3), scene, r, row))
    return sorted(entries)


def friction_table(res):
    """The frictional rows: time, fclib's natural-map error, sticking and sliding contacts, and the time
    against the frictionless exact resolve of the same scene (ledas complementary)."""
    lines = ["| Scene | μ | Bodies | Contacts | Resolver | Time (median) | Natural map | Sticking | Sliding | "
             "Exact | × frictionless ledas |", "|---|---:|---:|---:|---|---:|---:|---:|---:|:-:|---:|"]
    for *_, family, mu, scene, r, row in friction_rows(res):
        base = res.get("ledas", {}).get(scene.rsplit("_mu", 1)[0])
        ratio = f"{row['seconds'] / base['seconds']:,.0f}×" if base and "error" not in base else "—"
        lines.append(f"| {scene} | {mu} | {row['bodies']:.0f} | {row['contacts']:.0f} | {r} | "
                     f"{seconds(row['seconds'])} | {sci(row.get('natural_map'))} | {row.get('sticking', 0):.0f} | "
                     f"{row.get('sliding', 0):.0f} | {'yes' if row['exact'] >= 1 else 'no'} | {ratio} |")
    return "\n".join(lines)


def friction_fits(res):
    """Fitted exponent of time against contacts per (resolver, family, μ) over at least 3 rows."""
    groups = {}
    for *_, family, mu, scene, r, row in friction_rows(res):
        groups.setdefault((r, family, mu), []).append((row["contacts"], row["seconds"]))
    lines = ["| Resolver | Family | μ | Rows | k |", "|---|---|---:|---:|---:|"]
    for (r, family, mu), pts in groups.items():
        k = fit_exponent(pts)
        if k is not None:
            lines.append(f"| {LABELS[r]} | {family} | {mu} | {len(pts)} | {k:.2f} |")
    return "\n".join(lines)


def scaling_table(fits):
    lines = ["| Resolver | k, pyramid K = 3…100 | k, line e = 0 | k, line e = 1 |", "|---|---:|---:|---:|"]
    for r in RESOLVERS:
        if r not in fits:
            continue
        f = fits[r]
        cell = lambda k: "—" if f.get(k) is None else f"{f[k]:.2f}"
        lines.append(f"| {LABELS[r]} | {cell('pyramid')} | {cell('line_e0')} | {cell('line_e1')} |")
    return "\n".join(lines)


def step_table(steps):
    scenes = sorted({s for r in steps.values() for s in r}, key=scene_order)
    lines = ["| Scene | Resolver | Step (median) | velocities | detect | resolve | positions | resolve share |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for scene in scenes:
        for r in RESOLVERS:
            row = steps.get(r, {}).get(scene)
            if not row or "error" in row:
                continue
            ms = lambda k: seconds(row[k] * 1e-3)
            lines.append(f"| {scene} | {r} | {seconds(row['seconds'])} | {ms('velocities_ms')} | {ms('detect_ms')} | "
                         f"{ms('resolve_ms')} | {ms('positions_ms')} | {100 * row['resolve_share']:.0f}% |")
    return "\n".join(lines)


def detect_table(rows):
    lines = ["| Scene | Bodies | Contacts | Detect (median) | broadphase | narrowphase |", "|---|---:|---:|---:|---:|---:|"]
    for name, row in sorted(rows.items()):
        if not name.startswith("detect/") or "error" in row:
            continue
        lines.append(f"| {name[7:]} | {row['bodies']:.0f} | {row['contacts']:.0f} | {seconds(row['seconds'])} | "
                     f"{seconds(row['broadphase_ms'] * 1e-3)} | {seconds(row['narrowphase_ms'] * 1e-3)} |")
    return "\n".join(lines)


MODEL_TEXT = {
    "fixed_bodies": "16 pyramids (K = 6) on a fixed ground (on) or on a movable 10⁹ kg ground box (off)",
    "islands": "the same 16 pyramids solved island by island (on) or as one system (off)",
    "primitives": "pyramid K = 10 of analytic spheres (on) or of 642-vertex convex icosphere meshes (off)",
    "contact_reduction": "10 boxes, each turned 45°: ≤ 4 points per pair (on) or all 8 octagon corners (off)",
    "start_set": "pyramid K = 20 dropped on a fixed ground: ledas starts with the impact's contacts (on) or every "
                 "touching one (off)",
}


def model_table(rows):
    lines = ["| Lever | Scene | Step on | Step off | Off / on | Contacts on / off | Islands on / off | "
             "detect on / off | resolve on / off |", "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for lever, text in MODEL_TEXT.items():
        on, off = rows.get(f"model/{lever}/on"), rows.get(f"model/{lever}/off")
        if not on or not off or "error" in on or "error" in off:
            lines.append(f"| {lever} | {text} | — | — | — | | | | |")
            continue
        ms = lambda r, k: seconds(r[k] * 1e-3)
        lines.append(f"| {lever} | {text} | {seconds(on['seconds'])} | {seconds(off['seconds'])} | "
                     f"{off['seconds'] / on['seconds']:.1f}× | {on['contacts']:.0f} / {off['contacts']:.0f} | "
                     f"{on['islands']:.0f} / {off['islands']:.0f} | {ms(on, 'detect_ms')} / {ms(off, 'detect_ms')} | "
                     f"{ms(on, 'resolve_ms')} / {ms(off, 'resolve_ms')} |")
    return "\n".join(lines)


def peers_table(rows, scene_wanted):
    """Rows named peers/<method>/<scene_wanted>, sorted by time."""
    entries = []
    for name, row in rows.items():
        parts = name.split("/")
        if len(parts) != 3 or "error" in row or parts[2] != scene_wanted:
            continue
        entries.append((parts[2], parts[1], row))
    entries.sort(key=lambda e: (scene_order(e[0]), e[2]["seconds"]))
    lines = ["| Method | Time (median) | Solver alone | Residual (m/s) | Complementarity | Solver failure reported | Exact |",
             "|---|---:|---:|---:|---:|:-:|:-:|"]
    for scene, method, row in entries:
        solver = seconds(row["solver_ms"] * 1e-3) if row.get("solver_ms") else "—"
        lines.append(f"| {method} | {seconds(row['seconds'])} | {solver} | {sci(row.get('residual'))} | "
                     f"{sci(row.get('complementarity'))} | {'yes' if row.get('failures', 0) > 0 else ''} | "
                     f"{'yes' if row.get('exact', 0) >= 1 else 'no'} |")
    return "\n".join(lines)


def dynamic_table(rows):
    """bench_step's dynamic rows, step/<resolver>/<scene>_t<threads>: per-step wall times (the world's step
    profile, steady clock: CPU time would miss the second thread) and the speed-up of 2 threads over 1."""
    by_key = {}
    for name, row in rows.items():
        m = re.match(r"step/([a-z_]+)/(.+)_t(\d+)$", name)
        if m and "error" not in row:
            by_key[(m.group(2), m.group(1), int(m.group(3)))] = row
    lines = ["| Scene | Resolver | Threads | Bodies | Contacts | Islands | Step (median) | detect | resolve | "
             "2 threads over 1 | Residual (m/s) | Natural map | Deepest (m) | Analyses new / reused | Allocations |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for (scene, resolver, threads), row in sorted(by_key.items()):
        one = by_key.get((scene, resolver, 1))
        ratio = f"{one['step_ms'] / row['step_ms']:.2f}×" if threads == 2 and one else ""
        ms = lambda k: seconds(row[k] * 1e-3)
        analyses = (f"{row['analyses']:.0f} / {row['analyses_reused']:.0f}"
                    if "analyses" in row and "analyses_reused" in row else "—")
        allocations = f"{row['allocations']:,.0f}" if "allocations" in row else "—"
        lines.append(f"| {scene} | {resolver} | {threads} | {row['bodies']:.0f} | {row['contacts']:.0f} | "
                     f"{row['islands']:.0f} | {ms('step_ms')} | {ms('detect_ms')} | {ms('resolve_ms')} | {ratio} | "
                     f"{sci(row.get('residual'))} | {sci(row.get('natural_map'))} | {sci(row.get('penetration'))} | "
                     f"{analyses} | {allocations} |")
    return "\n".join(lines)


def machine_table(rows):
    """bench_step's machine/ rows (benchmarks/support/machine_probe.hpp): the pile's one-thread step pinned
    to each vCPU. None if the run has none."""
    lines = ["| Probe | Per step | Against the fastest |", "|---|---:|---:|"]
    pinned = {int(m.group(1)): row for name, row in rows.items()
              if (m := re.match(r"machine/pile_1000_cpu(\d+)$", name)) and "error" not in row}
    fastest = min((row["step_ms"] for row in pinned.values()), default=None)
    for cpu, row in sorted(pinned.items()):
        lines.append(f"| pile of 1,000, one thread on vCPU {cpu} | {seconds(row['step_ms'] * 1e-3)} | "
                     f"{row['step_ms'] / fastest:.2f}× |")
    if len(pinned) > 1:  # each vCPU doing the share its speed allows
        ceiling = sum(fastest / row["step_ms"] for row in pinned.values())
        lines.append(f"| ceiling for {len(pinned)} threads on work that splits perfectly | | {ceiling:.2f}× |")
    return "\n".join(lines) if len(lines) > 2 else None


def lead_in_table(rows):
    """bench_step's frictional dynamic rows (one thread): the lead-in to the snapshot, whole. Its resolver's
    time per step against the timed steps', its frictional problems left unconverged, and the share of its
    resolver's time in the steps that left one."""
    lines = ["| Scene | Lead-in steps | Resolver, whole lead-in | Mean per step | Timed step's resolve (median) | "
             "Frictional problems | Unconverged | Steps with one | Their share of the resolver's time |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, row in sorted(rows.items()):
        m = re.match(r"step/ledas/(.+)_t1$", name)
        if not m or "error" in row or "lead_in_unconverged_steps" not in row:
            continue
        steps = row["lead_in_steps"]
        total = row["lead_in_resolve_s"]
        share = f"{100 * row['lead_in_unconverged_resolve_s'] / total:.0f}%" if total > 0 else "—"
        lines.append(f"| {m.group(1)} | {steps:.0f} | {seconds(total)} | {seconds(total / steps)} | "
                     f"{seconds(row['resolve_ms'] * 1e-3)} | {row['lead_in_friction_problems']:.0f} | "
                     f"{row['lead_in_non_converged']:.0f} | {row['lead_in_unconverged_steps']:.0f} | {share} |")
    return "\n".join(lines) if len(lines) > 2 else ""


def cold_table(rows):
    """bench_resolve's resolve_cold rows: the first solve of a new contact pattern against a repeated one."""
    lines = ["| Scene | Bodies | Contacts | Cold (median) | Warm (mean, same run) | Cold / warm | Analyses per cold solve |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    entries = []
    for name, row in rows.items():
        parts = name.split("/")
        if len(parts) == 3 and parts[0] == "resolve_cold" and "error" not in row:
            entries.append((scene_order(parts[2]), parts[2], row))
    for _, scene, row in sorted(entries):
        lines.append(f"| {scene} | {row['bodies']:.0f} | {row['contacts']:.0f} | {seconds(row['seconds'])} | "
                     f"{seconds(row['warm_ms'] * 1e-3)} | {row['cold_over_warm']:.2f} | {row['analyses']:.0f} |")
    return "\n".join(lines)


def dynamic_peers_table(rows):
    """bench_peers' rows on the dynamic scenes: one whole step under gravity from a snapshot per engine."""
    families = ("heap_", "pile_", "knocked_wall_", "pyramid_")
    entries = []
    for name, row in rows.items():
        parts = name.split("/")
        if len(parts) == 3 and parts[2].startswith(families) and "error" not in row:
            scene, _, mu = parts[2].partition("_mu")
            family, n = scene.rsplit("_", 1)
            order = [f.rstrip("_") for f in families].index(family)
            entries.append((bool(mu), order, int(n), row["seconds"], parts[2], parts[1].removesuffix("_gravity"), row))
    entries.sort()
    lines = ["| Scene | Method | Step (median) | Solver alone | Contacts found | Touching contacts missed | "
             "Residual (m/s) | Complementarity | Natural map |", "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for *_, scene, method, row in entries:
        solver = seconds(row["solver_ms"] * 1e-3) if row.get("solver_ms") else "—"
        lines.append(f"| {scene} | {method} | {seconds(row['seconds'])} | {solver} | {row['engine_contacts']:.0f} | "
                     f"{row['missing']:.0f} | {sci(row.get('residual'))} | {sci(row.get('complementarity'))} | "
                     f"{sci(row.get('natural_map'))} |")
    return "\n".join(lines)


# The heap family (frictionless): whole-step time against bodies per engine, from bench_step's rows
# (five consecutive steps, per step) and bench_peers' (one step after an untimed one).
HEAP_SERIES = [
    ("step", r"step/ledas/heap_(\d+)_t1$", "Impetus ledas, 1 thread (bench_step)"),
    ("step", r"step/ledas/heap_(\d+)_t2$", "Impetus ledas, 2 threads (bench_step)"),
    ("step", r"step/mirtich/heap_(\d+)_t1$", "Impetus mirtich (bench_step)"),
    ("peers", r"peers/impetus_ledas_step_gravity/heap_(\d+)$", "Impetus ledas (bench_peers)"),
    ("peers", r"peers/bullet_si_10_gravity/heap_(\d+)$", "Bullet SI 10"),
    ("peers", r"peers/bullet_si_50_gravity/heap_(\d+)$", "Bullet SI 50"),
    ("peers", r"peers/ode_quickstep_20_gravity/heap_(\d+)$", "ODE QuickStep 20"),
    ("peers", r"peers/ode_worldstep_shipped_gravity/heap_(\d+)$", "ODE dWorldStep"),
    ("peers", r"peers/mujoco_newton_gravity/heap_(\d+)$", "MuJoCo Newton"),
]


def heap_family(dynamic_rows, peers_rows):
    """{label: [(bodies, seconds per step)]} over the heap family, each series in increasing bodies. bench_step
    rows give their per-step wall time (step_ms), bench_peers rows their median step."""
    series = {}
    for source, pattern, label in HEAP_SERIES:
        rows = dynamic_rows if source == "step" else peers_rows
        pts = []
        for name, row in (rows or {}).items():
            m = re.match(pattern, name)
            if m and "error" not in row:
                pts.append((int(m.group(1)), row["step_ms"] * 1e-3 if source == "step" else row["seconds"]))
        if pts:
            series[label] = sorted(pts)
    return series


def heap_table(series):
    """Per engine: its step time at each size of the heap family and the fitted exponent."""
    sizes = sorted({n for pts in series.values() for n, _ in pts})
    lines = ["| Engine | " + " | ".join(f"{n:,} spheres" for n in sizes) + " | Exponent k |",
             "|---|" + "---:|" * (len(sizes) + 1)]
    for label, pts in series.items():
        at = dict(pts)
        k = fit_exponent(pts)
        lines.append(f"| {label} | " + " | ".join(seconds(at.get(n)) for n in sizes) + " | " +
                     (f"{k:.2f}" if k is not None else "—") + " |")
    return "\n".join(lines)


def heap_chart(series, out_dir):
    """charts/dynamic_heap.{png,svg}: whole-step time against bodies per engine, log-log."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    os.makedirs(out_dir, exist_ok=True)
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for label, pts in series.items():
        style = "-" if label.startswith("Impetus") else "--"
        ax.plot([p[0] for p in pts], [p[1] for p in pts], style, marker="o", label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("spheres")
    ax.set_ylabel("whole step (s)")
    ax.set_title("Heap of spheres settling: whole-step time against bodies")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(plt, fig, out_dir, "dynamic_heap")


def save_figure(plt, fig, out_dir, name):
    """Writes the figure as out_dir/name.{png,svg}, closes it, returns the paths."""
    fig.tight_layout()
    written = []
    for ext in ("png", "svg"):
        path = os.path.join(out_dir, f"{name}.{ext}")
        fig.savefig(path, dpi=110)
        written.append(path)
    plt.close(fig)
    return written


def charts(res, out_dir):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("bench_report: matplotlib not installed (apt-get install python3-matplotlib): charts skipped")
        return []
    os.makedirs(out_dir, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    markers = {"ledas": "o", "ledas_paper": "s", "mirtich": "^"}
    for ax, family in zip(axes, ["pyramid", "line"]):
        ringed = False
        for r in RESOLVERS:
            pts = sorted((row["contacts"], row["seconds"], row["exact"] >= 1) for s, row in res.get(r, {}).items()
                         if "error" not in row and s.startswith(family) and not s.endswith("_e1") and not frictional(s))
            if not pts:
                continue
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=markers[r], label=LABELS[r])
            wrong = [p for p in pts if not p[2]]
            if wrong:
                ax.scatter([p[0] for p in wrong], [p[1] for p in wrong], s=140, facecolors="none",
                           edgecolors="red", zorder=5, label=None if ringed else "not exact (residual or complementarity > 1e-9)")
                ringed = True
        paper = [(c, t) for name, _, c, t, _ in PAPER if name.lower() == family]
        ax.scatter([p[0] for p in paper], [p[1] for p in paper], marker="*", s=160, color="black",
                   label="paper (sec. 5)", zorder=6)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("contacts")
        ax.set_ylabel("resolver time (s)")
        ax.set_title(f"{family}: resolver alone, e = 0" + (" (sphere pyramid drop)" if family == "pyramid" else " (line push)"))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    return save_figure(plt, fig, out_dir, "scaling")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    data_dir, docs_dir = sys.argv[1], sys.argv[2]
    resolve = load(os.path.join(data_dir, "resolve.json"))
    if resolve is None:
        sys.exit(f"bench_report: {data_dir}/resolve.json not found (run scripts/bench.sh)")
    step = load(os.path.join(data_dir, "step.json"))
    detect = load(os.path.join(data_dir, "detect.json"))
    peers = load(os.path.join(data_dir, "peers.json"))
    model = load(os.path.join(data_dir, "model.json"))
    res = by_scene(resolve["rows"], "resolve")
    fits = scaling(res)

    out = ["# Benchmarks", "",
           "Generated by `bash scripts/bench.sh` (which runs the suites in `benchmarks/` and then "
           "`scripts/bench_report.py`); do not edit by hand.", "",
           f"Machine: {machine(resolve['context'])}.", "",
           "Times are medians of the repetitions. *Residual* is the largest approach velocity left after the "
           "solve and *complementarity* the largest |p·v⁺| over the contacts, both measured from the bodies' "
           "velocities, not reported by the resolver; *exact* means both ≤ 1e-9. See `benchmarks/resolve.cpp`.", "",
           "## The paper's table (sec. 5), regenerated", "",
           "The resolver alone on the prepared contact list (detection outside the timed loop), velocity phase "
           "only. Speed-up = paper's time / Impetus' time on this machine (the paper's machine is unknown, so the "
           "ratio compares methods and implementations together). Impetus' pyramids also carry the K ground "
           "contacts the paper's counts leave out.", "",
           paper_table(res), "",
           "![Resolver time against contacts](charts/scaling.png)", "",
           "## Scaling exponents", "",
           "Least-squares fit of log time = k log contacts + c over each family (all rows, exact or not).", "",
           scaling_table(fits), "",
           "## Every row of the `resolve` family", "",
           full_table(res), ""]
    if friction_rows(res):
        out += ["## With Coulomb friction (`resolve` rows `…_mu<μ>`)", "",
                "The same scenes with friction coefficient μ on every contact (`benchmarks/resolve.cpp`). "
                "*Natural map* is fclib's error of the impulses (‖r − P_K(r − (u + μ‖u_t‖ n))‖ over the "
                "contacts, from the velocities after the solve); *exact* means natural map ≤ 1e-9 and no "
                "approach left; *sticking* and *sliding* count the contacts with an impulse and no slip after "
                "it, and with slip. The last column divides by the frictionless exact resolve of the same "
                "scene.", "", friction_table(res), "",
                "Fitted exponent of time against contacts (all rows, exact or not):", "",
                friction_fits(res), ""]
    cold = load(os.path.join(data_dir, "resolve_cold.json"))
    if cold:
        out += ["## A new contact pattern (`resolve_cold` rows)", "",
                "A running resolver handed a contact pattern it has not seen (the prepared contacts rotated to "
                "one of 40 start points: the same problem, rows in a new order, more patterns than ledas caches "
                "analyses of), against the same pattern solved again right after (the warm solve of the rows "
                "above). The cold solve pays the symbolic analysis (the order: COLAMD on the rows' bodies up to "
                "2,000 analysed rows, else AMD; the elimination tree; the row patterns of L); with friction the "
                "interior point's and Newton's shared analysis of W. "
                "`benchmarks/resolve.cpp`, `resolve_cold`.", "",
                f"Machine: {machine(cold['context'])}.", "",
                cold_table(cold["rows"]), "",
                "Where a cold solve's extra time goes (2026-12-06, timers around each stage of the analysis, "
                "removed after): at K = 20 the order takes 45 µs, the upper triangle of the permuted matrix "
                "20 µs and the elimination tree with the row patterns of L 23 µs, 89 µs against a warm solve "
                "of ~150 µs; at K = 100, 3.05 + 0.37 + 1.26 ms against ~8.7 ms. Orders taken from the bodies "
                "instead (minimum degree on the graph of bodies, each row placed by the first or the last of "
                "its two bodies) would cost a few µs, but gave L 1.5–8× more entries and 2–40× the "
                "factorization's work on the pyramids K = 20, 50 and 100: not kept.", "",
                "The first solve in a process costs more again, on this machine mostly in the kernel: a page "
                "of memory written for the first time costs about 10 µs here (a fresh 64 MB buffer written "
                "once per 4 KiB page: 9.8 µs a page; written again: 0.035 µs; mapped with `MAP_POPULATE`: still "
                "6.5 µs), where bare-metal Linux takes a fraction of a microsecond. A one-shot `impetus resolve` "
                "of the pyramid K = 100 spends 55–75 ms in the resolver against a warm 8–10 ms, and takes about "
                "3,600 minor page faults (`getrusage` around each stage, a temporary instrument): building the "
                "rows 910 (1,330 before they were reserved at once, 2026-12-06), the island's matrix 593, the "
                "order 702, the factor's storage 542, the search 262. At ~12 µs each that is ~40 ms, so the "
                "one-shot target (at most 2× the warm solve) is out of reach here for any resolver that builds "
                "this 15,000-row system in fresh memory. At K = 20 (2026-12-07, the same instrument around the "
                "command's one detection and resolve): the first in a process takes 299–301 minor page faults, "
                "1.2–1.4 ms detecting and 1.9–2.2 ms resolving; the same again on a second world built in the "
                "same process 39–49 faults, 0.13–0.18 and 0.69–0.91 ms. Binding every symbol at load "
                "(`LD_BIND_NOW=1`) and glibc's huge pages for its heap (`GLIBC_TUNABLES=glibc.malloc.hugetlb=1`) "
                "left the first figures as they were.", ""]
    if step:
        out += ["## A whole step under gravity (`step` family)", "",
                "Detect + resolve + integrate from the drop/push state, position correction on; the stage split "
                "comes from the world's step profile.", "",
                step_table(by_scene(step["rows"], "step")), ""]
    dynamic = load(os.path.join(data_dir, "dynamic.json"))
    dynamic_peers = load(os.path.join(data_dir, "dynamic_peers.json"))
    if dynamic:
        out += ["## Dynamic scenes (`step` family, rows `…_t1`, `…_t2`)", "",
                "Scenes whose contact pattern changes almost every step (`benchmarks/support/bench_dynamic.hpp`): "
                "a pile of mixed spheres, boxes and capsules poured into a bin, a heap of spheres settling on open "
                "ground, a brick wall hit by a heavy ball, the pyramid of 100 rows at rest. Each iteration gives "
                "the world a new resolver, steps it once untimed from the state a step before the scene's "
                "snapshot, puts it at the snapshot and times 5 whole steps from there, so every warm start and "
                "cached analysis comes from an earlier step of the same run, as in a simulation (never from an "
                "earlier iteration's timed steps); the figures are per step, wall time, with 1 and 2 threads "
                "(`World::set_threads`). *Residual* and *natural map* are the resolver's own, the largest over "
                "the steps; *deepest* the deepest contact a detection found. *Analyses* are `ledas`'s symbolic "
                "analyses per step (impacts and position corrections): new patterns analysed, and patterns "
                "found in a lane's cache; *allocations* the heap allocations per step (libraries included; "
                "benchmarks/README.md).", "",
                dynamic_table(dynamic["rows"]), ""]
        vcpus = machine_table(dynamic["rows"])
        if vcpus:
            out += ["### What two threads can give on this machine", "",
                    "The same run's `machine/` rows (`benchmarks/support/machine_probe.hpp`): the pile's "
                    "one-thread steps with the thread pinned to each vCPU in turn. On this virtual machine one vCPU "
                    "at times runs the scenes up to 1.3× slower than the other (which one changes over the day, "
                    "while plain arithmetic runs alike on both), so a one-thread row runs at the speed of whichever vCPU it "
                    "was given, and *2 threads over 1* above, against a one-thread row on the fast vCPU, is "
                    "bounded even for work that splits perfectly: by Σ t_fast / t_k over the vCPUs k (the "
                    "last line).", "",
                    vcpus, ""]
        lead_in = lead_in_table(dynamic["rows"])
        if lead_in:
            out += ["### The frictional rows' lead-in", "",
                    "The steps from each frictional scene's start to its snapshot (one thread, one run), whole: "
                    "a longer measure of the frictional solver than the 5 timed steps, which start where the "
                    "lead-in ends. A step counts under *steps with one* if it left at least one frictional "
                    "island problem above its tolerance (its best answer is applied, and counted in the "
                    "resolver's `non_converged`); the last column is those steps' share of the lead-in's "
                    "resolver time.", "",
                    lead_in, ""]
    if dynamic_peers:
        out += ["### The dynamic scenes in every engine", "",
                "One whole step under gravity from each scene's snapshot (the heaps, the pile of 1,000 mixed "
                "primitives in its bin, the wall of 200 bricks being knocked over, the pyramid of 100 rows at "
                "rest), each engine with its own "
                "detection (Impetus on one thread, as the others), judged at the contacts Impetus finds touching "
                "in the snapshot: *residual* is the largest approach velocity there, *complementarity* the "
                "largest impulse times separation over the pairs of bodies (a box's face is judged as one pair, "
                "since each engine picks its own points on it; `benchmarks/peers/README.md`). Where engines "
                "disagree on the geometry (a capsule on a box's edge), the judge is Impetus's detector. With "
                "μ = 0.5 (`_mu0.5`), each engine's own friction law; *natural map* is fclib's error of the "
                "impulses each engine reports, measured on the heap (one point per pair) and not on the pile "
                "(its face contacts have each engine's own points). Each timed step follows an untimed one "
                "from the state a step before the snapshot, every engine emptied of its caches first, so each "
                "warm-starts from a previous step as in a running simulation (`benchmarks/peers/README.md`); "
                "*solver alone* is the engine's solve in that step.", "",
                dynamic_peers_table(dynamic_peers["rows"]), ""]
    heap = heap_family(dynamic["rows"] if dynamic else None, dynamic_peers["rows"] if dynamic_peers else None)
    heap_written = []
    if heap:
        heap_written = heap_chart(heap, os.path.join(docs_dir, "charts"))
        out += ["### Whole-step time against bodies: the heap family", "",
                "The frictionless heaps of 300 to 10,000 spheres (above): each engine's whole step against the "
                "number of bodies, and the least-squares exponent k of log time = k log bodies + c over the "
                "sizes it ran (MuJoCo and ODE's `dWorldStep` are not run above 1,000 bodies). bench_step's rows "
                "are per step of five consecutive steps, bench_peers' one step after an untimed one; the "
                "larger heaps hold one large island (2,850 of the 10,000-sphere heap's 4,800 contacts), whose "
                "exact solve grows faster than its rows.", ""]
        if heap_written:
            out += ["![Whole-step time against bodies, heap family](charts/dynamic_heap.png)", ""]
        out += [heap_table(heap), ""]
    if detect:
        out += ["## Detection alone (`detect` family)", "", detect_table(detect["rows"]), ""]
    if model:
        out += ["## Model no more than a scene needs (`model` family)", "",
                "Each lever of “model no more than a scene needs” (docs/architecture.md) switched on and off on the same scene; one whole step from the "
                "same state per iteration (`benchmarks/model.cpp`).", "", model_table(model["rows"]), ""]
    if peers:
        out += ["## Peers side by side (`peers` benchmark)", "",
                "Bullet, ODE and MuJoCo on the identical initial state; their post-step velocities are judged with "
                "the same counters against the same contact list. Engine rows time a whole step (their own "
                "detection, solve, integration; *solver alone* is the engine's solve), Impetus rows the "
                "resolver alone. `benchmarks/peers/README.md` says which settings are as shipped and which "
                "regularized; [peers.md](peers.md) has every scene. Pyramid K = 20 (210 bodies, 590 contacts):", "",
                "![Time against error, pyramid K = 20](charts/peers.png)", "",
                peers_table(peers["rows"], "pyramid_20"), ""]
    else:
        out += ["## Peers", "", "No `peers.json`: the peers benchmark was not built (Bullet, ODE, MuJoCo not "
                "installed) or not run.", ""]
    os.makedirs(docs_dir, exist_ok=True)
    with open(os.path.join(docs_dir, "benchmarks.md"), "w") as f:
        f.write("\n".join(out))
    written = charts(res, os.path.join(docs_dir, "charts")) + heap_written
    print(f"bench_report: wrote {os.path.join(docs_dir, 'benchmarks.md')}" + "".join(f", {w}" for w in written))
    for r in RESOLVERS:
        if r in fits:
            print(f"  scaling {r}: " + ", ".join(f"{k} k={v:.2f}" for k, v in fits[r].items() if v is not None))


if __name__ == "__main__":
    main()
