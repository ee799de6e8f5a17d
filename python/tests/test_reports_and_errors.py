"""The tool's reports from Python (resolve, plugins, mass) equal its --json documents, and bad input raises
impetus.Error with the message the tool prints."""
import numpy as np
import pytest

import impetus
from conftest import CLI_SCENES, SCENES, SOURCE, tool, tool_json


def test_resolve_is_impetus_resolve_json():
    # The resting unit box (1 kg, restitution 0) arriving at 1 m/s: its four corners stop it together.
    scene = impetus.load_scene(CLI_SCENES / "resting_box.yaml", overrides={"bodies.box.velocity": [0, 0, -1]})
    ours = impetus.resolve(scene)
    theirs = tool_json("resolve", CLI_SCENES / "resting_box.yaml", "--set", "bodies.box.velocity=[0, 0, -1]")
    ours.pop("time_s")
    theirs.pop("time_s")
    assert ours == theirs
    assert len(ours["contacts"]) == 4
    assert sum(c["impulse"] for c in ours["contacts"]) == pytest.approx(1.0, rel=1e-9)
    box = next(b for b in ours["bodies"] if b["name"] == "box")
    assert box["velocity"] == pytest.approx([0, 0, 0], abs=1e-9)


def test_plugins_lists_the_shipped_modules():
    listing = impetus.plugins()
    found = {(p["kind"], p["name"]) for p in listing["plugins"]}
    assert {("integrator", "momentum"), ("detector", "fcl"), ("resolver", "ledas"), ("resolver", "mirtich")} <= found
    assert listing == tool_json("plugins")


def test_mass_of_a_unit_box_mesh():
    box = SOURCE / "assets" / "meshes" / "box.obj"
    ours = impetus.mass(box, density=7800)
    theirs = tool_json("mass", box, "--density", 7800)
    assert ours == theirs
    # A closed-form check on top: the box's volume and inertia from its extents.
    extent = np.array(ours["inertia"])
    assert ours["mass"] == pytest.approx(7800 * ours["volume"], rel=1e-12)
    assert np.allclose(extent, extent.T)
    with pytest.raises(impetus.Error, match="density must be a positive number"):
        impetus.mass(box, density=-1)
    with pytest.raises(impetus.Error, match="give density or mass, not both"):
        impetus.mass(box, density=1, mass=2)


def tool_error(*args):
    status, _, stderr = tool(*args, check=False)
    assert status == 1
    return stderr.strip().removeprefix("impetus: error: ")


@pytest.mark.parametrize("scene", ["typo.yaml", "negative_mass.yaml", "nan.yaml"])
def test_a_bad_scene_raises_the_tools_message(scene):
    with pytest.raises(impetus.Error) as raised:
        impetus.load_scene(CLI_SCENES / scene)
    assert str(raised.value) == tool_error("run", CLI_SCENES / scene)
    assert f"{scene}:" in str(raised.value)  # the file and line at fault


def test_an_override_path_the_scene_lacks_raises_the_message_of_set():
    with pytest.raises(impetus.Error) as raised:
        impetus.load_scene(CLI_SCENES / "drop.yaml", overrides={"bodies.nobody.mass": 3})
    assert str(raised.value) == tool_error("run", CLI_SCENES / "drop.yaml", "--set", "bodies.nobody.mass=3")
    with pytest.raises(impetus.Error, match="expected KEY=VALUE"):
        impetus.load_scene(CLI_SCENES / "drop.yaml", overrides=["dt"])
    with pytest.raises(impetus.Error, match="has no YAML form"):
        impetus.load_scene(CLI_SCENES / "drop.yaml", overrides={"dt": object()})


def test_missing_files_and_plugins_are_named():
    with pytest.raises(impetus.Error, match="no_such_scene.yaml"):
        impetus.load_scene(CLI_SCENES / "no_such_scene.yaml")
    scene = impetus.load_scene(CLI_SCENES / "drop.yaml", overrides={"modules.resolver": "no_such_resolver"})
    with pytest.raises(impetus.Error, match="no resolver plugin named 'no_such_resolver'"):
        impetus.World(scene)


def test_a_scene_built_in_code_is_checked_as_a_file_is(free_ball):
    free_ball["bodies"][0]["mass"] = -2.0
    with pytest.raises(impetus.Error, match=r"<python>:\d+:\d+: .*mass"):
        impetus.scene_from_dict(free_ball)


def test_a_failing_step_raises_and_leaves_the_world_before_it():
    # A ball pushed so hard its kinetic energy overflows in one step: the step fails, as `impetus run` fails,
    # and the world is back where it was.
    scene = impetus.scene_from_dict({
        "dt": 0.001, "modules": {"integrator": "momentum", "detector": "none", "resolver": "none"},
        "bodies": [{"name": "ball", "shape": {"sphere": {"radius": 0.1}}, "mass": 1.0}]})
    world = impetus.World(scene)
    world.step(3)
    before = world.state()
    world.set_load("ball", force=[1e308, 0, 0])
    with pytest.raises(impetus.Error, match="ball"):
        world.step(10)
    assert world.step_count == 3
    for key, value in world.state().items():
        assert np.array_equal(value, before[key]), key
