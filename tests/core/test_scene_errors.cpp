// Bad scenes are refused with "<file>:<line>:<col>: <reason>" pointing at the offending value, never
// silently defaulted and never crashing. Lines and columns are 1-based, as editors show them.
#include "scene_test_support.hpp"

namespace impetus {
namespace {

using test::expect_error;
using test::load_error;

TEST(SceneErrors, UnknownTopLevelKeyListsTheAllowedKeys) {
  expect_error("dt: 0.001\ngraviti: [0, 0, -9.81]\n",
               "scene.yaml:2:1: unknown key 'graviti' in scene; expected one of: dt, gravity, step_order, sleep, threads, "
               "plugin_path, modules, bodies, generators, constraints; did you mean 'gravity'?");
}

TEST(SceneErrors, UnknownKeyHintsAtAMissingSpaceAfterTheColon) {
  expect_error("bodies:\n  - {name: b, shape: {sphere: {radius:1}}, mass: 1}\n",
               "scene.yaml:2:32: unknown key 'radius:1' in sphere; expected one of: radius; a ':' needs a space after "
               "it to separate key and value");
}

TEST(SceneErrors, UnknownKeyInABodyNamesTheBody) {
  expect_error(R"(bodies:
  - name: ball
    shape: {sphere: {radius: 0.5}}
    mas: 1
)",
               "scene.yaml:4:5: unknown key 'mas' in body 'ball'; expected one of: name, fixed, shape, mass");
}

TEST(SceneErrors, UnknownKeyInAShape) {
  expect_error(R"(bodies:
  - name: ball
    shape: {sphere: {radius: 0.5, radios: 1}}
    mass: 1
)",
               "scene.yaml:3:35: unknown key 'radios' in sphere; expected one of: radius");
  expect_error(R"(bodies:
  - name: ball
    shape: {ball: {radius: 0.5}}
    mass: 1
)",
               "scene.yaml:3:13: unknown key 'ball' in shape; expected one of: sphere, box, capsule, cylinder, "
               "plane, mesh");
}

TEST(SceneErrors, RepeatedKeyIsRefused) {
  expect_error("dt: 0.001\ndt: 0.002\n", "scene.yaml:2:1: key 'dt' appears twice in scene (first at scene.yaml:1:1)");
}

TEST(SceneErrors, WrongTypeNamesTheKeyAndTheValue) {
  expect_error(R"(bodies:
  - name: ball
    shape: {sphere: {radius: 0.5}}
    mass: abc
)",
               "scene.yaml:4:11: 'mass' expects a number, got 'abc'");
  expect_error("gravity: 9.81\n", "scene.yaml:1:10: 'gravity' expects a list of 3 numbers, got '9.81'");
  expect_error("gravity: [0, -9.81]\n", "scene.yaml:1:10: 'gravity' expects a list of 3 numbers, got a list of 2");
  expect_error("bodies: {name: ball}\n", "scene.yaml:1:9: 'bodies' expects a list, got a mapping");
  expect_error("bodies:\n  - {name: [a, b]}\n", "scene.yaml:2:12: 'name' expects a text value, got a list");
  expect_error("bodies:\n  - {name: a, fixed: maybe}\n", "scene.yaml:2:22: 'fixed' expects true or false, got 'maybe'");
}

TEST(SceneErrors, NegativeMassIsRefused) {
  expect_error(R"(bodies:
  - name: ball
    shape: {sphere: {radius: 0.5}}
    mass: -1
)",
               "scene.yaml:4:11: 'mass' must be positive, got -1");
}

TEST(SceneErrors, ZeroRadiusIsRefused) {
  expect_error(R"(bodies:
  - name: ball
    shape: {sphere: {radius: 0}}
    mass: 1
)",
               "scene.yaml:3:30: 'radius' must be positive, got 0");
}

TEST(SceneErrors, NaNAndInfinityAreRefused) {
  expect_error(R"(bodies:
  - name: ball
    shape: {sphere: {radius: 1}}
    mass: 1
    position: [0, .nan, 1]
)",
               "scene.yaml:5:19: 'position' must be a finite number, got '.nan'");
  expect_error("dt: .inf\n", "scene.yaml:1:5: 'dt' must be a finite number, got '.inf'");
  expect_error("gravity: [0, 0, -.Inf]\n", "scene.yaml:1:17: 'gravity' must be a finite number, got '-.Inf'");
  expect_error("dt: 1e999\n", "scene.yaml:1:5: 'dt' is out of the range of a double");
}

TEST(SceneErrors, NonPositiveTimeStepIsRefused) {
  expect_error("dt: 0\n", "scene.yaml:1:5: 'dt' must be positive, got 0");
}

TEST(SceneErrors, ZeroQuaternionIsRefused) {
  expect_error(R"(bodies:
  - name: ball
    shape: {sphere: {radius: 1}}
    mass: 1
    orientation: [0, 0, 0, 0]
)",
               "scene.yaml:5:18: 'orientation' is the zero quaternion");
}

TEST(SceneErrors, ZeroPlaneNormalIsRefused) {
  expect_error(R"(bodies:
  - {name: g, fixed: true, shape: {plane: {normal: [0, 0, 0]}}}
)",
               "scene.yaml:2:52: 'normal' must not be the zero vector");
}

TEST(SceneErrors, MassAndDensityTogetherAreRefused) {
  expect_error(R"(bodies:
  - name: ball
    shape: {sphere: {radius: 1}}
    mass: 1
    density: 1000
)",
               "scene.yaml:5:14: give either 'mass' or 'density', not both");
}

TEST(SceneErrors, MovableBodyNeedsMassOrDensity) {
  expect_error(R"(bodies:
  - name: ball
    shape: {sphere: {radius: 1}}
)",
               "scene.yaml:2:5: body 'ball' needs 'mass' or 'density'");
}

TEST(SceneErrors, MissingShapeOrNameIsNamed) {
  expect_error("bodies:\n  - {name: ball, mass: 1}\n", "scene.yaml:2:5: body 'ball' needs 'shape'");
  expect_error("bodies:\n  - {mass: 1}\n", "scene.yaml:2:5: body #1 needs 'name'");
  expect_error("bodies:\n  - {name: b, mass: 1, shape: {}}\n",
               "scene.yaml:2:31: shape needs one of: sphere, box, capsule, cylinder, plane, mesh");
  expect_error("bodies:\n  - {name: b, mass: 1, shape: {sphere: {radius: 1}, box: {size: [1, 1, 1]}}}\n",
               "scene.yaml:2:53: shape has both 'sphere' and 'box'; give exactly one");
}

TEST(SceneErrors, PlaneOnAMovableBodyIsRefused) {
  expect_error(R"(bodies:
  - name: floor
    shape: {plane: {normal: [0, 0, 1]}}
    mass: 1
)",
               "scene.yaml:3:12: a plane is only allowed on a fixed body");
}

TEST(SceneErrors, MassOnAFixedBodyIsRefused) {
  expect_error("bodies:\n  - {name: g, fixed: true, mass: 3, shape: {sphere: {radius: 1}}}\n",
               "scene.yaml:2:34: 'mass' does not apply to a fixed body");
}

TEST(SceneErrors, LoadsOnAFixedBodyAndMotionOnAMovableOneAreRefused) {
  expect_error("bodies:\n  - {name: g, fixed: true, force: [1, 0, 0], shape: {sphere: {radius: 1}}}\n",
               "scene.yaml:2:35: 'force' does not apply to a fixed body");
  expect_error("bodies:\n  - {name: g, fixed: true, torque_body: [0, 0, 1], shape: {sphere: {radius: 1}}}\n",
               "scene.yaml:2:41: 'torque_body' does not apply to a fixed body");
  expect_error("bodies:\n  - {name: b, mass: 1, motion: moving, shape: {sphere: {radius: 1}}}\n",
               "scene.yaml:2:32: 'motion' (a prescribed motion) applies to fixed bodies only");
  expect_error("bodies:\n  - {name: g, fixed: true, motion: surface, shape: {sphere: {radius: 1}}}\n",
               "scene.yaml:2:36: 'motion' needs the fixed body's 'velocity' or 'angular_velocity'");
  expect_error("bodies:\n  - {name: g, fixed: true, velocity: [1, 0, 0], motion: belt, shape: {sphere: {radius: 1}}}\n",
               "scene.yaml:2:57: 'motion' expects one of: moving, surface");
  expect_error("bodies:\n  - {name: b, mass: 1, force: [1, .nan, 0], shape: {sphere: {radius: 1}}}\n",
               "scene.yaml:2:");
}

TEST(SceneErrors, DuplicateBodyNameIsRefused) {
  expect_error(R"(bodies:
  - {name: ball, shape: {sphere: {radius: 1}}, mass: 1}
  - {name: ball, shape: {sphere: {radius: 1}}, mass: 1}
)",
               "scene.yaml:3:12: duplicate body name 'ball' (first at scene.yaml:2:12)");
}

TEST(SceneErrors, OutOfRangeMaterialIsRefused) {
  expect_error("bodies:\n  - {name: b, shape: {sphere: {radius: 1}}, mass: 1, restitution: 1.5}\n",
               "scene.yaml:2:67: 'restitution' must be between 0 and 1, got 1.5");
  expect_error("bodies:\n  - {name: b, shape: {sphere: {radius: 1}}, mass: 1, collision_mask: -1}\n",
               "scene.yaml:2:70: 'collision_mask' must be between 0 and 4294967295");
}

TEST(SceneErrors, InertiaMustBeARigidBodyInertia) {
  expect_error("bodies:\n  - {name: b, shape: {sphere: {radius: 1}}, mass: 1, inertia: [1, -1, 1]}\n",
               "scene.yaml:2:63: 'inertia' must be positive definite");
  expect_error("bodies:\n  - {name: b, shape: {sphere: {radius: 1}}, mass: 1, inertia: [1, 1, 3]}\n",
               "scene.yaml:2:63: 'inertia' is not that of any rigid body");
  expect_error(
      "bodies:\n  - {name: b, shape: {sphere: {radius: 1}}, mass: 1, inertia: [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]}\n",
      "scene.yaml:2:63: 'inertia' must be a symmetric matrix");
}

TEST(SceneErrors, MeshKeysAreCheckedAndAMissingMeshFileIsLocated) {
  expect_error("bodies:\n  - {name: part, density: 7800, shape: {mesh: {file: part.obj, scael: 2}}}\n",
               "scene.yaml:2:64: unknown key 'scael' in mesh; expected one of: file, scale, collision");
  // The mesh file is relative to the scene's directory (/scenes here); the message points at `file`.
  expect_error("bodies:\n  - {name: part, density: 7800, shape: {mesh: {file: part.obj, scale: 0.001}}}\n",
               "scene.yaml:2:54: ", "/scenes/part.obj");
}

TEST(SceneErrors, BadYamlSyntaxIsAnErrorNotACrash) {
  // Positions are yaml-cpp's: where the parser found the problem.
  expect_error("dt: 0.001\n  gravity: [0, 0, 1]\n", "scene.yaml:2:10: invalid YAML: illegal map value");
  expect_error("dt: 0.001\nmodules: {integrator: euler\n", "scene.yaml:3:1: invalid YAML: end of map flow not found");
  expect_error("bodies:\n\t- name: a\n", "scene.yaml:2:2: invalid YAML: illegal block entry");
  expect_error("a: &x 1\nb: *y\n", "scene.yaml:2:4: invalid YAML: the referenced anchor is not defined");
}

TEST(SceneErrors, SceneThatIsNotAMappingIsRefused) {
  expect_error("- dt\n- gravity\n", "scene.yaml:1:1: a scene is a mapping of keys");
  expect_error("", "scene.yaml: a scene is a mapping of keys");
}

TEST(SceneErrors, ModuleMistakes) {
  expect_error("modules:\n  integrator: none\n",
               "scene.yaml:2:15: the integrator is required; 'none' is allowed only for the detector and the resolver");
  expect_error("modules:\n  resolver: [ledas]\n",
               "scene.yaml:2:13: 'resolver' expects a plugin name or a mapping {plugin: NAME, OPTION: VALUE, ...}");
  expect_error("modules:\n  detector: {plugin: fcl, margin: {a: 1}}\n",
               "scene.yaml:2:35: option 'margin' expects a value or a list of values, got a mapping");
  expect_error("modules:\n  integrator: euler\n  solver: ledas\n",
               "scene.yaml:3:3: unknown key 'solver' in modules; expected one of: integrator, detector, resolver");
  expect_error("step_order: backwards\n", "scene.yaml:1:13: 'step_order' expects one of: split, paper; got 'backwards'");
}

TEST(SceneErrors, ConstraintToAnUnknownBodyNamesIt) {
  expect_error(R"(bodies:
  - {name: a, shape: {sphere: {radius: 1}}, mass: 1}
constraints:
  - point_point: {bodies: [a, c], point: [0, 0, 0]}
)",
               "scene.yaml:4:31: no body named 'c'");
  expect_error(R"(bodies:
  - {name: a, shape: {sphere: {radius: 1}}, mass: 1}
constraints:
  - point_point: {bodies: [a, a], point: [0, 0, 0]}
)",
               "scene.yaml:4:27: a constraint needs two different bodies");
  expect_error(R"(bodies:
  - {name: a, shape: {sphere: {radius: 1}}, mass: 1}
constraints:
  - hinge: {bodies: [a, a]}
)",
               "scene.yaml:4:5: unknown key 'hinge' in constraint; expected one of: point_point");
}

TEST(SceneErrors, GeneratorParameterErrorPointsAtTheParameter) {
  expect_error("generators:\n  - pyramid: {rows: 3,\n      radius: -1}\n",
               "scene.yaml:3:15: pyramid 'radius' must be a positive number, got -1");
  expect_error("generators:\n  - line: {count: 0}\n", "scene.yaml:2:19: line 'count' must be between 1 and");
  expect_error("generators:\n  - line: {count: 3, walls: false}\n",
               "scene.yaml:2:22: unknown key 'walls' in line; expected one of: count, radius");
  expect_error("generators:\n  - tower: {rows: 3}\n", "scene.yaml:2:5: unknown key 'tower' in generator");
}

TEST(SceneErrors, GeneratedNameCollidingWithABodyIsRefused) {
  expect_error(R"(bodies:
  - {name: wall, fixed: true, shape: {plane: {normal: [1, 0, 0], offset: 0}}}
generators:
  - line: {count: 2}
)",
               "scene.yaml:4:5: duplicate body name 'wall' (first at scene.yaml:2:12)");
}

}  // namespace
}  // namespace impetus
