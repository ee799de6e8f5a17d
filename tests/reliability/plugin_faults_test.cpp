// Plugin faults, each handled: a factory that throws or returns null (with and without a message), a
// library whose host goes away while modules (and a whole World) still use it, and two libraries with
// the same kind and name in different directories.

#include "impetus/core/mass.hpp"
#include "reliability_support.hpp"

#include <dlfcn.h>

namespace impetus::reliability {
namespace {

fs::path fixture(const std::string& name) { return fixture_dir() / ("impetus_integrator_" + name + ".so"); }

bool is_loaded(const fs::path& file) {
  void* handle = dlopen(fs::canonical(file).c_str(), RTLD_NOW | RTLD_NOLOAD);
  if (handle != nullptr) dlclose(handle);  // NOLOAD still took a reference
  return handle != nullptr;
}

PluginHost host_searching(const std::vector<fs::path>& dirs) {
  PluginHost host;
  host.prepend_directories(dirs);
  return host;
}

PluginRequest request(const std::string& name) {
  PluginRequest r;
  r.name = name;
  r.where = "scene.yaml:3:15";
  return r;
}

// One falling body, stepped by `integrator`.
std::unique_ptr<World> falling_world(std::shared_ptr<Integrator> integrator) {
  auto world = std::make_unique<World>();
  RigidBody body;
  body.name = "ball";
  body.shape = Sphere{0.5};
  set_primitive_mass(body, 1.0);
  world->add_body(body);
  world->set_integrator(std::move(integrator));
  return world;
}

struct FactoryCase {
  const char* fixture;
  const char* expected;
};

class FaultyFactory : public testing::TestWithParam<FactoryCase> {};

TEST_P(FaultyFactory, IsAnErrorNamingThePluginAndNothingStaysLoaded) {
  auto host = host_searching({fixture_dir()});
  const std::string message = error_of([&] { host.create_integrator(request(GetParam().fixture)); });
  EXPECT_EQ(message.rfind("scene.yaml:3:15: cannot load integrator plugin '" + std::string(GetParam().fixture) +
                              "' from " + fixture(GetParam().fixture).string() + ": its factory failed: ",
                          0),
            0u)
      << message;
  EXPECT_NE(message.find(GetParam().expected), std::string::npos) << message;
  EXPECT_FALSE(is_loaded(fixture(GetParam().fixture)));
  // The host is still usable afterwards.
  EXPECT_NE(host.create_integrator(request("fixture_good")), nullptr);
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, FaultyFactory,
    testing::Values(FactoryCase{"fixture_throws", "fixture_throws: this constructor always fails"},
                    FactoryCase{"fixture_null", "it returned no module and no message"},
                    FactoryCase{"fixture_null_message", "fixture_null_message: no module today"}),
    [](const testing::TestParamInfo<FactoryCase>& info) { return std::string(info.param.fixture); });

// The library stays loaded while any module it made lives, even after its host is gone, and the
// module's code keeps running; it is unloaded with the last module.
TEST(PluginLifetime, AWorldOutlivesTheHostThatLoadedItsModules) {
  std::unique_ptr<World> world;
  {
    const auto host = make_host();
    world = build_world(load_scene_text("modules: {integrator: fixture_good, detector: none, resolver: none}\n"
                                        "bodies:\n  - {name: ball, shape: {sphere: {radius: 0.5}}, mass: 1}\n",
                                        "scene.yaml", "."),
                        *host);
  }
  ASSERT_TRUE(is_loaded(fixture("fixture_good")));
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(world->step().ok);
  // fixture_good: v += dt·g each step (scale 1), x += dt·v. Exact to rounding, 1e-12.
  EXPECT_NEAR(world->bodies()[0].velocity.z(), -9.81 * 10 * 1e-3, 1e-12);
  world.reset();
  EXPECT_FALSE(is_loaded(fixture("fixture_good"))) << "the last module gone, the library is unloaded";
}

TEST(PluginLifetime, ModulesOfOneLibraryKeepItUntilTheLastIsGone) {
  std::shared_ptr<Integrator> a, b;
  {
    auto host = host_searching({fixture_dir()});
    a = host.create_integrator(request("fixture_good"));
    b = host.create_integrator(request("fixture_good"));
  }
  const auto world_a = falling_world(a);
  a.reset();
  ASSERT_TRUE(is_loaded(fixture("fixture_good"))) << "world_a still holds a module";
  EXPECT_TRUE(world_a->step().ok);
  b.reset();
  EXPECT_TRUE(is_loaded(fixture("fixture_good")));
  world_a->set_integrator(nullptr);
  EXPECT_FALSE(is_loaded(fixture("fixture_good")));
}

// Two different files, both integrator 'fixture_good', in two directories.
class SameNameTwoDirectories : public testing::Test {
 protected:
  Scratch first{"first"}, second{"second"};
  fs::path first_file = first.path() / "impetus_integrator_fixture_good.so";
  fs::path second_file = second.path() / "impetus_integrator_fixture_good.so";
  void SetUp() override {
    fs::copy_file(fixture("fixture_good"), first_file);
    fs::copy_file(fixture("fixture_good"), second_file);
  }
};

TEST_F(SameNameTwoDirectories, TheFirstDirectoryWinsAndTheOtherIsListedAsShadowed) {
  auto host = host_searching({first.path(), second.path()});
  auto module = host.create_integrator(request("fixture_good"));
  EXPECT_TRUE(is_loaded(first_file));
  EXPECT_FALSE(is_loaded(second_file));
  const PluginListing listing = host.discover();
  int found = 0;
  for (const PluginInfo& info : listing.plugins) {
    if (info.path == first_file) {
      EXPECT_FALSE(info.shadowed);
      ++found;
    }
    if (info.path == second_file) {
      EXPECT_TRUE(info.shadowed);
      ++found;
    }
  }
  EXPECT_EQ(found, 2);
}

TEST_F(SameNameTwoDirectories, OneHostRefusesTheSecondLibraryWhileTheFirstIsInUse) {
  auto host = host_searching({first.path(), second.path()});
  auto module = host.create_integrator(request("fixture_good"));
  PluginRequest other = request("fixture_good");
  other.file = second_file;
  const std::string message = error_of([&] { host.create_integrator(other); });
  EXPECT_NE(message.find("duplicate: integrator plugin 'fixture_good' is already loaded from " +
                         fs::canonical(first_file).string()),
            std::string::npos)
      << message;
  module.reset();
  EXPECT_NE(host.create_integrator(other), nullptr) << "once the first is gone, the other may provide it";
}

TEST_F(SameNameTwoDirectories, TwoHostsMayEachUseTheirOwnAndBothRun) {
  auto host_a = host_searching({first.path()});
  auto host_b = host_searching({second.path()});
  const auto a = falling_world(host_a.create_integrator(request("fixture_good")));
  const auto b = falling_world(host_b.create_integrator(request("fixture_good")));
  EXPECT_TRUE(is_loaded(first_file));
  EXPECT_TRUE(is_loaded(second_file));
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(a->step().ok);
    ASSERT_TRUE(b->step().ok);
  }
  // The same code in two copies: the same trajectory, bit for bit (RTLD_LOCAL keeps them apart).
  EXPECT_EQ(state_bits(*a), state_bits(*b));
  EXPECT_NE(a->bodies()[0].velocity.z(), 0.0);
}

}  // namespace
}  // namespace impetus::reliability
