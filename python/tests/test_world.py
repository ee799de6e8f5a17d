"""impetus.World from Python: physics against closed forms, module swaps by override, the state in numpy
arrays and back, errors with the tool's messages, and trajectories bit-identical to `impetus run`."""
import csv
import threading

import numpy as np
import pytest

import impetus
from conftest import CLI_SCENES, SCENES, tool, tool_json


def test_free_fall_follows_the_integrators_closed_form(free_ball):
    # Symplectic Euler: v_n = v0 − g n dt, z_n = z0 − g dt² n(n+1)/2 (the velocity is updated first).
    world = impetus.World(impetus.scene_from_dict(free_ball))
    n, dt, g = 500, 0.001, 9.81
    status = world.step(n)
    assert status["ok"] and status["step"] == n and world.step_count == n
    assert world.time == pytest.approx(n * dt, abs=1e-15)
    s = world.state()
    assert s["position"][0] == pytest.approx([1.5 * n * dt, 0.0, 10.0 - g * dt * dt * n * (n + 1) / 2], abs=1e-9)
    assert s["velocity"][0] == pytest.approx([1.5, 0.0, -g * n * dt], abs=1e-9)
    m = impetus.measure(world)
    v = s["velocity"][0]
    assert m["kinetic_energy"] == pytest.approx(0.5 * 2.0 * v.dot(v), rel=1e-12)
    assert m["linear_momentum"] == pytest.approx(tuple(2.0 * v), rel=1e-12)
    assert m["contacts"] == 0


def test_a_resolver_swap_by_override_changes_only_the_resolver():
    for resolver in ("ledas", "mirtich"):
        scene = impetus.load_scene(CLI_SCENES / "drop.yaml", overrides={"modules.resolver": resolver, "dt": 0.002})
        assert scene.modules == {"integrator": "momentum", "detector": "fcl", "resolver": resolver}
        assert scene.dt == 0.002
        world = impetus.World(scene)
        world.step(1000)  # 2 s: the ball (radius 0.5, dropped from 1 m above the plane) has landed
        z = world.state()["position"][world.names.index("ball"), 2]
        assert z == pytest.approx(0.5, abs=1e-3), resolver
        assert impetus.summary(world)["modules"]["resolver"] == resolver


def test_overrides_as_set_strings_and_as_python_values_agree():
    a = impetus.load_scene(CLI_SCENES / "drop.yaml", overrides=["dt=0.004", "bodies.ball.velocity=[1, 0, 0]"])
    b = impetus.load_scene(CLI_SCENES / "drop.yaml", overrides={"dt": 0.004, "bodies.ball.velocity": np.array([1.0, 0, 0])})
    wa, wb = impetus.World(a), impetus.World(b)
    assert np.array_equal(wa.state()["velocity"], wb.state()["velocity"])
    assert wa.state()["velocity"][1, 0] == 1.0 and a.dt == b.dt == 0.004


def test_state_round_trip_leaves_the_trajectory_bit_identical():
    scene = impetus.load_scene(SCENES / "demo.yaml")
    left, right = impetus.World(scene), impetus.World(scene)
    left.step(150)
    right.step(150)
    right.set_state(right.state())  # exact: the rotation matrices travel with the quaternions
    left.step(150)
    right.step(150)
    for key, value in left.state().items():
        assert np.array_equal(value, right.state()[key]), key


def test_the_thread_count_changes_no_bit_of_the_trajectory():
    scene = impetus.load_scene(SCENES / "demo.yaml")
    one, two = impetus.World(scene), impetus.World(scene)
    one.threads, two.threads = 1, 2
    assert (one.threads, two.threads) == (1, 2)
    one.step(100)
    two.step(50)
    two.threads = 4  # between steps
    two.step(50)
    for key, value in one.state().items():
        assert np.array_equal(value, two.state()[key]), key
    for bad in (-1, 4097):
        with pytest.raises(impetus.Error, match="World.threads: must be 0"):
            one.threads = bad
    assert one.threads == 1


def test_set_state_moves_bodies_and_checks_what_it_is_given():
    world = impetus.World(impetus.load_scene(CLI_SCENES / "drop.yaml"))
    s = world.state()
    ball = world.names.index("ball")
    s["position"][ball] += [0.0, 0.0, 1.0]
    s["orientation"][ball] = [np.cos(0.25), 0.0, 0.0, np.sin(0.25)]  # half a radian about z
    del s["rotation"]
    world.set_state(s)
    after = world.state()
    assert after["position"][ball, 2] == pytest.approx(2.5, abs=1e-15)
    assert after["orientation"][ball] == pytest.approx(s["orientation"][ball], abs=1e-15)
    assert np.allclose(after["rotation"][ball], [[np.cos(0.5), -np.sin(0.5), 0], [np.sin(0.5), np.cos(0.5), 0],
                                                 [0, 0, 1]], rtol=0, atol=1e-15)

    def refused(change, message):
        t = world.state()
        change(t)
        with pytest.raises(impetus.Error, match=message):
            world.set_state(t)
        assert np.array_equal(world.state()["position"], after["position"]), "a refused state changes nothing"

    refused(lambda t: t.update(position=t["position"][:1]), r"'position' has shape \(1, 3\); this world needs \(2, 3\)")
    refused(lambda t: t.update(velocity=t["velocity"].astype(np.float32)), "'velocity' has dtype float32; it must be float64")
    refused(lambda t: t.update(velocity=t["velocity"].tolist()), "'velocity' is a list, not a numpy array")
    refused(lambda t: t["angular_velocity"].__setitem__((1, 2), np.nan), "'angular_velocity' of body 1 is not finite")
    refused(lambda t: (t.pop("rotation"), t["orientation"].__setitem__(1, [1, 1, 0, 0])),
            r"body 1 \('ball'\): its orientation quaternion has norm 1.41")
    refused(lambda t: t["orientation"].__setitem__(1, [0, 1, 0, 0]), "'orientation' and 'rotation' disagree")
    refused(lambda t: t["rotation"].__setitem__(1, 2 * np.eye(3)), "not a proper rotation matrix")
    refused(lambda t: t["velocity"].__setitem__(0, [1, 0, 0]), r"body 0 \('ground'\) is fixed and does not move")
    refused(lambda t: t.pop("position"), "no 'position' array")


def test_contacts_of_a_resting_box_carry_its_weight():
    scene = impetus.load_scene(CLI_SCENES / "resting_box.yaml")
    world = impetus.World(scene)
    world.step(60)
    c = world.contacts()
    assert len(c["a"]) == 4 and c["point"].shape == (4, 3) and c["impulse"].shape == (4,)
    assert set(c["mode"]) <= {"separate", "stick", "slide"}
    assert np.allclose(c["normal"], [0, 0, 1])
    # At rest the contacts take gravity's m g dt each step (1 kg, dt 1/60 s).
    assert c["impulse"].sum() == pytest.approx(9.81 / 60, rel=1e-6)


def test_applied_loads_act_as_forces_do():
    # A 2 kg ball pushed by 4 N along x with no gravity: x = ½ a t² at the scheme's discrete times.
    world = impetus.World(impetus.scene_from_dict({
        "dt": 0.01, "gravity": [0, 0, 0], "modules": {"integrator": "momentum", "detector": "none", "resolver": "none"},
        "bodies": [{"name": "ball", "shape": {"sphere": {"radius": 0.1}}, "mass": 2.0}]}))
    world.set_load("ball", force=[4.0, 0, 0])
    world.step(100)
    n, dt, a = 100, 0.01, 2.0
    assert world.state()["position"][0, 0] == pytest.approx(a * dt * dt * n * (n + 1) / 2, rel=1e-12)
    with pytest.raises(impetus.Error, match="no body named 'nobody'"):
        world.set_load("nobody", force=[1, 0, 0])
    with pytest.raises(impetus.Error, match="must be three finite numbers"):
        world.set_load("ball", torque=[0, float("inf"), 0])


def read_csv(path):
    with open(path, newline="") as f:
        return [row for row in csv.DictReader(f)]


def test_a_world_stepped_from_python_matches_impetus_run_bit_for_bit(tmp_path):
    out = tmp_path / "demo.csv"
    tool("run", SCENES / "demo.yaml", "--steps", 300, "--every", 50, "--out", out)
    rows = read_csv(out)
    world = impetus.World(impetus.load_scene(SCENES / "demo.yaml"))
    names = world.names
    compared = 0
    for step in range(0, 301):
        if step:
            world.step()
        if step % 50:
            continue
        s = world.state()
        for row in (r for r in rows if int(r["step"]) == step):
            i = names.index(row["body"])
            # The CSV holds shortest round-trip numbers: float() reads back the very double.
            assert float(row["time"]) == world.time
            assert [float(row[k]) for k in ("x", "y", "z")] == s["position"][i].tolist()
            assert [float(row[k]) for k in ("qw", "qx", "qy", "qz")] == s["orientation"][i].tolist()
            assert [float(row[k]) for k in ("vx", "vy", "vz")] == s["velocity"][i].tolist()
            assert [float(row[k]) for k in ("wx", "wy", "wz")] == s["angular_velocity"][i].tolist()
            compared += 1
    assert compared == 7 * len(names)


def test_run_gives_the_tools_summary():
    ours = impetus.run(CLI_SCENES / "drop.yaml", steps=800)
    theirs = tool_json("run", CLI_SCENES / "drop.yaml", "--steps", 800)
    for key in ("steps", "simulated_time_s", "energy", "momentum", "contacts_per_step", "max_penetration_m", "modules",
                "module_options", "scene"):
        assert ours[key] == theirs[key], key
    by_duration = impetus.run(CLI_SCENES / "drop.yaml", duration=0.8)
    assert by_duration["energy"] == ours["energy"]


def test_step_releases_the_gil():
    world = impetus.World(impetus.load_scene(SCENES / "demo.yaml"))
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(None)

    counter = threading.Thread(target=count)
    counter.start()
    try:
        world.step(1500)  # ~0.1 s or more of stepping; the other thread keeps counting only if the GIL is free
    finally:
        done.set()
        counter.join()
    assert len(ticks) > 1000
