// Where the host looks: prepended (scene) directories, then IMPETUS_PLUGIN_PATH, then the directory next
// to libimpetus_plugin_host.so; and what it says when a name is found nowhere.
#include "plugin_test_support.hpp"

namespace {

using namespace impetus_test;
using impetus::PluginHost;

TEST(PluginSearch, DefaultDirectoryIsNextToTheCoreLibrary) {
  // The build tree mirrors the install tree: <build>/lib/impetus/plugins.
  EXPECT_EQ(fs::weakly_canonical(PluginHost::default_directory()), fs::weakly_canonical(IMPETUS_PLUGIN_DIR));
  ScopedEnv no_env("IMPETUS_PLUGIN_PATH", std::nullopt);
  PluginHost host;
  ASSERT_EQ(host.search_path().size(), 1u);
  EXPECT_EQ(host.search_path()[0], PluginHost::default_directory());
}

TEST(PluginSearch, EnvironmentPathInOrderWithEmptyEntriesIgnored) {
  TempDir a("env-a"), b("env-b");
  ScopedEnv env("IMPETUS_PLUGIN_PATH", ":" + a.path().string() + "::" + b.path().string() + ":");
  PluginHost host;
  const std::vector<fs::path> expected{a.path(), b.path(), PluginHost::default_directory()};
  EXPECT_EQ(host.search_path(), expected);
}

TEST(PluginSearch, PrependedDirectoriesComeBeforeTheEnvironment) {
  TempDir scene("scene"), env_dir("env");
  ScopedEnv env("IMPETUS_PLUGIN_PATH", env_dir.path().string());
  PluginHost host;
  host.prepend_directories({scene.path(), env_dir.path()});  // a repeated directory keeps its first place
  const std::vector<fs::path> expected{scene.path(), env_dir.path(), PluginHost::default_directory()};
  EXPECT_EQ(host.search_path(), expected);
}

TEST(PluginSearch, FirstDirectoryWithTheFileWins) {
  TempDir scene("scene"), env_dir("env");
  const fs::path in_scene = scene.copy(integrator_fixture("fixture_good"));
  const fs::path in_env = env_dir.copy(integrator_fixture("fixture_good"));
  ScopedEnv env("IMPETUS_PLUGIN_PATH", env_dir.path().string() + ":" + fixture_dir().string());

  // The environment before the fixture directory (and the default one).
  PluginHost env_only;
  auto from_env = env_only.create_integrator(integrator_request("fixture_good"));
  EXPECT_TRUE(is_loaded(in_env));
  EXPECT_FALSE(is_loaded(integrator_fixture("fixture_good")));
  from_env.reset();

  // The scene's directories before the environment.
  PluginHost with_scene;
  with_scene.prepend_directories({scene.path()});
  auto from_scene = with_scene.create_integrator(integrator_request("fixture_good"));
  EXPECT_TRUE(is_loaded(in_scene));
  EXPECT_FALSE(is_loaded(in_env));
}

TEST(PluginSearch, UnknownNameListsSearchedDirectoriesAndAvailablePlugins) {
  const fs::path missing = fixture_dir() / "no-such-subdirectory";
  auto host = host_with({fixture_dir(), missing});
  const std::string message =
      error_message([&] { host.create_integrator(integrator_request("fixture_goood", "--integrator")); });
  EXPECT_EQ(message.rfind("--integrator: no integrator plugin named 'fixture_goood'; searched: ", 0), 0u) << message;
  expect_contains(message, {fixture_dir().string() + ", " + missing.string() + " (missing), " +
                                PluginHost::default_directory().string(),
                            "; available integrators: ", "fixture_dup", "fixture_good", "my_integrator",
                            "failed to load", "IMPETUS_PLUGIN_PATH"});
  EXPECT_EQ(message.find("fixture_other"), std::string::npos) << "a misnamed library is not available: " << message;
  EXPECT_FALSE(is_loaded(integrator_fixture("fixture_good"))) << "the listing did not keep libraries";
}

TEST(PluginSearch, UnknownNameOfAnotherKind) {
  auto host = fixture_host();
  const std::string message = error_message([&] {
    impetus::PluginRequest request;
    request.name = "fixture_kind";
    host.create_resolver(request);
  });
  // fixture_kind is a resolver, but in an integrator's file: not findable as a resolver by name.
  expect_contains(message, {"no resolver plugin named 'fixture_kind'", "available resolvers: "});
}

}  // namespace
