#!/usr/bin/env python3
"""Table (markdown) and performance profile (chart) from a bench_fclib JSON run.

    bench_fclib --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
                --benchmark_out_format=json --benchmark_out=fclib.json
    benchmarks/fclib_report.py fclib.json [--chart fclib_profile.png]

Times are medians over the repetitions (CPU time of one solve, ms: robust on a shared machine); the counters are the median
aggregate's (they do not vary between repetitions). The performance profile is the fraction of the
problems solved to fclib's error 1e-8 (the tolerance of the published comparison of solvers) and 1e-10
within a time t, against t.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "peers"))
from report import fmt  # noqa: E402  (benchmarks/peers/report.py: numbers as the other tables print them)


def load(path):
    with open(path) as f:
        data = json.load(f)
    rows = {}
    for b in data["benchmarks"]:
        if b.get("error_occurred"):
            continue
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        rows[b["run_name"].split("/", 1)[1]] = b  # a median aggregate replaces a single run's row
    return rows


def table(rows):
    out = ["| problem | contacts | ms | ms per 100 contacts | error (fclib) | iterations | sticking | sliding | ≤ 1e-8 | ≤ 1e-10 |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for name, b in rows.items():
        contacts = int(b["contacts"])
        ms = b["cpu_time"]
        out.append("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |".format(
            name, contacts, fmt(ms), fmt(100.0 * ms / max(contacts, 1)), fmt(b["error"]), int(b["iterations"]),
            int(b["sticking"]), int(b["sliding"]), "yes" if b["solved_1e8"] else "**no**",
            "yes" if b["exact"] else "**no**"))
    return "\n".join(out)


def profile(rows, path):
    try:
        import matplotlib
    except ImportError:
        sys.exit("--chart needs matplotlib (Debian: python3-matplotlib; run with /usr/bin/python3)")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5))
    n = len(rows)
    # Drawn wide then narrow: where every problem solved to 1e-8 is also solved to 1e-10, both show.
    for key, label, style in (("solved_1e8", "error ≤ 1e-8", dict(linewidth=4, alpha=0.5)),
                              ("exact", "error ≤ 1e-10", dict(linewidth=1.5))):
        times = sorted(b["cpu_time"] for b in rows.values() if b[key])
        xs, ys = [], []
        for i, t in enumerate(times):
            xs += [t, t]
            ys += [i / n, (i + 1) / n]
        if xs:
            xs.append(max(b["cpu_time"] for b in rows.values()) * 2)
            ys.append(len(times) / n)
        ax.step(xs, ys, where="post", label=label, **style)
    ax.set_xscale("log")
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("CPU time per problem (ms, median)")
    ax.set_ylabel(f"fraction of the {n} problems solved")
    ax.set_title("ledas on fclib problems: performance profile")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("json")
    parser.add_argument("--chart", help="write the performance profile (PNG) here")
    args = parser.parse_args()
    rows = load(args.json)
    if not rows:
        sys.exit(f"{args.json}: no fclib benchmark in it")
    print(table(rows))
    if args.chart:
        profile(rows, args.chart)


if __name__ == "__main__":
    main()
