// The success path: a module is created, runs the plugin's code, keeps its library loaded for as long as
// it lives (even after the host is gone), and the library is unloaded after the last module goes, unless
// it was built to stay loaded.
#include "plugin_test_support.hpp"

#include <memory>

namespace {

using namespace impetus_test;
using impetus::PluginRequest;

/// One step of the good fixture on one free body: v = scale · dt · g (it starts at rest).
void expect_fixture_good_runs(impetus::Integrator& integrator, double scale) {
  std::vector<impetus::RigidBody> bodies(1);
  impetus::StepContext ctx;
  ctx.dt = 0.01;
  impetus::IntegratorCounters counters;
  integrator.integrate_velocities(bodies, ctx, counters);
  EXPECT_EQ(counters.bodies, 1u);
  EXPECT_DOUBLE_EQ(bodies[0].velocity.z(), scale * 0.01 * -9.81);
}

TEST(PluginLoad, CreatesAModuleThatRunsThePluginsCode) {
  auto host = fixture_host();
  impetus::ModuleOptions options("plugin 'fixture_good' (integrator)");
  options.set("scale", option("2", "scene.yaml:3:5"));
  PluginRequest request = integrator_request("fixture_good");
  request.options = &options;
  const auto integrator = host.create_integrator(request);
  ASSERT_NE(integrator, nullptr);
  expect_fixture_good_runs(*integrator, 2.0);
}

TEST(PluginLoad, NullOptionsMeanNoOptions) {
  auto host = fixture_host();
  const auto integrator = host.create_integrator(integrator_request("fixture_good"));
  ASSERT_NE(integrator, nullptr);
  expect_fixture_good_runs(*integrator, 1.0);  // the default scale
}

TEST(PluginLoad, ModuleOutlivesTheHostAndTheLibraryIsUnloadedAfterIt) {
  const fs::path file = integrator_fixture("fixture_good");
  ASSERT_FALSE(is_loaded(file));
  auto host = std::make_unique<impetus::PluginHost>(fixture_host());
  auto integrator = host->create_integrator(integrator_request("fixture_good"));
  EXPECT_TRUE(is_loaded(file));
  host.reset();
  EXPECT_TRUE(is_loaded(file)) << "the module holds its library, not the host";
  expect_fixture_good_runs(*integrator, 1.0);
  integrator.reset();
  EXPECT_FALSE(is_loaded(file)) << "the last module released its library";
}

TEST(PluginLoad, ShippedPluginsWithAThreadPoolStayLoadedAfterTheirLastModule) {
  // fcl and ledas run oneTBB's workers, which outlive the call that started them: their libraries are
  // built STAYS_LOADED (-z nodelete), so releasing the last module must leave them mapped (plugins/README.md).
  // mirtich starts no thread and is unloaded as usual.
  auto host = host_with({});
  const fs::path dir(IMPETUS_PLUGIN_DIR);
  impetus::PluginRequest request;
  request.kind = impetus::ModuleKind::detector;
  request.name = "fcl";
  auto detector = host.create_detector(request);
  ASSERT_NE(detector, nullptr);
  request.kind = impetus::ModuleKind::resolver;
  request.name = "ledas";
  auto ledas = host.create_resolver(request);
  ASSERT_NE(ledas, nullptr);
  request.name = "mirtich";
  auto mirtich = host.create_resolver(request);
  ASSERT_NE(mirtich, nullptr);
  detector.reset();
  ledas.reset();
  mirtich.reset();
  EXPECT_TRUE(is_loaded(dir / "impetus_detector_fcl.so"));
  EXPECT_TRUE(is_loaded(dir / "impetus_resolver_ledas.so"));
  EXPECT_FALSE(is_loaded(dir / "impetus_resolver_mirtich.so"));
}

TEST(PluginLoad, ModulesOfOneLibraryShareIt) {
  const fs::path file = integrator_fixture("fixture_good");
  auto host = fixture_host();
  auto first = host.create_integrator(integrator_request("fixture_good"));
  auto second = host.create_integrator(integrator_request("fixture_good"));
  EXPECT_NE(first, second);
  first.reset();
  EXPECT_TRUE(is_loaded(file));
  expect_fixture_good_runs(*second, 1.0);
  second.reset();
  EXPECT_FALSE(is_loaded(file));
}

TEST(PluginLoad, ExplicitFileOutsideTheSearchPathWithAnyFileName) {
  TempDir dir("explicit");
  const fs::path copy = dir.copy(integrator_fixture("fixture_good"), "my-build-of-good.so");
  auto host = host_with({});
  PluginRequest request;  // no name: the file decides
  request.file = copy;
  auto integrator = host.create_integrator(request);
  ASSERT_NE(integrator, nullptr);
  EXPECT_TRUE(is_loaded(copy));
  EXPECT_FALSE(is_loaded(integrator_fixture("fixture_good")));
  expect_fixture_good_runs(*integrator, 1.0);

  request.name = "fixture_good";  // with a name, the file must declare it
  EXPECT_NE(host.create_integrator(request), nullptr);
}

TEST(PluginLoad, TheTemplatePluginBuildsLoadsAndReadsItsOption) {
  auto host = fixture_host();
  impetus::ModuleOptions options("plugin 'my_integrator' (integrator)");
  options.set("damping", option("0.5", "scene.yaml:3:5"));
  PluginRequest request = integrator_request("my_integrator");
  request.options = &options;
  const auto integrator = host.create_integrator(request);
  ASSERT_NE(integrator, nullptr);
  // One step from rest: v = dt g / (1 + damping dt).
  std::vector<impetus::RigidBody> bodies(1);
  impetus::StepContext ctx;
  impetus::IntegratorCounters counters;
  integrator->integrate_velocities(bodies, ctx, counters);
  EXPECT_NEAR(bodies[0].velocity.z(), ctx.dt * -9.81 / (1.0 + 0.5 * ctx.dt), 1e-15);
}

}  // namespace
