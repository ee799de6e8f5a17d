// `--set KEY=VALUE` overrides: applied to the YAML tree before validation, so an overridden value is
// checked like a written one, and messages about it name the override instead of a line.
#include "scene_test_support.hpp"

namespace impetus {
namespace {

using test::expect_error;
using test::load;
using test::load_error;

constexpr const char* kScene = R"(dt: 0.001
modules:
  integrator: euler
  detector: {plugin: fcl, margin: 1.0e-4}
  resolver: ledas
bodies:
  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1]}}}
  - {name: ball, shape: {sphere: {radius: 0.5}}, mass: 1, position: [0, 0, 0.5]}
)";

TEST(SceneOverride, ParseSplitsAtTheFirstEquals) {
  const SceneOverride o = parse_override("modules.resolver.mode=a=b");
  EXPECT_EQ(o.key, "modules.resolver.mode");
  EXPECT_EQ(o.value, "a=b");
  EXPECT_EQ(parse_override(" dt =0.01").key, "dt");
  EXPECT_EQ(parse_override("dt=").value, "");
  EXPECT_THROW(parse_override("dt"), Error);
  EXPECT_THROW(parse_override("=3"), Error);
}

TEST(SceneOverride, TopLevelNumber) {
  EXPECT_EQ(load(kScene, {{"dt", "0.01"}}).settings.dt, 0.01);
}

TEST(SceneOverride, ValueIsParsedAsYaml) {
  const Scene scene = load(kScene, {{"gravity", "[0, -1, 0]"}});
  EXPECT_EQ(scene.settings.gravity, Vec3(0, -1, 0));
}

TEST(SceneOverride, NestedModuleOptionOfALongFormModule) {
  const Scene scene = load(kScene, {{"modules.detector.margin", "2e-3"}});
  EXPECT_EQ(scene.detector.plugin, "fcl");
  EXPECT_EQ(scene.detector.options.values().at("margin").text, "2e-3");
  EXPECT_EQ(scene.detector.options.values().at("margin").where, "--set modules.detector.margin");
}

TEST(SceneOverride, OptionOnAShortFormModuleTurnsItIntoTheLongForm) {
  const Scene scene = load(kScene, {{"modules.resolver.mode", "paper"}});
  EXPECT_EQ(scene.resolver.plugin, "ledas");
  EXPECT_EQ(scene.resolver.where, "scene.yaml:5:13");  // the plugin name keeps its own location
  ASSERT_TRUE(scene.resolver.options.has("mode"));
  EXPECT_EQ(scene.resolver.options.values().at("mode").text, "paper");
  EXPECT_EQ(scene.resolver.options.label(), "plugin 'ledas' (resolver)");
}

TEST(SceneOverride, ModuleNameReplacesTheWholeModule) {
  const Scene scene = load(kScene, {{"modules.detector", "none"}, {"modules.integrator", "momentum"}});
  EXPECT_EQ(scene.detector.plugin, "none");
  EXPECT_TRUE(scene.detector.options.values().empty());
  EXPECT_EQ(scene.integrator.plugin, "momentum");
  EXPECT_EQ(scene.integrator.where, "--set modules.integrator");
}

TEST(SceneOverride, OptionOnAnOmittedModuleGoesToTheDefaultPlugin) {
  const Scene scene = load("bodies: []\n", {{"modules.detector.margin", "1e-3"}});
  EXPECT_EQ(scene.detector.plugin, "fcl");
  EXPECT_TRUE(scene.detector.options.has("margin"));
}

TEST(SceneOverride, BodyByNameAndByIndex) {
  const Scene by_name = load(kScene, {{"bodies.ball.mass", "2"}});
  EXPECT_EQ(by_name.bodies[1].mass, 2.0);
  const Scene by_index = load(kScene, {{"bodies.1.position", "[1, 2, 3]"}, {"bodies.ball.velocity", "[0, 0, -1]"}});
  EXPECT_EQ(by_index.bodies[1].position, Vec3(1, 2, 3));
  EXPECT_EQ(by_index.bodies[1].velocity, Vec3(0, 0, -1));
  const Scene shape = load(kScene, {{"bodies.ball.shape.sphere.radius", "0.25"}});
  EXPECT_EQ(std::get<Sphere>(shape.bodies[1].shape).radius, 0.25);
}

TEST(SceneOverride, LaterOverridesWin) {
  EXPECT_EQ(load(kScene, {{"dt", "0.01"}, {"dt", "0.02"}}).settings.dt, 0.02);
}

TEST(SceneOverride, UnknownBodyNameIsAnError) {
  EXPECT_EQ(load_error(kScene, {{"bodies.bal.mass", "2"}}), "--set bodies.bal.mass: no body named 'bal'");
}

TEST(SceneOverride, BadPathsAreErrors) {
  EXPECT_EQ(load_error(kScene, {{"bodies.5.mass", "2"}}), "--set bodies.5.mass: 'bodies' has 2 elements, no element 5");
  EXPECT_EQ(load_error(kScene, {{"dt.x", "2"}}), "--set dt.x: 'dt' is a single value, so it has no 'x'");
  EXPECT_EQ(load_error(kScene, {{"bodies..mass", "2"}}), "--set bodies..mass: the path has an empty part");
  EXPECT_EQ(load_error("generators: [{line: {count: 2}}]\n", {{"generators.first.line", "{}"}}),
            "--set generators.first.line: 'generators' is a list; select an element by its index, not 'first'");
  const std::string bad_yaml = load_error(kScene, {{"gravity", "[0, 0"}});
  EXPECT_TRUE(bad_yaml.starts_with("--set gravity: the value '[0, 0' is not valid YAML")) << bad_yaml;
}

TEST(SceneOverride, NewKeysAreValidatedLikeWrittenOnes) {
  // A typo creates a key, which validation then refuses, naming the override.
  expect_error(kScene, "--set graviti: unknown key 'graviti' in scene", "", {{"graviti", "[0, 0, 0]"}});
  expect_error(kScene, "--set bodies.ball.mas: unknown key 'mas' in body 'ball'", "", {{"bodies.ball.mas", "2"}});
}

TEST(SceneOverride, BadValuesNameTheOverride) {
  expect_error(kScene, "--set bodies.ball.mass: 'mass' must be positive, got -2", "", {{"bodies.ball.mass", "-2"}});
  expect_error(kScene, "--set dt: 'dt' must be a finite number, got '.nan'", "", {{"dt", ".nan"}});
  expect_error(kScene, "--set bodies.ball.position: 'position' expects a number, got 'x'", "",
               {{"bodies.ball.position", "[0, x, 0]"}});
  expect_error(kScene, "--set bodies.ball: 'mass' must be positive, got 0", "",
               {{"bodies.ball", "{name: ball, shape: {sphere: {radius: 1}}, mass: 0}"}});
  // A value written in the file keeps its line and column after overrides elsewhere.
  expect_error("bodies:\n  - {name: ball, shape: {sphere: {radius: 1}}, mass: -1}\n",
               "scene.yaml:2:54: 'mass' must be positive", "", {{"dt", "0.01"}, {"bodies.ball.velocity", "[1, 0, 0]"}});
}

}  // namespace
}  // namespace impetus
