// Scene loading: what a valid scene turns into (settings, modules, bodies with mass properties,
// constraints), from inline YAML and from the fixture files in scenes/.
#include "scene_test_support.hpp"

#include <cmath>
#include <filesystem>
#include <numbers>

namespace impetus {
namespace {

using test::load;
using std::numbers::pi;

const RigidBody& body_named(const Scene& scene, const std::string& name) {
  for (const RigidBody& b : scene.bodies)
    if (b.name == name) return b;
  ADD_FAILURE() << "no body named " << name;
  return scene.bodies.front();
}

// a minimal example in the spirit of README.md's, without the mesh body (no asset pipeline yet) and with the
// constraint joining two bodies the example actually has.
constexpr const char* kDesignExample = R"(dt: 0.001
gravity: [0, 0, -9.81]
modules:
  integrator: euler                         # short form: plugin name
  detector: {plugin: fcl, margin: 1.0e-4}   # long form: plugin name + its options
  resolver: {plugin: ledas}
bodies:
  - name: ground
    fixed: true
    shape: {plane: {normal: [0, 0, 1], offset: 0}}
  - name: ball
    shape: {sphere: {radius: 0.5}}
    mass: 1.0                  # or density: …
    position: [0, 0, 0.5]      # center of mass
    orientation: [1, 0, 0, 0]  # quaternion w, x, y, z
    velocity: [0, 0, -1]
    angular_velocity: [0, 0, 0]
    restitution: 0.0
generators:                    # procedurally built benchmark scenes
  - pyramid: {rows: 20, radius: 0.5, mass: 1}
  - line: {count: 100, radius: 0.5, wall: true}
constraints:
  - point_point: {bodies: [ground, ball], point: [0, 0, 1], level: position}
)";

TEST(SceneLoad, DesignExampleWithoutMeshLoads) {
  const Scene scene = load(kDesignExample);
  EXPECT_EQ(scene.settings.dt, 0.001);
  EXPECT_EQ(scene.settings.gravity, Vec3(0, 0, -9.81));
  EXPECT_EQ(scene.settings.order, StepOrder::split);
  EXPECT_EQ(scene.integrator.plugin, "euler");
  EXPECT_EQ(scene.detector.plugin, "fcl");
  EXPECT_EQ(scene.resolver.plugin, "ledas");
  // 2 bodies + 210 pyramid spheres (its ground is the scene's own) + 100 line spheres + the wall.
  EXPECT_EQ(scene.bodies.size(), 2u + 210u + 100u + 1u);
  EXPECT_EQ(scene.constraints.size(), 1u);
  const RigidBody& ball = body_named(scene, "ball");
  EXPECT_EQ(ball.mass, 1.0);
  EXPECT_EQ(ball.velocity, Vec3(0, 0, -1));
  EXPECT_TRUE(body_named(scene, "ground").fixed);
}

TEST(SceneLoad, DefaultsWhenKeysAreOmitted) {
  const Scene scene = load("bodies: []\n");
  EXPECT_EQ(scene.settings.dt, WorldSettings{}.dt);
  EXPECT_EQ(scene.settings.gravity, Vec3(0, 0, -9.81));
  EXPECT_EQ(scene.integrator.plugin, "momentum");
  EXPECT_EQ(scene.detector.plugin, "fcl");
  EXPECT_EQ(scene.resolver.plugin, "ledas");
  EXPECT_EQ(scene.detector.options.label(), "plugin 'fcl' (detector)");
  EXPECT_TRUE(scene.bodies.empty());
}

TEST(SceneLoad, SphereMassFromDensityIsFourThirdsPiRCubedRho) {
  const Scene scene = load(R"(bodies:
  - {name: s, shape: {sphere: {radius: 0.3}}, density: 7800}
)");
  const RigidBody& s = scene.bodies.at(0);
  const double mass = 4.0 / 3.0 * pi * 0.3 * 0.3 * 0.3 * 7800.0;
  EXPECT_NEAR(s.mass, mass, 1e-12 * mass);
  EXPECT_NEAR(s.inv_mass, 1.0 / mass, 1e-12 / mass);
  const double moment = 0.4 * mass * 0.3 * 0.3;  // 2/5 m r²
  EXPECT_LE((s.inertia_body - moment * Mat3::Identity()).norm(), 1e-12 * moment);
  EXPECT_LE((s.inv_inertia_body - Mat3::Identity() / moment).norm(), 1e-12 / moment);
  EXPECT_FALSE(s.fixed);
}

TEST(SceneLoad, BoxInertiaFromMassUsesTheShapeDensity) {
  // Given mass m, a box's inertia about x is m (y² + z²) / 12.
  const Scene scene = load(R"(bodies:
  - {name: b, shape: {box: {size: [1, 2, 3]}}, mass: 6}
)");
  const RigidBody& b = scene.bodies.at(0);
  EXPECT_NEAR(b.inertia_body(0, 0), 6.0 * (4 + 9) / 12.0, 1e-12 * 6.5);
  EXPECT_NEAR(b.inertia_body(1, 1), 6.0 * (1 + 9) / 12.0, 1e-12 * 5.0);
  EXPECT_NEAR(b.inertia_body(2, 2), 6.0 * (1 + 4) / 12.0, 1e-12 * 2.5);
}

TEST(SceneLoad, InertiaOverrideReplacesTheShapeInertia) {
  const Scene principal = load(R"(bodies:
  - {name: a, shape: {sphere: {radius: 1}}, mass: 2, inertia: [1, 2, 2.5]}
)");
  EXPECT_EQ(principal.bodies[0].inertia_body, Mat3(Vec3(1, 2, 2.5).asDiagonal()));
  EXPECT_EQ(principal.bodies[0].mass, 2.0);
  const Scene full = load(R"(bodies:
  - name: a
    shape: {sphere: {radius: 1}}
    mass: 2
    inertia: [[2, 0.5, 0], [0.5, 2, 0], [0, 0, 3]]
)");
  Mat3 expected;
  expected << 2, 0.5, 0, 0.5, 2, 0, 0, 0, 3;
  EXPECT_EQ(full.bodies[0].inertia_body, expected);
  EXPECT_LE((full.bodies[0].inv_inertia_body * expected - Mat3::Identity()).norm(), 1e-14);
}

TEST(SceneLoad, OrientationIsNormalizedAndMapsBodyToWorld) {
  // [1, 0, 0, 1] normalized is a quarter turn about z: body x maps to world y.
  const Scene scene = load(R"(bodies:
  - {name: a, shape: {box: {size: [1, 1, 1]}}, mass: 1, orientation: [1, 0, 0, 1]}
)");
  const Mat3& r = scene.bodies[0].rotation;
  EXPECT_LE((r * Vec3::UnitX() - Vec3::UnitY()).norm(), 1e-15);
  EXPECT_LE((r.transpose() * r - Mat3::Identity()).norm(), 1e-15);
}

TEST(SceneLoad, PlaneNormalIsNormalized) {
  const Scene scene = load(R"(bodies:
  - {name: w, fixed: true, shape: {plane: {normal: [3, 4, 0], offset: 2}}}
)");
  const Plane& plane = std::get<Plane>(scene.bodies[0].shape);
  EXPECT_LE((plane.normal - Vec3(0.6, 0.8, 0.0)).norm(), 1e-15);
  EXPECT_EQ(plane.offset, 2.0);
}

TEST(SceneLoad, FixedBodyHasInfiniteMassAndZeroInverses) {
  const Scene scene = load(R"(bodies:
  - {name: post, fixed: true, shape: {cylinder: {radius: 0.1, length: 2}}, position: [1, 2, 1]}
)");
  const RigidBody& post = scene.bodies[0];
  EXPECT_TRUE(post.fixed);
  EXPECT_TRUE(std::isinf(post.mass));
  EXPECT_EQ(post.inv_mass, 0.0);
  EXPECT_EQ(post.inv_inertia_body, Mat3::Zero());
  EXPECT_EQ(post.position, Vec3(1, 2, 1));
}

TEST(SceneLoad, MaterialAndCollisionFilter) {
  const Scene scene = load(R"(bodies:
  - name: a
    shape: {capsule: {radius: 0.2, length: 0.5}}
    density: 1000
    restitution: 0.75
    friction: 0.3
    collision_group: 4
    collision_mask: 0xFFFFFFF0
)");
  const RigidBody& a = scene.bodies[0];
  EXPECT_EQ(a.material.restitution, 0.75);
  EXPECT_EQ(a.material.friction, 0.3);
  EXPECT_EQ(a.collision_group, 4u);
  EXPECT_EQ(a.collision_mask, 0xFFFFFFF0u);
}

TEST(SceneLoad, ModuleLongFormKeepsOptionsWithTheirLocation) {
  const Scene scene = load(R"(modules:
  integrator: {plugin: euler}
  detector: {plugin: mine, path: ../lib/libmine.so, margin: 1.0e-4, axes: [1, 0, 0]}
  resolver: none
)");
  EXPECT_EQ(scene.detector.plugin, "mine");
  EXPECT_EQ(scene.detector.path, std::filesystem::path("/lib/libmine.so"));  // relative to /scenes
  EXPECT_EQ(scene.detector.where, "scene.yaml:3:22");
  EXPECT_EQ(scene.detector.options.label(), "plugin 'mine' (detector)");
  const auto& values = scene.detector.options.values();
  ASSERT_EQ(values.size(), 2u);
  EXPECT_EQ(values.at("margin").text, "1.0e-4");
  EXPECT_EQ(values.at("margin").where, "scene.yaml:3:61");
  EXPECT_TRUE(values.at("axes").is_list);
  EXPECT_EQ(values.at("axes").items, (std::vector<std::string>{"1", "0", "0"}));
  EXPECT_DOUBLE_EQ(scene.detector.options.number("margin", 0.0), 1e-4);
  EXPECT_EQ(scene.resolver.plugin, "none");
  EXPECT_EQ(scene.integrator.where, "scene.yaml:2:24");
}

TEST(SceneLoad, StepOrderAndPluginPathRelativeToTheScene) {
  const Scene one = load("step_order: paper\nplugin_path: plugins\n");
  EXPECT_EQ(one.settings.order, StepOrder::paper);
  EXPECT_EQ(one.plugin_path, (std::vector<std::filesystem::path>{"/scenes/plugins"}));
  const Scene list = load("plugin_path: [a, /opt/p, ../b]\n");
  EXPECT_EQ(list.plugin_path, (std::vector<std::filesystem::path>{"/scenes/a", "/opt/p", "/b"}));
}

TEST(SceneLoad, ConstraintAnchorsMapBackToTheSameWorldPoint) {
  const Scene scene = load(R"(bodies:
  - {name: a, shape: {box: {size: [1, 1, 1]}}, mass: 1, position: [1, 2, 3], orientation: [0.3, 0.1, -0.7, 0.5]}
  - {name: b, shape: {sphere: {radius: 1}}, mass: 1, position: [-1, 0, 2], orientation: [1, 1, 0, 0]}
constraints:
  - point_point: {bodies: [a, b], point: [0.5, 1.5, 2.5], level: velocity, collide: true}
)");
  ASSERT_EQ(scene.constraints.size(), 1u);
  const auto& c = std::get<PointPointConstraint>(scene.constraints[0]);
  EXPECT_EQ(c.a, 0u);
  EXPECT_EQ(c.b, 1u);
  EXPECT_EQ(c.level, ConstraintLevel::velocity);
  EXPECT_TRUE(c.collide);
  const Vec3 point(0.5, 1.5, 2.5);
  for (const auto& [index, anchor] : {std::pair{c.a, c.anchor_a}, std::pair{c.b, c.anchor_b}}) {
    const RigidBody& body = scene.bodies[index];
    EXPECT_LE((body.position + body.rotation * anchor - point).norm(), 1e-14) << body.name;
  }
}

TEST(SceneLoad, ConstraintDefaultsArePositionLevelWithoutCollision) {
  const Scene scene = load(R"(bodies:
  - {name: a, shape: {sphere: {radius: 1}}, mass: 1}
  - {name: b, fixed: true, shape: {sphere: {radius: 1}}, position: [2, 0, 0]}
constraints:
  - point_point: {bodies: [b, a], point: [1, 0, 0]}
)");
  const auto& c = std::get<PointPointConstraint>(scene.constraints.at(0));
  EXPECT_EQ(c.a, 1u);
  EXPECT_EQ(c.level, ConstraintLevel::position);
  EXPECT_FALSE(c.collide);
  EXPECT_LE((c.anchor_a - Vec3(-1, 0, 0)).norm(), 1e-15);
  EXPECT_LE((c.anchor_b - Vec3(1, 0, 0)).norm(), 1e-15);
}

// coaxial: the world point and axis at the initial poses map back from each body's frame (1e-14), the
// axis is normalized, and a zero axis or a non-positive length is refused at its line and column.
TEST(SceneLoad, CoaxialAxisAndPointMapBackToTheWorldInEachBody) {
  const Scene scene = load(R"(bodies:
  - {name: a, shape: {box: {size: [1, 1, 1]}}, mass: 1, position: [1, 2, 3], orientation: [0.3, 0.1, -0.7, 0.5]}
  - {name: b, shape: {cylinder: {radius: 0.1, length: 1}}, mass: 1, position: [1, 2, 4], orientation: [1, 1, 0, 0]}
constraints:
  - coaxial: {bodies: [a, b], point: [1, 2, 3.5], axis: [0, 0, 2], length: 0.5, level: velocity}
)");
  ASSERT_EQ(scene.constraints.size(), 1u);
  const auto& c = std::get<CoaxialConstraint>(scene.constraints[0]);
  EXPECT_EQ(c.level, ConstraintLevel::velocity);
  EXPECT_FALSE(c.collide);
  EXPECT_DOUBLE_EQ(c.length, 0.5);
  const RigidBody& a = scene.bodies[c.a];
  const RigidBody& b = scene.bodies[c.b];
  EXPECT_LE((a.position + a.rotation * c.anchor_a - Vec3(1, 2, 3.5)).norm(), 1e-14);
  EXPECT_LE((b.position + b.rotation * c.anchor_b - Vec3(1, 2, 3.5)).norm(), 1e-14);
  EXPECT_LE((a.rotation * c.axis_a - Vec3::UnitZ()).norm(), 1e-14);
  EXPECT_LE((b.rotation * c.axis_b - Vec3::UnitZ()).norm(), 1e-14);

  const std::string two_bodies = R"(bodies:
  - {name: a, shape: {sphere: {radius: 1}}, mass: 1}
  - {name: b, shape: {sphere: {radius: 1}}, mass: 1, position: [0, 0, 3]}
constraints:
)";
  test::expect_error(two_bodies + "  - coaxial: {bodies: [a, b], point: [0, 0, 1], axis: [0, 0, 0]}\n", "scene.yaml:5:", "axis");
  test::expect_error(two_bodies + "  - coaxial: {bodies: [a, b], point: [0, 0, 1], axis: [0, 0, 1], length: 0}\n",
               "scene.yaml:5:", "length");
  test::expect_error(two_bodies + "  - coaxial: {bodies: [a, b], point: [0, 0, 1], axis: [0, 0, 1], axle: 1}\n",
               "scene.yaml:5:", "axle");
}

const std::filesystem::path kScenes = std::filesystem::path(IMPETUS_SOURCE_DIR) / "tests/core/scenes";

TEST(SceneFile, GoodFileLoadsWithPathsRelativeToIt) {
  const Scene scene = load_scene(kScenes / "good.yaml");
  EXPECT_EQ(scene.file, kScenes / "good.yaml");
  EXPECT_EQ(scene.plugin_path.at(0), (kScenes / "my_plugins").lexically_normal());
  EXPECT_EQ(scene.bodies.size(), 4u);  // ground, ball, crate, lid
  EXPECT_EQ(scene.constraints.size(), 1u);
}

TEST(SceneFile, BadFileNamesTheFileLineAndColumn) {
  const std::string file = (kScenes / "bad_unknown_key.yaml").string();
  try {
    load_scene(file);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(file + ":8:5: unknown key 'radius' in body 'ball'", 0), 0u) << e.what();
  }
}

TEST(SceneFile, MissingFileIsAnError) {
  EXPECT_THROW(load_scene(kScenes / "does_not_exist.yaml"), Error);
}

}  // namespace
}  // namespace impetus
