// build_world: a loaded scene becomes a World with its bodies, constraints and plugins. Uses the euler
// integrator plugin from the build tree (found next to libimpetus_plugin_host.so) and no detector/resolver.
#include "impetus/plugins/host.hpp"
#include "scene_test_support.hpp"

namespace impetus {
namespace {

constexpr const char* kScene = R"(dt: 0.01
gravity: [0, 0, -10]
modules:
  integrator: euler
  detector: none
  resolver: none
bodies:
  - {name: anchor, fixed: true, shape: {sphere: {radius: 0.1}}, position: [0, 0, 2]}
  - {name: bob, shape: {sphere: {radius: 0.1}}, mass: 2, position: [1, 0, 2]}
constraints:
  - point_point: {bodies: [anchor, bob], point: [0.5, 0, 2]}
)";

TEST(BuildWorld, AddsBodiesConstraintsAndTheIntegrator) {
  PluginHost host;
  const std::unique_ptr<World> world = build_world(test::load(kScene), host);
  ASSERT_EQ(world->bodies().size(), 2u);
  EXPECT_EQ(world->find_body("bob"), BodyIndex{1});
  EXPECT_EQ(world->constraints().size(), 1u);
  EXPECT_FALSE(world->has_detector());
  EXPECT_FALSE(world->has_resolver());
  EXPECT_EQ(world->settings().dt, 0.01);
  // One free step under gravity (nothing resolves the joint): Δv = g·dt exactly.
  world->step();
  EXPECT_NEAR(world->bodies()[1].velocity.z(), -0.1, 1e-12);
  EXPECT_EQ(world->bodies()[0].velocity, Vec3::Zero());
}

TEST(BuildWorld, UnknownPluginNamesTheSceneLine) {
  PluginHost host;
  const Scene scene = test::load(kScene, {{"modules.integrator", "eulerr"}});
  try {
    build_world(scene, host);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_TRUE(message.starts_with("--set modules.integrator: ")) << message;
    EXPECT_NE(message.find("eulerr"), std::string::npos) << message;
  }
}

TEST(BuildWorld, UnknownPluginOptionNamesWhereItWasWritten) {
  PluginHost host;
  const Scene scene = test::load(kScene, {{"modules.integrator.bogus", "1"}});
  try {
    build_world(scene, host);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_TRUE(message.starts_with("scene.yaml:4:15: ")) << message;  // the plugin name's position
    EXPECT_NE(message.find("'bogus' (--set modules.integrator.bogus)"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace impetus
