"""impetus.sweep: grids checked before anything runs, the same numbers serially and on LocalClusters of any
size, failures recorded, and a worker killed mid-sweep losing nothing. Clusters are bounded (one or two
single-threaded worker processes), on the loopback interface, and closed by each test."""
import json
import os
import signal

import pytest

import impetus
from impetus import sweep
from conftest import CLI_SCENES

distributed = pytest.importorskip("distributed")


def write_grid(folder, text):
    path = folder / "grid.yaml"
    path.write_text(text)
    return path


GRID = f"""
scenes: [{CLI_SCENES / 'drop.yaml'}]
overrides:
  modules.resolver: [ledas, mirtich]
  dt: [0.001, 0.002]
steps: [400]
repetitions: 2
probes:
  - {{name: ball_z, body: ball, quantity: position, component: 2}}
  - {{name: energy, quantity: kinetic_energy}}
  - {{name: steps, quantity: step_count}}
"""


def cluster(workers):
    c = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                                 dashboard_address=None, silence_logs=50)
    return c, distributed.Client(c)


def test_a_grid_is_the_cartesian_product_with_its_probes(tmp_path):
    runs = sweep.load_grid(write_grid(tmp_path, GRID))
    assert len(runs) == 2 * 2 * 1 * 2
    assert [r["id"] for r in runs] == list(range(8))
    results = sweep.run_grid(runs)
    for run, result in zip(runs, results):
        assert result["ok"], result["error"]
        assert result["overrides"] == run["overrides"] and result["steps"] == 400
        assert result["probes"]["steps"] == 400
        assert result["summary"]["modules"]["resolver"] == run["overrides"]["modules.resolver"]
        # The probe is the world's state: before the ball lands (it falls 1 m), z = 1.5 - g t²/2 roughly.
        t = 400 * run["overrides"]["dt"]
        if t < 0.45:
            assert result["probes"]["ball_z"] == pytest.approx(1.5 - 9.81 * t * t / 2, abs=0.02)
    # Repetitions of one combination give one answer.
    assert sweep.strip_timings(results[0])["summary"] == sweep.strip_timings(results[1])["summary"]


def test_serial_and_clusters_of_any_size_give_the_same_numbers(tmp_path):
    runs = sweep.load_grid(write_grid(tmp_path, GRID))
    serial = sweep.strip_timings(sweep.run_grid(runs))
    for workers in (1, 2):
        c, client = cluster(workers)
        try:
            results = sweep.run_grid(runs, client)
        finally:
            client.close()
            c.close()
        assert sweep.strip_timings(results) == serial, f"{workers} workers"
        assert all(r["worker"].startswith("tcp://127.0.0.1:") for r in results)


def test_a_failing_run_is_recorded_not_raised(tmp_path):
    grid = write_grid(tmp_path, f"""
scenes: [{CLI_SCENES / 'drop.yaml'}]
overrides: {{modules.resolver: [ledas, no_such_resolver]}}
steps: 10
""")
    results = sweep.run_grid(sweep.load_grid(grid))
    assert [r["ok"] for r in results] == [True, False]
    assert "no resolver plugin named 'no_such_resolver'" in results[1]["error"]
    assert results[1]["summary"] is None


def test_a_worker_killed_mid_sweep_loses_no_run_and_repeats_none(tmp_path):
    # Runs long enough (about 0.1-0.3 s each) that the kill lands while both workers are busy.
    grid = write_grid(tmp_path, f"""
scenes: [{CLI_SCENES.parent.parent.parent / 'assets' / 'scenes' / 'demo.yaml'}]
overrides: {{modules.resolver: [ledas, mirtich]}}
steps: 1500
repetitions: 6
probes: [{{name: ball, body: ball, quantity: position}}]
""")
    runs = sweep.load_grid(grid)
    killed = []

    class KillOnce(sweep.Progress):
        def add(self, ok):
            super().add(ok)
            if killed:
                return
            busy = [address for address, keys in client.processing().items() if keys]
            if busy:
                pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
                os.kill(pid, signal.SIGKILL)
                killed.append(busy[0])

    c, client = cluster(2)
    try:
        results = sweep.run_grid(runs, client, KillOnce(len(runs), stream=open(os.devnull, "w")))
    finally:
        client.close()
        c.close()
    assert killed, "no worker was busy to kill"
    assert [r["id"] for r in results] == [r["id"] for r in runs]  # every run, once, in order
    assert all(r["ok"] for r in results)
    assert sweep.strip_timings(results) == sweep.strip_timings(sweep.run_grid(runs))


@pytest.mark.parametrize("text, message", [
    ("scenes: [a.yaml]\nsteps: 1\nscnes: []\n", "unknown key 'scnes'; expected one of: scenes"),
    (f"scenes: [{CLI_SCENES / 'drop.yaml'}]\noverrides: {{bodies.nobody.mass: [1]}}\n", "grid.yaml: .*nobody"),
    (f"scenes: [{CLI_SCENES / 'drop.yaml'}]\nsteps: [-3]\n", "steps -3: must be a non-negative integer"),
    (f"scenes: [{CLI_SCENES / 'drop.yaml'}]\nsteps: 1\nduration: 1\n", "give 'steps' or 'duration', not both"),
    (f"scenes: [{CLI_SCENES / 'drop.yaml'}]\nprobes: [{{name: p, quantity: speed}}]\n", "unknown quantity 'speed'"),
    (f"scenes: [{CLI_SCENES / 'drop.yaml'}]\nprobes: [{{name: p, quantity: position}}]\n", "'position' needs a 'body'"),
    ("scenes: [missing.yaml]\n", "missing.yaml"),
])
def test_a_bad_grid_is_refused_before_anything_runs(tmp_path, text, message):
    with pytest.raises(sweep.GridError, match=message):
        sweep.load_grid(write_grid(tmp_path, text))


def test_an_override_the_scene_lacks_has_the_message_of_set(tmp_path):
    grid = write_grid(tmp_path, f"scenes: [{CLI_SCENES / 'drop.yaml'}]\noverrides: {{bodies.nobody.mass: [1]}}\n")
    with pytest.raises(impetus.Error) as expected:
        impetus.load_scene(CLI_SCENES / "drop.yaml", {"bodies.nobody.mass": 1})
    with pytest.raises(sweep.GridError) as raised:
        sweep.load_grid(grid)
    assert str(raised.value) == f"grid.yaml: {expected.value}"


def test_the_command_line_writes_results_and_refuses_what_it_should(tmp_path, capsys):
    grid = write_grid(tmp_path, f"scenes: [{CLI_SCENES / 'drop.yaml'}]\nsteps: 50\n")
    out = tmp_path / "results.json"
    assert sweep.main([str(grid), "--out", str(out), "--serial"]) == 0
    document = json.loads(out.read_text())
    assert document["ran_on"] == "serial" and len(document["runs"]) == 1 and document["runs"][0]["ok"]
    assert sweep.main([str(grid), "--out", str(out), "--serial"]) == 1
    assert "file exists; pass --overwrite" in capsys.readouterr().err
    assert sweep.main([str(grid), "--out", str(tmp_path / "no" / "r.json"), "--serial"]) == 1
    assert "does not exist" in capsys.readouterr().err
    # Nothing listens on port 9 of the loopback interface: refused well within the timeout.
    assert sweep.main([str(grid), "--out", str(tmp_path / "r.json"), "--scheduler", "tcp://127.0.0.1:9",
                       "--timeout", "3"]) == 1
    assert "--scheduler tcp://127.0.0.1:9: no answer within 3.0 s" in capsys.readouterr().err


def test_the_accuracy_suite_on_a_cluster_is_the_suite_run_directly(tmp_path):
    bench = sweep.default_bench()
    if not os.path.exists(bench):
        pytest.skip("bench_accuracy is built with -DIMPETUS_BUILD_BENCHMARKS=ON")
    out, direct = tmp_path / "accuracy.json", tmp_path / "direct.json"
    filters = ["--filter", "two_balls", "--filter", "billiards"]
    assert sweep.main(["--accuracy", "--quick", *filters, "--workers", "2", "--out", str(out)]) == 0
    import subprocess
    subprocess.run([bench, "--quick", *filters, "--out", str(direct)], check=True, capture_output=True)
    ours, theirs = json.loads(out.read_text()), json.loads(direct.read_text())
    assert [s["id"] for s in ours["scenarios"]] == [s["id"] for s in theirs["scenarios"]]
    assert sweep.strip_timings(ours["scenarios"]) == sweep.strip_timings(theirs["scenarios"])
    assert ours["failed"] == []
    # scripts/accuracy.py reads it as it reads bench_accuracy's own file, and writes the atlas from it.
    subprocess.run(["/usr/bin/python3", str(CLI_SCENES.parents[2] / "scripts" / "accuracy.py"), str(out), str(tmp_path)],
                   check=True, capture_output=True)
    atlas = (tmp_path / "stability.md").read_text()
    assert "two_balls_e0.5" in atlas or "Two balls head on, e = 0.5" in atlas
