#!/usr/bin/env python3
"""The stability atlas and the accuracy charts from one run of the accuracy suite.

    python3 scripts/accuracy.py SUITE.json DOCS_DIR [PEERS.json]

reads the JSON written by `bench_accuracy --out SUITE.json` (benchmarks/accuracy/README.md) and, when it
exists, the same scenarios run in Bullet, ODE and MuJoCo by `bench_accuracy_peers --out PEERS.json`
(benchmarks/peers/README.md; default: accuracy_peers.json next to SUITE.json), and writes
  DOCS_DIR/stability.md                        the atlas: scenario x method, pass/fail with its figure,
                                               and why the failing methods fail; then the peers' table
  DOCS_DIR/charts/accuracy_<group>.png/.svg    per scenario: time per step (x, log) against error
                                               (y, log), one point per method x setting (peers as extra
                                               marker shapes), Pareto front over all points
  DOCS_DIR/charts/accuracy_overview.png/.svg   the headline chart (six scenarios)
Needs matplotlib (Debian: python3-matplotlib); if the python3 on PATH lacks it, the script re-runs itself
with /usr/bin/python3.
"""
import json
import math
import os
import sys

try:
    import matplotlib
except ImportError:  # e.g. a pyenv python3 first on PATH: use the system one, which has the package
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != "/usr/bin/python3":
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    sys.exit("accuracy.py: matplotlib is missing (apt-get install python3-matplotlib)")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import ticker  # noqa: E402

RESOLVERS = ["ledas/complementary", "ledas/paper", "mirtich"]
INTEGRATORS = ["euler", "momentum", "splitting"]
COLUMNS = [("ledas/complementary", None), ("ledas/paper", None), ("mirtich", None),
           (None, "euler"), (None, "momentum"), (None, "splitting")]
COLUMN_TITLES = ["ledas complementary", "ledas paper", "mirtich (sequential)", "euler (paper's eq. 2)",
                 "momentum", "splitting"]
COLORS = {"ledas/complementary": "#1f77b4", "ledas/paper": "#ff7f0e", "mirtich": "#2ca02c"}
MARKERS = {"momentum": "o", "euler": "s", "splitting": "v"}
# Peer engines (bench_accuracy_peers): one marker shape per engine, one colour per setting.
PEER_MARKERS = {"bullet": "^", "ode": "D", "mujoco": "P"}
PEER_ENGINES = {"bullet": "Bullet", "ode": "ODE", "mujoco": "MuJoCo"}
PEER_COLORS = {"bullet/si_10": "#9467bd", "bullet/si_100": "#e377c2", "ode/quickstep_20": "#8c564b",
               "ode/worldstep": "#bcbd22", "mujoco/newton": "#17becf", "mujoco/pgs": "#7f7f7f"}
PEER_TITLES = {"bullet/si_10": "Bullet SI 10", "bullet/si_100": "Bullet SI 100",
               "ode/quickstep_20": "ODE QuickStep 20", "ode/worldstep": "ODE dWorldStep",
               "mujoco/newton": "MuJoCo Newton", "mujoco/pgs": "MuJoCo PGS"}
FLOOR = 1e-17  # an error of exactly 0 is plotted here
OVERVIEW = ["billiards", "cradle_20", "pyramid_drop_20", "box_stack_20", "pendulum_velocity", "t_handle"]

# Why a method fails a scenario: printed under the scenario only when that method fails it there.
# How the peer engines do on each scenario (by id, else by group): one honest sentence, printed under the
# scenario when bench_accuracy_peers ran it.
PEER_NOTES = {
    "two_balls":
        "Bullet's sequential impulse solves a single contact exactly (restitution √e per body, which it "
        "multiplies to the scene's e); ODE is off by 1e-7 m/s, the size of its default CFM 1e-10 "
        "(the contact is slightly soft), which fails a 1e-9 criterion; MuJoCo's shipped soft contact removes "
        "only part of the approach in one step (e = 0) and it has no coefficient of restitution (e > 0: "
        "unsupported).",
    "billiards":
        "Bullet's iterations converge to the simultaneous answer, which is symmetric (3e-12 m/s after 10 "
        "iterations, 1e-16 after 100); ODE is symmetric too but its CFM 1e-10 loses 1.6e-8 of the energy "
        "(criterion 1e-9); MuJoCo has no restitution (unsupported).",
    "cradle":
        "Every peer solves the chain's contacts together with restitution as a target velocity per contact, so "
        "where it converges it gives the simultaneous-impact answer of `ledas/complementary` (ball 1 rebounds "
        "and the rest leave together: distance 0.6 for 5 balls, 0.9 for 20), not the classic cradle; Bullet "
        "SI 10 and ODE QuickStep do not converge on 20 balls and also lose 10-22 % of the energy; MuJoCo has "
        "no restitution (unsupported).",
    "pyramid_drop":
        "Only ODE's dWorldStep (the Dantzig LCP, with the ERP 1e-6 that keeps it from giving up) comes close: "
        "1.7e-7 to 1.2e-6 m/s left, over the bound at K = 20 (CFM 1e-10 and the perturbation), and it is two "
        "orders of magnitude slower than `ledas/complementary` there; the iterative solvers leave approach "
        "that grows with K (Bullet SI 100 is exact up to K = 4, 0.06 m/s at K = 20; SI 10 and ODE QuickStep "
        "0.25-0.35 m/s), and MuJoCo's soft contacts absorb only about 8 % of the approach in one step by "
        "design (0.91-0.92 m/s left on every K).",
    "figure2":
        "ODE's dWorldStep stops the plank and lands on the minimum-norm impulses (1.6e-9: its CFM picks the "
        "smallest of the equivalent distributions); Bullet SI and ODE QuickStep stop the plank but share the "
        "impulse among the four corners by their sweep order (25 % and 46 % from the minimum-norm one); "
        "MuJoCo spreads it evenly (the minimum-norm one, by symmetry) but its soft contact leaves the plank "
        "moving at 0.9 m/s after the step.",
    "pyramid_walls":
        "ODE's dWorldStep holds the squeezed pyramid (top sphere 0.5 mm off, no jitter); Bullet SI and ODE QuickStep keep it up but jittering (0.04-0.16 J at rest) and 4-8 mm "
        "deep, the steady state of their Baumgarte correction; MuJoCo's soft contacts let the frictionless "
        "pyramid collapse (the top sphere ends about 40 m away, still sliding).",
    "box_stack_settle":
        "ODE's dWorldStep settles the five boxes exactly (3e-10 m); Bullet SI 100 settles them, but the top "
        "box ends 3.5 mm from its rest position (1.3 cm deep on landing); Bullet SI 10, ODE QuickStep and both "
        "MuJoCo solvers let the frictionless stack topple (the top box ends tens of metres away).",
    "box_stack":
        "Only ODE's dWorldStep keeps the frictionless stacks standing at every height (0.1-0.4 mm: the initial "
        "overlaps pushed out); the iterative solvers (Bullet SI, ODE QuickStep, MuJoCo PGS) share each face's "
        "impulse unevenly among its four corners, the boxes tilt and, with nothing to hold them sideways, "
        "slide apart; MuJoCo Newton keeps 10 and 20 boxes up but 5-11 mm deep in every contact (soft by "
        "design: the stack sinks 2.6 and 11 cm) and loses the 40-box stack, while PGS even throws the 10-box "
        "stack apart (its top box leaves upward at 4 m/s after 0.3 s).",
    "mass_ratio":
        "ODE's dWorldStep holds all three ratios; Bullet SI and ODE QuickStep let the heavy box end on the "
        "ground (through or beside the light one, a drift of about 1 m) and leave even the light-on-heavy box "
        "1.3-27 mm low; MuJoCo passes the light-on-heavy pair with both solvers (0.8 mm low), while Newton "
        "sinks a heavy box 4 cm (100:1) and 41 cm (1000:1) into its soft contact and PGS lets it reach the "
        "ground.",
    "pendulum":
        "The peers have one joint model each (so the position- and velocity-level rows hold the same runs): "
        "at 1/100 s every peer ends within the criterion (0.9-2.9 mm) but the gap reaches 2.4 cm during the "
        "swing, since Bullet's and ODE's velocity-level joints are corrected by Baumgarte/ERP only and "
        "MuJoCo's `connect` is soft (its gap stays at 6-8 mm at the finer steps), where the "
        "position-level joint of Impetus stays at 1e-10 m.",
    "t_handle":
        "Each engine's own integrator drifts at first order in dt: over 20 s at 1/1000 s the angular momentum "
        "by 0.9 % (Bullet, MuJoCo) and 1.4 % (ODE), the energy by 1.7-3 %, 4-10 times more at 1/100 s; none "
        "keeps L to 1e-6 as the `momentum` integrator does by construction.",
    "friction_slope_slide":
        "Only ODE's dWorldStep (the Dantzig LCP; friction bounded by μ times the normal force through "
        "dContactApprox1) slides the box at the closed form (5e-11 m/s, its CFM); ODE QuickStep ends 2e-5 to 0.06 "
        "m/s off, differently from run to run at the same step (it reorders its rows at random from a seed that "
        "carries over between worlds); Bullet's box ends 13 % (1/1000 s) to 45 % (1/60 s) slower than Coulomb's "
        "law, turning and drifting sideways (one friction row per corner, each along that corner's own slip); "
        "MuJoCo's soft friction is off by 0.02-0.15 m/s.",
    "friction_slope_stick":
        "Every peer lets the box that should stick creep. ODE's dWorldStep moves it 1.9e-6 m at 1/1000 s and "
        "5e-4 m at 1/60 s, of the size of g dt² (one step before its contact exists: ODE makes a contact "
        "only once the box sinks into the slope), then holds it; Bullet creeps 1.5e-5 m (1/1000 s) to 4 mm "
        "(1/60 s), ODE QuickStep 0.5-9 mm, and MuJoCo's regularized friction lets the box slide on steadily "
        "(9.5-15 mm in 5 s with both solvers).",
    "friction_kane_rod":
        "Bullet (10 or 100 iterations) and ODE (QuickStep and dWorldStep) all leave the rod with 37 % more "
        "kinetic energy than it came with: each targets a normal rebound velocity of −e v_n⁻ at the contact "
        "while friction acts there too, Kane's paradox; MuJoCo has no restitution coefficient (unsupported).",
    "friction_painleve_rod":
        "At the reference step (1/1000 s) only Bullet SI 100 keeps the total energy from rising: Bullet SI 10 "
        "and MuJoCo gain 1.7-1.8e-5 of it (nothing at the coarser steps), and ODE gains at every step size "
        "(4.6-5.9e-6 at 1/1000 s, 3.8-5.2e-4 at 1/60 s). No engine blows up: the cases Coulomb's law with forces "
        "cannot answer are answered at the velocity level by every engine.",
    "friction_slope_diagonal":
        "The isotropy test: ODE's box does not move at all (0.66 m/s short, with dWorldStep and QuickStep), "
        "since each of its two friction directions, along x and y, is bounded by μ N separately and the "
        "diagonal pull (3.47 N per axis) stays under μ N cos 30° = 4.25 N in each, although its length "
        "(4.9 N) is over Coulomb's bound; Bullet, whose friction row follows the slip, comes within 3.5e-5 "
        "m/s with 100 iterations at 1/1000 s (1.2e-3 with 10, 0.02-0.05 at coarser steps); MuJoCo's soft "
        "friction is 0.03-0.3 m/s off.",
    "friction_ramp":
        "ODE's dWorldStep meets every box's closed form at 1/240 and 1/1000 s (1.2e-10 m/s; 1.5e-4 at 1/60 s); "
        "QuickStep is 1.5-5.6e-3 m/s off and Bullet 0.13-0.74 m/s (its boxes slide too slowly, as on the "
        "single slope); MuJoCo refuses the scene, whose boxes have different μ (it would give each contact "
        "the larger one).",
    "friction_stack_10":
        "Only ODE's dWorldStep keeps the top box within 1 mm, at 1/240 s (0.5 mm; 5-55 mm at the coarser "
        "steps, with an LCP failure message); Bullet, ODE QuickStep and MuJoCo Newton leave it 6-14 mm off "
        "even at 1/240 s, and MuJoCo PGS throws the stack over (10 m, with constraint-buffer warnings).",
    "friction_sphere_roll":
        "A single contact is easy: Bullet and ODE reach 5/7 v0 at rounding level with μ translated exactly "
        "(`tests/peers` checks the sliding phase too); MuJoCo's soft contact keeps a slip of 8e-4 m/s at "
        "1/1000 s (6e-3 at 1/60).",
    "friction_card_house":
        "ODE's dWorldStep keeps the house standing at 1/240 s (the plank 0.6 mm off; 1.3 and 5.4 mm at 1/120 "
        "and 1/60 s, after one LCP failure message); at the finer steps ODE QuickStep and MuJoCo Newton let the "
        "plank slip about 2 cm and MuJoCo PGS 9-11 mm, and at 1/60 s all three lose the house (0.17-0.9 m); "
        "under Bullet SI (10 or 100 iterations) it collapses at every step (plank 0.93-0.95 m off).",
    "friction_pyramid_10":
        "Every peer's pyramid collapses at every step size (top sphere 3.5-15 m away), although an equilibrium exists: the Baumgarte "
        "push they ship (ERP 0.2) opens the spheres' initial 5e-5 m overlaps and the pyramid comes apart. "
        "Measured aside: ODE's dWorldStep with ERP 1e-6 instead holds it (top sphere 4e-8 m off after 10 s at "
        "1/30 s, within 3e-7 m as far as the wall-time budget let the finer steps run) but takes 20 ms per step, 100 times `ledas`; with ERP 0 its LCP gives up on the resting contacts and the "
        "pyramid collapses as well.",
    "bracket":
        "Not run in any peer: the bracket is a non-convex triangle mesh (MuJoCo collides a mesh as its convex "
        "hull, Bullet needs GImpact for a moving concave mesh, ODE's trimesh is another contact model).",
}

WHY = {
    ("friction_slope_slide", "mirtich"):
        "A box face with four corner contacts gets its friction from four separate collisions, one corner "
        "at a time, and the sweep stops as soon as no corner approaches, with slip left at the others "
        "(resolution/mirtich/README.md, \"Simultaneous contacts are still sequential\"): the sliding box "
        "ends 4.4e-3 m/s off the closed form.",
    ("friction_slope_stick", "mirtich"):
        "The same four sequential corner collisions leave slip that nothing removes, so the box that should "
        "stick creeps 5.5 mm in 5 s.",
    ("friction_card_house", "mirtich"):
        "The leaning cards and the plank are held by frictional contacts that must all hold at once; one "
        "sequential collision at a time never settles them. Without a cap the sweep runs past the suite's "
        "time budget; with 100 impulses per step it hits the cap in 995 steps and the plank slides 0.9 m.",
    ("friction_slope_diagonal", "mirtich"):
        "The four sequential corner collisions of the box sliding along x, along the diagonal: 4.9e-4 m/s "
        "off the closed form at 1/1000 s, 8e-3 at 1/60 s.",
    ("friction_ramp", "mirtich"):
        "Each box's four corners share its friction one collision at a time: the sliding boxes end up to "
        "6.5e-3 m/s (1/1000 s) and 0.1 m/s (1/60 s) off their closed forms.",
    ("friction_stack_10", "mirtich"):
        "The frictional stack holds for a while but the sweep needs thousands of impulses per step (40-65 ms "
        "per step): every run stops at the 10 s wall-time budget with the top box 0.05-0.8 mm off, and with "
        "100 impulses per step the stack falls (9 m).",
    ("friction_pyramid_10", "mirtich"):
        "55 spheres held by friction in a pyramid: the sequential sweep hits its cap in 45 of 600 steps and "
        "the pyramid spreads (top sphere 7.8 m off at 1/60 s), as the frictionless stacks above creep.",
    ("billiards", "mirtich"):
        "The sequential method resolves one contact at a time. Ball 1 touches balls 2 and 3 "
        "symmetrically, but the sweep picks one contact first (the most approaching, ties to the lower "
        "index), so ball 2 takes a full elastic impulse before ball 3 is touched: the outcome depends on "
        "the order, not on the physics (paper, sec. 1). Momentum and energy are still conserved.",
    ("cradle", "ledas/complementary"):
        "Resolving every contact at once is one simultaneous impact of the whole chain: the inelastic "
        "solve gives every ball the common velocity 1/N and restitution doubles the impulse, so ball 1 "
        "rebounds at 2/N - 1 and the others leave together at 2/N. Momentum and energy are conserved, "
        "but it is not the classic cradle, which is a sequence of two-ball collisions (the paper's "
        "round-by-round mode and the sequential method give it).",
    ("pyramid_drop", "mirtich"):
        "An inelastic pyramid is a chain of coupled contacts; single impulses converge like Gauss-Seidel "
        "on it, so the number needed grows quickly with K and the sweep stops at its cap "
        "(`max_impulses`, default max(10 000, 100 x contacts)) with contacts still approaching.",
    ("pyramid_drop", "ledas/paper"):
        "The paper's round-by-round mode only lets approaching contacts in: spheres that move together "
        "do not approach, so the impulse travels down the pyramid one layer per round. With a small "
        "`max_rounds` it stops before the last layer has been reached.",
    ("pyramid_drop", "ledas/complementary"):
        "Capping the active-set iterations (`max_rounds`) stops the exact solve before every contact's "
        "sign is settled.",
    ("figure2", "mirtich"):
        "The four corner contacts of the flat face are redundant (the matrix A has rank 3). The "
        "sequential sweep spreads the impulse by the order in which it meets the corners, not by any "
        "principle, so the impulses are far from the minimum-norm ones, although the plank does stop.",
    ("pyramid_walls", "*"):
        "The walls squeeze the bottom row, so the contact set is singular and its position-correction "
        "targets can conflict; a solver that cycles there runs each step to its cap `max_rounds` (10^6 "
        "singular solves: minutes per step, seen during development of both ledas modes: `impetus run "
        "assets/scenes/accuracy_pyramid_walls.yaml --steps 240`, and `--steps 5 --set "
        "modules.resolver.mode=paper`). With a small cap the steps end but the pyramid creeps.",
    ("resting", "mirtich"):
        "Sequential impulses on many coupled resting contacts need many sweeps every step; the order of "
        "single impulses leaves small spins and sideways velocities that the frictionless contacts never "
        "remove, so the bodies creep and keep jittering.",
    ("resting", "ledas/paper"):
        "In the paper's mode contacts enter round by round: resting bodies all move down together under "
        "gravity, so only the bottom contacts approach at first and every step takes one round per layer, "
        "each a (singular, minimum-norm) solve. Pulling impulses are applied as the paper does.",
    ("resting", "euler"):
        "The resting scenes barely rotate, so the integrator is rarely the cause; see the resolver column.",
    ("box_stack", "mirtich"):
        "Every step the sweep hits its cap of single impulses (the stack is a long chain of coupled "
        "contacts) and leaves some approach, plus small spins from the order of the impulses; without "
        "friction nothing removes them and the stack slides apart or sinks.",
    ("box_stack", "ledas/paper"):
        "The paper's mode takes one round per layer of the stack in every step (the bodies above the "
        "lowest approaching contact move together and do not approach), each a minimum-norm solve of a "
        "singular system: the run is too slow to finish within its budget, and with a cap it stops early.",
    ("mass_ratio", "mirtich"):
        "Two coupled contacts under a heavy box converge by the factor m_top / (m_top + m_bottom) per "
        "sweep (100/101, 1000/1001): the sweep stops at its cap long before the contacts are resolved.",
    ("mass_ratio", "ledas/paper"):
        "Round by round, the heavy box's contact only enters after the lower one has been resolved; "
        "pulling impulses and the rounds cap leave the pair unresolved.",
    ("pendulum", "mirtich"):
        "The sequential baseline has no joints: it refuses constraints (the world is not built).",
    ("pendulum_velocity", "*"):
        "At velocity level a joint only zeroes the relative velocity of the joined points; the rotation "
        "step is not linear in the angular velocity, so each step leaves a small separation that nothing "
        "removes: the gap grows steadily, the more so the larger the step (paper, sec. 4). The position "
        "level asks for the points to coincide after the step and does not drift.",
    ("t_handle", "euler"):
        "The paper's eq. 2 updates the angular velocity from the torque and otherwise keeps it constant in "
        "the world frame: the gyroscopic term is missing, so a torque-free body spinning about anything "
        "but a principal axis turns steadily about a fixed axis instead of tumbling, and its angular "
        "momentum vector drifts by a fixed amount that no step size removes.",
    ("t_handle", "momentum"):
        "The `momentum` integrator keeps L exactly but its explicit rotation step lets the kinetic energy "
        "grow at first order in dt; at coarse steps the growth exceeds the bound.",
    ("t_handle", "splitting"):
        "The `splitting` integrator turns the body by exact rotations about its principal axes, so L is kept "
        "to rounding and the energy error is second order and bounded: it oscillates instead of growing.",
    ("bracket", "*"):
        "Energy rises when the position correction lifts a penetrating body (it adds potential energy, "
        "not kinetic) or when a coarse step lets the mesh sink deep before the contact is found.",
}

# Why a method that passes at the reference step fails at other swept steps (printed when it does).
DT_NOTES = {
    "bracket_bounce":
        "At coarse steps (1/100 s and above) the total energy at the step ends rises by 0.2 % (1/100 s) to "
        "1.3-2.6 % (1/30 s) around the bounces. This is the same whether or not the bracket sinks in: the "
        "detector's speculative contacts now catch the landing a step ahead (penetration 0 in most runs, "
        "where it used to be 2-5 cm), and the rise was 0.2 % at 1/100 s before as well. It is the "
        "first-order step around an impact that happens inside it, for every method: the step, not the "
        "resolver.",
    "t_handle":
        "`momentum` conserves L at every step but its kinetic energy grows at first order in dt while the "
        "handle flips: +3 % over 20 s at 1/1000 s, tens of per cent at 1/250 s and more than doubled at "
        "1/30 s. An energy-conserving rotation step would need an implicit (midpoint) update.",
    "box_stack_settle":
        "At 1/30 s the boxes land 6 cm deep (v dt past the 1 mm margin) and the correction pushes them "
        "apart over several steps; the top box ends 2 mm off. The sequential method drifts at every "
        "step size (table above), most at the coarsest and the finest steps.",
    "pyramid_walls":
        "The sequential method jitters at every step size: its rest kinetic energy never falls below "
        "the bound.",
}


def md(text):
    """Text safe inside a Markdown table cell."""
    return text.replace("|", "\\|")


def fmt(x):
    if x is None:
        return "-"
    if x == 0:
        return "0"
    if isinstance(x, float) and (math.isnan(x) or math.isinf(x)):
        return str(x)
    return "%.2g" % x


def fmt_time(t):
    if t is None or t <= 0:
        return "-"
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6)):
        if t >= scale:
            return "%.3g %s" % (t / scale, unit)
    return "%.3g ns" % (t / 1e-9)


def default_run(scenario, method, integrator, runs=None):
    """The run the atlas judges: the method at the reference step, default caps."""
    for r in scenario["runs"] if runs is None else runs:
        if r["method"] != method or r["integrator"] != integrator or r["cap"] is not None:
            continue
        if scenario["kind"] == "simulation" and not math.isclose(r["dt"], scenario["reference_dt"]):
            continue
        return r
    return None


def failing_measures(scenario, run):
    bounds = scenario["bounds"]
    return [k for k, b in bounds.items() if run["errors"].get(k) is None or not run["errors"][k] <= b]


def dt_summary(scenario, method, integrator, runs=None):
    """Which steps the method passes at (default caps), e.g. 'dt <= 1/120'."""
    if scenario["kind"] != "simulation":
        return ""
    runs = [r for r in (scenario["runs"] if runs is None else runs)
            if r["method"] == method and r["integrator"] == integrator
            and r["cap"] is None and r["status"] != "unsupported"]
    if len(runs) < 2:
        return ""
    runs.sort(key=lambda r: -r["dt"])
    passing = [r for r in runs if r["pass"]]
    if len(passing) == len(runs):
        return "every dt"
    if not passing:
        return "no dt"
    largest = max(passing, key=lambda r: r["dt"])
    if all(r["pass"] for r in runs if r["dt"] <= largest["dt"]):
        return "dt ≤ " + largest["dt_label"]
    return "dt " + ", ".join(r["dt_label"] for r in passing)


def cell(scenario, method, integrator, runs=None):
    run = default_run(scenario, method, integrator, runs)
    if run is None:
        return "—"
    if run["status"] == "unsupported":
        return "n/a (unsupported)"
    if run["status"] in ("error", "hung"):
        return "⚠ %s" % run["status"]
    primary = scenario["primary"]
    if run["pass"]:
        text = "✅ %s" % fmt(run["errors"].get(primary))
    else:
        bad = failing_measures(scenario, run)
        shown = primary if primary in bad or not bad else bad[0]
        label = "" if shown == primary else shown.replace("_", " ") + " "
        mark = "⏱" if run["status"] == "budget" else "❌"
        text = "%s %s%s" % (mark, label, fmt(run["errors"].get(shown)))
        if run["status"] == "budget":
            text += " (stopped at %.3g s)" % run["simulated_s"]
    hits = run["counters"]["non_converged"]
    if run.get("peer"):  # an engine's own failure reports (ODE LCP messages, MuJoCo buffer warnings)
        if hits:
            text += " · %d solver failure%s reported" % (hits, "s" if hits > 1 else "")
    elif hits and scenario["kind"] == "simulation":
        text += " · cap hit in %d of %d steps" % (hits, run["steps"]) if hits <= run["steps"] else \
            " · cap hit %d times" % hits
    elif hits:
        text += " · cap hit"
    summary = dt_summary(scenario, method, integrator, runs)
    return text + (" · " + summary if summary else "")


def column_run(scenario, column):
    method, integrator = column
    if method is None:  # an integrator column: judged with the reference resolver
        if scenario["kind"] == "impact":
            return None, None
        method = scenario["resolvers"][0]
    return method, integrator or "momentum"


def atlas(suite):
    lines = []
    out = lines.append
    out("# Stability atlas")
    out("")
    out("Generated by `scripts/accuracy.py` from one run of the accuracy suite (`bench_accuracy%s`, %s, "
        "%s build, %d cores; every run's data in `docs/data/accuracy.json`%s). Do not edit by hand: "
        "`bench_accuracy --out docs/data/accuracy.json%s && python3 scripts/accuracy.py "
        "docs/data/accuracy.json docs`." % (
            " --quick" if suite["quick"] else "", suite["generated_utc"][:10], suite["build_type"], suite["cores"],
            ", the peers' in `docs/data/accuracy_peers.json`" if suite.get("peers") else "",
            " && bench_accuracy_peers --out docs/data/accuracy_peers.json" if suite.get("peers") else ""))
    out("")
    out("Each cell judges one method against the scenario's criterion (below the table) at the scenario's "
        "reference setting: the resolver columns with the `momentum` integrator, the integrator columns "
        "with `ledas` (complementary), both at the reference time step and default iteration caps. The "
        "figure is the scenario's main error (or the measure that failed). For simulations, `· dt ≤ …` says "
        "at which of the swept time steps the method passes. ✅ pass, ❌ fail, ⏱ stopped at the wall-time "
        "budget of %g s per run (too slow; the figure is over the part simulated), ⚠ the run failed, — "
        "not applicable (an impact is one resolution: no integrator, no time step). The charts "
        "(`docs/charts/accuracy_*.svg`) show every setting: time per step against error, Pareto front "
        "marked." % suite["budget_s"])
    out("")
    out("| scenario | criterion | " + " | ".join(COLUMN_TITLES) + " |")
    out("|---|---|" + "---|" * len(COLUMNS))
    for s in suite["scenarios"]:
        cells = []
        for column in COLUMNS:
            method, integrator = column_run(s, column)
            cells.append("—" if method is None or method not in s["resolvers"] else cell(s, method, integrator))
        ref = " (dt %s)" % s["reference_dt_label"] if s["kind"] == "simulation" else ""
        out("| [%s](#%s)%s | %s | %s |" % (s["title"], s["id"].replace(".", ""), ref, md(s["criterion"]),
                                           " | ".join(cells)))
    out("")
    if suite.get("peers"):
        lines.extend(peer_table(suite))
    for s in suite["scenarios"]:
        out("## %s" % s["id"])
        out("")
        out("**%s.** Scene `%s`%s. Measures: %s. Criterion: %s. Chart: "
            "[`accuracy_%s.svg`](charts/accuracy_%s.svg)." % (
                s["title"], s["scene"],
                (" with `--set " + "`, `--set ".join(s["overrides"]) + "`") if s["overrides"] else "",
                s["measures"], md(s["criterion"]), s["group"], s["group"]))
        out("")
        errors = list(s["errors"].keys())
        out("| method | integrator | dt | cap | status | time/step | rounds/step (max) | cap hits%s | "
            % (" (engines: failures reported)" if s.get("peer_runs") else "") + " | ".join(errors) + " | pass |")
        out("|---|---|---|---|---|---|---|---|" + "---|" * len(errors) + "---|")
        unsupported = set()
        for r in s["runs"]:
            if r["status"] == "unsupported":  # one row says it; the method refuses the scene at any setting
                if r["method"] in unsupported:
                    continue
                unsupported.add(r["method"])
                out("| %s | any | any | any | unsupported: %s |%s" % (
                    r["method"], md(r["message"].split(": ")[-1]), " |" * (4 + len(errors))))
                continue
            cap = "%s=%d" % (r["cap_option"], r["cap"]) if r["cap"] else "default"
            out("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                r["method"], r["integrator"] if s["kind"] == "simulation" else "—", r["dt_label"] or "—", cap,
                r["status"], fmt_time(r["time_per_step_s"]), r["counters"]["max_rounds_per_step"],
                r["counters"]["non_converged"], " | ".join(fmt(r["errors"].get(e)) for e in errors), "✅" if r["pass"] else "❌"))
        for r in s.get("peer_runs", []):
            if r["status"] == "unsupported":  # at every time step
                out("| %s | engine's own | any | — | unsupported: %s |%s" % (
                    r["method"], md(r["message"].split(": ", 1)[-1]), " |" * (4 + len(errors))))
                continue
            out("| %s | engine's own | %s | — | %s | %s | — | %s | %s | %s |" % (
                r["method"], r["dt_label"] or "—", r["status"], fmt_time(r["time_per_step_s"]),
                r["counters"]["non_converged"] or "—", " | ".join(fmt(r["errors"].get(e)) for e in errors),
                "✅" if r["pass"] else "❌"))
        out("")
        failing = failing_columns(s)
        if failing:
            out("**Why the failing methods fail.**")
            out("")
            for name, note in failing:
                text = WHY.get((s["id"], name)) or WHY.get((s["group"], name)) or WHY.get((s["id"], "*")) \
                    or WHY.get((s["group"], "*"))
                out("- *%s*%s: %s" % (name, note, text or "no explanation recorded yet; see the table above."))
            out("")
        else:
            out("Every method passes at its reference setting.")
            out("")
        if s.get("peer_runs"):
            note = PEER_NOTES.get(s["id"]) or PEER_NOTES.get(s["group"])
            out("**Peers** (%s): %s" % (peer_verdict(s), note or "no comment recorded yet; see the rows above."))
            out("")
        off_reference = [r for r in s["runs"] if s["kind"] == "simulation" and r["cap"] is None and not r["pass"]
                         and r["status"] == "ok" and not math.isclose(r["dt"], s["reference_dt"])]
        if off_reference and s["id"] in DT_NOTES:
            out("**At other time steps** (%s fail): %s" % (
                ", ".join(sorted({"%s %s at %s" % (r["method"], r["integrator"], r["dt_label"])
                                  for r in off_reference})), DT_NOTES[s["id"]]))
            out("")
    return "\n".join(lines) + "\n"


def peer_labels(suite):
    """The peer settings of the peers' run, Bullet, ODE, MuJoCo first (PEER_COLORS order)."""
    labels = list(suite["peers"].get("settings", {}).keys())
    return [label for label in PEER_COLORS if label in labels] + sorted(set(labels) - set(PEER_COLORS))


def peer_verdict(s):
    """'Bullet SI 10 ✅, ODE dWorldStep ❌, …' at the reference setting."""
    parts = []
    for r in s["peer_runs"]:
        if s["kind"] == "simulation" and r["status"] != "unsupported" and \
                not math.isclose(r["dt"], s["reference_dt"]):
            continue
        title = PEER_TITLES.get(r["method"], r["method"])
        mark = "n/a" if r["status"] == "unsupported" else ("✅" if r["pass"] else "❌")
        parts.append("%s %s" % (title, mark))
    return ", ".join(parts)


def peer_table(suite):
    """The atlas's second table: every scenario run in Bullet, ODE and MuJoCo."""
    peers = suite["peers"]
    labels = peer_labels(suite)
    lines = []
    out = lines.append
    out("## Peers: Bullet, ODE and MuJoCo on the same scenarios")
    out("")
    out("From `docs/data/accuracy_peers.json` (`bench_accuracy_peers%s`, %s; %s). Each scenario's scene is "
        "loaded and built by Impetus exactly as in the suite, then translated into the engine: the same bodies, "
        "masses, inertias, shapes, initial state and joints, the scene's restitution and friction (each "
        "engine's own friction law with the scene's μ: Bullet's one row per point, ODE's pyramid scaled by the "
        "normal force, MuJoCo's elliptic cone). The engine "
        "steps it with the same time step for the same duration, and the suite's own probes judge the engine's "
        "body states (positions, rotations, velocities; contacts found by the Impetus detector at those "
        "positions), never what the engine reports about itself. Impacts are the suite's one-resolution "
        "experiment: one engine step from the initial state with gravity off, its velocities judged at the "
        "initial positions. Time per step is the median wall time of the engine's whole step (its own collision "
        "detection, solve and integration), where the Impetus impact cells time detection + resolution. Cells "
        "read as in the table above, at the reference time step; `· n solver failures reported` counts the "
        "engine's own reports (ODE's LCP messages, MuJoCo's buffer warnings). Per-scenario rows and one sentence "
        "on each follow in the scenario sections; the charts carry the peers as extra marker shapes. "
        "`benchmarks/peers/README.md` documents the translation." % (
            " --quick" if peers.get("quick") else "", peers.get("generated_utc", "?")[:10],
            ", ".join(peers.get("engines", []))))
    out("")
    for label in labels:
        out("- `%s` (%s): %s." % (label, PEER_TITLES.get(label, label), peers["settings"][label]))
    out("")
    out("| scenario | " + " | ".join(PEER_TITLES.get(label, label) for label in labels) + " |")
    out("|---|" + "---|" * len(labels))
    for s in suite["scenarios"]:
        runs = s.get("peer_runs", [])
        cells = []
        for label in labels:
            unsupported = next((r for r in runs if r["method"] == label and r["status"] == "unsupported"), None)
            cells.append("n/a (unsupported)" if unsupported else cell(s, label, "engine", runs))
        ref = " (dt %s)" % s["reference_dt_label"] if s["kind"] == "simulation" else ""
        out("| [%s](#%s)%s | %s |" % (s["title"], s["id"].replace(".", ""), ref, " | ".join(cells)))
    out("")
    return lines


def failing_columns(s):
    """(name, note) for each column whose method fails here: at its reference setting, or only with a cap."""
    out = []
    for column in COLUMNS:
        method, integrator = column_run(s, column)
        if method is None or method not in s["resolvers"]:
            continue
        name = column[0] or column[1]
        if any(n == name for n, _ in out):
            continue
        run = default_run(s, method, integrator)
        if run is not None and run["status"] != "unsupported" and not run["pass"]:
            out.append((name, ""))
        elif run is not None and run["status"] == "unsupported":
            out.append((name, " (unsupported)"))
        elif column[0]:
            capped = sorted({r["cap"] for r in s["runs"] if r["method"] == method and r["cap"] and not r["pass"]})
            if capped:
                option = next(r["cap_option"] for r in s["runs"] if r["method"] == method)
                out.append((name, " (only with a cap: %s = %s)" % (option, ", ".join(str(c) for c in capped))))
    return out


def pareto(points):
    """Indices of the points no other point beats in both time and error."""
    front = []
    best = math.inf
    for i in sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1])):
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def plot_scenario(ax, s, compact=False):
    xs, ys = [], []
    for r in s["runs"] + s.get("peer_runs", []):
        if r["status"] not in ("ok", "budget") or not r["time_per_step_s"]:
            continue
        y = r["errors"].get(s["primary"])
        if y is None:
            continue
        x, y = r["time_per_step_s"], max(y, FLOOR)
        xs.append(x)
        ys.append(y)
        filled = r["cap"] is None and r["status"] == "ok"
        if r.get("peer"):
            color = PEER_COLORS.get(r["method"], "gray")
            marker = PEER_MARKERS.get(r["engine"], "x")
        else:
            color = COLORS.get(r["method"], "gray")
            marker = MARKERS.get(r["integrator"], "o")
        ax.scatter([x], [y], marker=marker, s=30 if compact else 40,
                   facecolors=color if filled else "none", edgecolors=color, linewidths=1.2, zorder=3)
        if not compact and (r["dt_label"] or r["cap"]):
            label = r["dt_label"] + (" cap %d" % r["cap"] if r["cap"] else "")
            ax.annotate(label.strip(), (x, y), textcoords="offset points", xytext=(4, 3), fontsize=6,
                        color="#555555")
    if xs:
        front = pareto(list(zip(xs, ys)))
        fx = [xs[i] for i in front]
        fy = [ys[i] for i in front]
        ax.step(fx, fy, where="post", color="black", linewidth=0.9, linestyle="--", zorder=2)
        ax.scatter(fx, fy, s=110 if not compact else 80, facecolors="none", edgecolors="black",
                   linewidths=0.8, zorder=4)
    bound = s["bounds"].get(s["primary"])
    if bound:
        ax.axhline(bound, color="#d62728", linewidth=0.8, linestyle=":", zorder=1)
    if any(y <= FLOOR for y in ys):
        ax.axhline(FLOOR, color="#999999", linewidth=0.6, linestyle="-.", zorder=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    if xs:
        widen(ax.set_xlim, min(xs) / 1.5, max(xs) * 1.5, 10)
        levels = ys + ([bound] if bound else [])
        widen(ax.set_ylim, min(levels) / 10, max(levels) * 10, 1e3)
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(ticker.LogLocator(base=10, numticks=8))
        axis.set_minor_locator(ticker.LogLocator(base=10, subs=(2, 5), numticks=8))
        axis.set_minor_formatter(ticker.NullFormatter())
    ax.set_title(s["title"] if not compact else s["id"], fontsize=8 if compact else 9)
    ax.set_xlabel("wall time per step (s)", fontsize=7 if compact else 8)
    ax.set_ylabel(s["primary"].replace("_", " "), fontsize=7 if compact else 8)
    ax.tick_params(labelsize=6 if compact else 7)
    ax.grid(True, which="major", linewidth=0.3, alpha=0.5)


def widen(set_limits, lo, hi, ratio):
    """Log-axis limits spanning at least `ratio`, centred on the data."""
    if hi / lo < ratio:
        mid = math.sqrt(lo * hi)
        lo, hi = mid / math.sqrt(ratio), mid * math.sqrt(ratio)
    set_limits(lo, hi)


def legend(fig, peers=()):
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], marker="o", linestyle="", color=c, label=m) for m, c in COLORS.items()]
    handles += [Line2D([], [], marker=MARKERS[i], linestyle="", markerfacecolor="none", color="black",
                       label="integrator " + i) for i in INTEGRATORS]
    handles += [Line2D([], [], marker=PEER_MARKERS[label.split("/")[0]], linestyle="",
                       color=PEER_COLORS.get(label, "gray"), label=PEER_TITLES.get(label, label)) for label in peers]
    handles += [Line2D([], [], marker="o", linestyle="", markerfacecolor="none", color="gray",
                       label="capped / stopped at budget"),
                Line2D([], [], linestyle="--", color="black", label="Pareto front"),
                Line2D([], [], linestyle=":", color="#d62728", label="criterion"),
                Line2D([], [], linestyle="-.", color="#999999", label="error 0 (drawn at 1e-17)")]
    fig.legend(handles=handles, loc="lower center", ncol=6 if peers else 5, fontsize=7, frameon=False)


def save(fig, path):
    fig.savefig(path + ".png", dpi=110, metadata={"Software": None})
    fig.savefig(path + ".svg", metadata={"Date": None, "Creator": None})
    plt.close(fig)


def peers_in(scenarios):
    """The peer settings with at least one point on these scenarios' charts, in PEER_COLORS order."""
    seen = {r["method"] for s in scenarios for r in s.get("peer_runs", []) if r["status"] in ("ok", "budget")}
    return [label for label in PEER_COLORS if label in seen] + sorted(seen - set(PEER_COLORS))


def legend_space(fig, peers):
    """Fraction of the figure's height below the plots for the legend (rows of 5 or 6 entries)."""
    entries = 9 + len(peers)
    rows = (entries + (6 if peers else 5) - 1) // (6 if peers else 5)
    return min(0.4, (0.2 + 0.2 * rows) / fig.get_size_inches()[1])


def charts(suite, chart_dir):
    os.makedirs(chart_dir, exist_ok=True)
    groups = {}
    for s in suite["scenarios"]:
        groups.setdefault(s["group"], []).append(s)
    written = []
    for group, members in groups.items():
        n = len(members)
        cols = min(3, n)
        rows = (n + cols - 1) // cols
        fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.6 * rows + 0.7), squeeze=False)
        for ax, s in zip(axes.flat, members):
            plot_scenario(ax, s)
        for ax in list(axes.flat)[n:]:
            ax.axis("off")
        peers = peers_in(members)
        legend(fig, peers)
        fig.tight_layout(rect=(0, legend_space(fig, peers), 1, 1))
        path = os.path.join(chart_dir, "accuracy_" + group)
        save(fig, path)
        written.append(path)
    by_id = {s["id"]: s for s in suite["scenarios"]}
    chosen = [by_id[i] for i in OVERVIEW if i in by_id]
    if chosen:
        fig, axes = plt.subplots(2, 3, figsize=(12, 7.2), squeeze=False)
        for ax, s in zip(axes.flat, chosen):
            plot_scenario(ax, s, compact=True)
        for ax in list(axes.flat)[len(chosen):]:
            ax.axis("off")
        peers = peers_in(chosen)
        fig.suptitle("Impetus%s: speed against accuracy (time per step vs error, log-log; Pareto front dashed)"
                     % (" and its peers" if peers else ""), fontsize=10)
        legend(fig, peers)
        fig.tight_layout(rect=(0, legend_space(fig, peers), 1, 0.97))
        path = os.path.join(chart_dir, "accuracy_overview")
        save(fig, path)
        written.append(path)
    return written


def merge_peers(suite, peers):
    """The peers' runs as `peer_runs` of the suite's scenarios with the same id; their header as `peers`."""
    by_id = {s["id"]: s for s in peers["scenarios"]}
    for s in suite["scenarios"]:
        if s["id"] in by_id:
            s["peer_runs"] = by_id[s["id"]]["runs"]
    suite["peers"] = {k: v for k, v in peers.items() if k != "scenarios"}


def main(argv):
    if len(argv) not in (3, 4):
        sys.exit("usage: accuracy.py SUITE.json DOCS_DIR [PEERS.json]")
    with open(argv[1]) as f:
        suite = json.load(f)
    peers_path = argv[3] if len(argv) == 4 else os.path.join(os.path.dirname(argv[1]), "accuracy_peers.json")
    if os.path.exists(peers_path):
        with open(peers_path) as f:
            peers = json.load(f)
        if peers.get("quick") != suite.get("quick"):  # e.g. a full peers file left beside a quick suite
            print("accuracy.py: %s is a %s run and the suite a %s one: peers left out" % (
                peers_path, "quick" if peers.get("quick") else "full", "quick" if suite.get("quick") else "full"))
        else:
            merge_peers(suite, peers)
    elif len(argv) == 4:
        sys.exit("accuracy.py: %s not found" % peers_path)
    plt.rcParams["svg.hashsalt"] = "impetus-accuracy"
    docs = argv[2]
    os.makedirs(docs, exist_ok=True)
    with open(os.path.join(docs, "stability.md"), "w") as f:
        f.write(atlas(suite))
    written = charts(suite, os.path.join(docs, "charts"))
    print("accuracy.py: wrote %s and %d charts (png + svg) in %s%s" % (
        os.path.join(docs, "stability.md"), len(written), os.path.join(docs, "charts"),
        " with the peers of " + peers_path if suite.get("peers") else " (no peers merged)"))


if __name__ == "__main__":
    main(sys.argv)
