#!/usr/bin/env python3
"""Table (markdown) and chart (time per solve against error) from a bench_peers JSON run.

    bench_peers --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
                --benchmark_format=json > peers.json
    benchmarks/peers/report.py peers.json [--chart peers.png]

Times are medians over the repetitions: CPU time of the process (robust on a shared machine) and wall
time; the counters are those of the median aggregate (they do not vary between repetitions).
"""
import argparse
import json
import math
import sys


def load(path):
    with open(path) as f:
        data = json.load(f)
    rows = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median" or b.get("error_occurred"):
            continue
        _, method, scene = b["run_name"].split("/")[:3]
        rows[(method, scene)] = b
    return rows


def fmt(x):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "nan"
    if x == 0:
        return "0"
    return f"{x:.3g}" if 1e-3 <= abs(x) < 1e4 else f"{x:.1e}"


def scene_key(s):
    return (s.split("_")[0], int(s.split("_")[1]), s)


def table(rows):
    scenes = sorted({s for _, s in rows if "_mu" not in s}, key=scene_key)
    out = ["| method | scene | contacts (engine) | cpu ms | wall ms | solver ms | residual m/s | complementarity | energy change | failures | exact |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for method in dict.fromkeys(m for m, _ in rows):
        for scene in scenes:
            b = rows.get((method, scene))
            if not b:
                continue
            out.append("| {} | {} | {} ({}) | {} | {} | {} | {} | {} | {} | {} | {} |".format(
                method, scene, int(b["contacts"]), int(b["engine_contacts"]), fmt(b["cpu_time"]),
                fmt(b["real_time"]), fmt(b.get("solver_ms")), fmt(b["residual"]), fmt(b["complementarity"]),
                fmt(b["energy_change"]), int(b["failures"]), int(b["exact"])))
    return "\n".join(out)


FRICTION_INTRO = """## With friction: the same contact problem, judged by the natural-map error

The dropped pyramids of the table above with every body's μ = 0.7 (every contact can stick) or 0.5 (the
supports slide), gravity off, one step: each engine's own friction law with that μ (Bullet: one friction
row per contact point along its slip as shipped, two in the `_2dir` rows; ODE: two directions each bounded
by μ times the normal force, `dContactApprox1`; MuJoCo: condim 3, elliptic cones, pyramidal ones in the
`_pyramidal` rows). Each is judged by fclib's natural-map error of its own impulses (normal and friction,
read from the engine: Bullet's applied normal and lateral impulses, ODE's joint feedback force × dt,
MuJoCo's `mj_contactForce` × dt) and the relative velocities its step left, in each contact's frame
(unscaled: the error ledas's frictional solver drives below 1e-9 by Coulomb's law). `impulse mismatch` is
the largest difference between a body's momentum change and the impulses the engine reports on it: near
rounding everywhere, so the impulses read are the ones applied. exact: natural-map error ≤ 1e-9 and
residual ≤ 1e-9 m/s (as `bench_resolve`)."""


def friction_table(rows):
    scenes = sorted({s for _, s in rows if "_mu" in s}, key=lambda s: (s.split("_mu")[1], scene_key(s)))
    out = [FRICTION_INTRO, "",
           "| method | scene | contacts (engine) | cpu ms | solver ms | natural-map error | residual m/s | impulse mismatch N·s | failures | exact |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for scene in scenes:
        for method in dict.fromkeys(m for m, _ in rows):
            b = rows.get((method, scene))
            if not b:
                continue
            out.append("| {} | {} | {} ({}) | {} | {} | {} | {} | {} | {} | {} |".format(
                method, scene, int(b["contacts"]), int(b["engine_contacts"]), fmt(b["cpu_time"]),
                fmt(b.get("solver_ms")), fmt(b.get("natural_map")), fmt(b["residual"]),
                fmt(b.get("impulse_mismatch")), int(b["failures"]), int(b["exact"])))
    return "\n".join(out)


def time_error_chart(rows, path, scene, error_of, ylabel, title):
    """CPU time against an error, one labelled point per method on `scene` (exact zero at the floor)."""
    try:
        import matplotlib
    except ImportError:
        sys.exit("a chart needs matplotlib (Debian: python3-matplotlib; run with /usr/bin/python3)")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 6))
    for (method, s), b in rows.items():
        if s != scene or method.endswith("_gravity"):
            continue
        error = max(error_of(b), 1e-17)
        ax.scatter(b["cpu_time"], error)
        ax.annotate(method, (b["cpu_time"], error), fontsize=7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("CPU time per step (engines) or solve (Impetus), ms, median")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.axhline(1e-9, color="grey", linestyle=":", linewidth=1)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def friction_chart(rows, path, scene):
    time_error_chart(rows, path, scene, lambda b: b.get("natural_map", float("nan")),
                     "natural-map error of the engine's impulses and velocities",
                     f"bench_peers with friction, {scene}")


def chart(rows, path, scene):
    # One error axis: a method that leaves no approach but pushes the bodies apart (Baumgarte) is not
    # exact either, so the larger of residual and complementarity is drawn.
    time_error_chart(rows, path, scene,
                     lambda b: max(b["residual"], 0 if math.isnan(b["complementarity"]) else b["complementarity"]),
                     "max(residual m/s, complementarity N·m/s) after", f"bench_peers, {scene}")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("json")
    p.add_argument("--chart", help="write a PNG: CPU time against residual")
    p.add_argument("--scene", default="pyramid_20", help="scene for the chart (default pyramid_20)")
    p.add_argument("--friction", help="a second bench_peers JSON with the frictional rows (…_muX scenes)")
    p.add_argument("--friction-chart", help="write a PNG: CPU time against natural-map error")
    p.add_argument("--friction-scene", default="pyramid_10_mu0.7", help="scene for that chart")
    args = p.parse_args()
    rows = load(args.json)
    if not rows:
        sys.exit(f"{args.json}: no median aggregates (run with --benchmark_repetitions=3 "
                 "--benchmark_report_aggregates_only=true)")
    print(table(rows))
    if args.chart:
        chart(rows, args.chart, args.scene)
    friction = load(args.friction) if args.friction else {k: v for k, v in rows.items() if "_mu" in k[1]}
    if friction:
        print()
        print(friction_table(friction))
        if args.friction_chart:
            friction_chart(friction, args.friction_chart, args.friction_scene)


if __name__ == "__main__":
    main()
