"""Shared fixtures of the Python package's tests (run by ctest as `python_tests`, with PYTHONPATH at the
package in the build tree, IMPETUS_EXE the tool and IMPETUS_SOURCE_DIR the checkout)."""
import json
import os
import subprocess
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("IMPETUS_SOURCE_DIR", Path(__file__).resolve().parents[2]))
EXE = os.environ.get("IMPETUS_EXE", str(SOURCE / "build" / "bin" / "impetus"))
CLI_SCENES = SOURCE / "tests" / "cli" / "scenes"
SCENES = SOURCE / "assets" / "scenes"


def tool(*args, check=True):
    """Runs the `impetus` tool; returns (exit status, stdout, stderr)."""
    done = subprocess.run([EXE, *map(str, args)], capture_output=True, text=True, timeout=600)
    if check and done.returncode != 0:
        raise AssertionError(f"impetus {' '.join(map(str, args))} failed:\n{done.stderr}")
    return done.returncode, done.stdout, done.stderr


def tool_json(*args):
    return json.loads(tool(*args, "--json")[1])


@pytest.fixture
def free_ball():
    """A ball in free fall, no detector: x(t) of the integrator's discrete scheme is known in closed form."""
    return {
        "dt": 0.001,
        "gravity": [0, 0, -9.81],
        "modules": {"integrator": "momentum", "detector": "none", "resolver": "none"},
        "bodies": [{"name": "ball", "shape": {"sphere": {"radius": 0.1}}, "mass": 2.0,
                    "position": [0, 0, 10], "velocity": [1.5, 0, 0]}],
    }
