"""Impetus from Python: scenes, worlds with numpy state, and the tool's reports (README.md, "Python").

    import impetus
    scene = impetus.load_scene("scene.yaml", overrides={"modules.resolver": "mirtich", "dt": 0.01})
    world = impetus.World(scene)      # modules loaded by name, as `impetus run` does
    status = world.step(1000)         # the last step's status
    s = world.state()                 # numpy arrays: position (N,3), orientation (N,4) w,x,y,z, ...
    world.set_state(s)
    impetus.resolve(scene), impetus.measure(world), impetus.plugins(), impetus.mass("part.obj", density=7800)

Errors raise impetus.Error (a ValueError) with the tool's messages: the file, line and field at fault.
"""

import json as _json
import math as _math
import os as _os
import numbers as _numbers

from ._impetus import Error, Scene, World, measure, __version__  # noqa: F401
from . import _impetus

__all__ = ["Error", "Scene", "World", "load_scene", "scene_from_dict", "resolve", "measure", "plugins", "mass",
           "run", "summary", "__version__"]


def _yaml(value):
    """A Python value as the YAML text `impetus run --set KEY=VALUE` takes for VALUE."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, _numbers.Integral):
        return str(int(value))
    if isinstance(value, _numbers.Real):
        number = float(value)
        if not _math.isfinite(number):
            return ".nan" if _math.isnan(number) else (".inf" if number > 0 else "-.inf")
        return repr(number)  # shortest text that reads back as the same double
    if isinstance(value, dict):
        return "{" + ", ".join(f"{key}: {_yaml(item)}" for key, item in value.items()) + "}"
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return _yaml(value.tolist())
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_yaml(item) for item in value) + "]"
    raise Error(f"override value {value!r}: a {type(value).__name__} has no YAML form (use a str, number, bool, "
                "list or dict)")


def _overrides(overrides):
    """{"dotted.key": value} or ["KEY=VALUE", ...] (as --set) into (key, YAML text) pairs."""
    if overrides is None:
        return []
    if isinstance(overrides, dict):
        return [(str(key), _yaml(value)) for key, value in overrides.items()]
    pairs = []
    for item in overrides:
        if isinstance(item, str):
            key, sep, value = item.partition("=")
            if not sep or not key:
                raise Error(f"--set {item}: expected KEY=VALUE")
            pairs.append((key, value))
        else:
            key, value = item
            pairs.append((str(key), _yaml(value)))
    return pairs


def load_scene(path, overrides=None):
    """Reads a scene file (YAML), applying overrides as `impetus run --set` does: a dict of dotted keys
    ({"modules.resolver": "mirtich", "dt": 0.01, "bodies.ball.velocity": [1, 0, 0]}) or a list of
    "KEY=VALUE" strings. Raises Error naming the file, line and field of any defect."""
    return _impetus._load_scene(_os.fspath(path), _overrides(overrides))


def scene_from_dict(description, overrides=None, base_dir=".", name="<python>"):
    """A scene built in code: a dict with the scene file's layout (dt, gravity, modules, bodies, generators,
    constraints; README.md, "Scene files"), checked as a file is. Relative mesh paths are taken from
    base_dir. Messages name `name` and the line of the dict written as indented JSON (which is YAML)."""
    text = _json.dumps(description, indent=2, allow_nan=True)
    return _impetus._load_scene_text(text, name, _os.fspath(base_dir), _overrides(overrides))


def _scene(scene):
    return scene if isinstance(scene, Scene) else load_scene(scene)


def resolve(scene):
    """One detection and one resolution on the scene's initial state (`impetus resolve --json`, as a dict)."""
    return _json.loads(_impetus._resolve(_scene(scene)))


def plugins():
    """Every plugin found and every library that failed to load (`impetus plugins --json`, as a dict)."""
    return _json.loads(_impetus._plugins())


def mass(mesh, density=None, mass=None, scale=1.0, part=""):
    """Volume, mass, centre of mass and inertia of a closed mesh (`impetus mass --json`, as a dict)."""
    for label, value in (("density", density), ("mass", mass), ("scale", scale)):
        if value is not None and not (isinstance(value, _numbers.Real) and _math.isfinite(value) and value > 0):
            raise Error(f"mass: {label} must be a positive number, not {value!r}")
    if density is not None and mass is not None:
        raise Error("mass: give density or mass, not both")
    return _json.loads(_impetus._mass(_os.fspath(mesh), density, mass, float(scale), part))


def summary(world):
    """The run summary since the world was built: the document `impetus run --json` prints (energy balance,
    momentum, contacts, resolver counters, penetration), with the wall time of its steps."""
    return _json.loads(world._summary())


def run(scene, steps=None, duration=None, overrides=None):
    """Builds a world, runs it as `impetus run` does (`steps`, default 1000, or `duration` seconds) and
    returns its summary (the `--json` document)."""
    if not isinstance(scene, Scene):
        scene = load_scene(scene, overrides)
    elif overrides:
        raise Error("run: overrides apply when the scene is read; pass a file name, or load_scene(..., overrides)")
    if steps is not None and duration is not None:
        raise Error("run: give steps or duration, not both")
    world = World(scene)
    if duration is not None:
        if not (isinstance(duration, _numbers.Real) and _math.isfinite(duration) and duration >= 0):
            raise Error(f"run: duration must be a non-negative number of seconds, not {duration!r}")
        steps = int(_math.floor(duration / world.dt + 0.5))  # as the tool rounds (half away from zero)
    steps = 1000 if steps is None else steps
    if not isinstance(steps, _numbers.Integral) or steps < 0:
        raise Error(f"run: steps must be a non-negative integer, not {steps!r}")
    world.step(int(steps))
    return summary(world)
