// discover(): every library in the search path, what each provides or why it cannot be used, and which
// plugins are hidden by an earlier directory.
#include "plugin_test_support.hpp"

#include <algorithm>

namespace {

using namespace impetus_test;

const impetus::PluginInfo* find_plugin(const impetus::PluginListing& listing, const fs::path& path) {
  for (const auto& info : listing.plugins)
    if (info.path == path) return &info;
  return nullptr;
}

/// The reason given for `path`, or "" (with a test failure) if it was not reported as broken.
std::string failure_reason(const impetus::PluginListing& listing, const fs::path& path) {
  for (const auto& failure : listing.failures)
    if (failure.path == path) return failure.reason;
  ADD_FAILURE() << path << " was not reported as a failure";
  return {};
}

TEST(PluginDiscover, ListsGoodPluginsAndReportsEveryBrokenFixture) {
  auto host = fixture_host();
  const impetus::PluginListing listing = host.discover();
  EXPECT_EQ(listing.searched, host.search_path());

  const impetus::PluginInfo* good = find_plugin(listing, integrator_fixture("fixture_good"));
  ASSERT_NE(good, nullptr);
  EXPECT_EQ(good->kind, impetus::ModuleKind::integrator);
  EXPECT_EQ(good->name, "fixture_good");
  EXPECT_EQ(good->version, "0.0.1");
  EXPECT_EQ(good->summary, "test fixture: v += scale * dt * g");
  EXPECT_FALSE(good->shadowed);
  // Loading is enough to be listed: the factory of fixture_throws only fails when called.
  for (const char* name : {"fixture_dup", "fixture_throws", "my_integrator"})
    EXPECT_NE(find_plugin(listing, integrator_fixture(name)), nullptr) << name;

  const std::pair<const char*, std::string> broken[] = {
      {"fixture_unresolved", "dlopen failed: "},
      {"fixture_no_entry", "does not export the entry symbol 'impetus_plugin_descriptor'"},
      {"fixture_abi", "ABI version mismatch"},
      {"fixture_size", "descriptor size mismatch"},
      {"fixture_config", "build configuration mismatch"},
      {"fixture_layout", "layout mismatch: the plugin was built with a different layout of impetus::Contact"},
      {"fixture_kind", "wrong kind: it declares a resolver named 'fixture_kind', expected an integrator"},
      {"fixture_misnamed", "name mismatch: it declares 'fixture_other', expected 'fixture_misnamed'"},
  };
  for (const auto& [name, reason] : broken)
    expect_contains(failure_reason(listing, integrator_fixture(name)), {reason});
  expect_contains(failure_reason(listing, fixture_dir() / "impetus_copy_of_fixture_dup.so"),
                  {"duplicate: integrator plugin 'fixture_dup' is also provided by " +
                       integrator_fixture("fixture_dup").string() + " in the same directory"});

  // Exactly the fixtures above, nothing else, from the fixture directory.
  const auto in_fixture_dir = [](const fs::path& p) { return p.parent_path() == fixture_dir(); };
  EXPECT_EQ(std::count_if(listing.failures.begin(), listing.failures.end(),
                          [&](const auto& f) { return in_fixture_dir(f.path); }),
            9);
  EXPECT_FALSE(is_loaded(integrator_fixture("fixture_good"))) << "discover does not keep libraries";
}

TEST(PluginDiscover, SameKindAndNameInALaterDirectoryIsShadowed) {
  TempDir first("first");
  const fs::path earlier = first.copy(integrator_fixture("fixture_good"));
  auto host = host_with({first.path(), fixture_dir()});
  const impetus::PluginListing listing = host.discover();
  const impetus::PluginInfo* winner = find_plugin(listing, earlier);
  const impetus::PluginInfo* hidden = find_plugin(listing, integrator_fixture("fixture_good"));
  ASSERT_NE(winner, nullptr);
  ASSERT_NE(hidden, nullptr);
  EXPECT_FALSE(winner->shadowed);
  EXPECT_TRUE(hidden->shadowed);
}

TEST(PluginDiscover, EmptyAndMissingDirectoriesAreNotErrors) {
  TempDir empty("empty");
  auto host = host_with({empty.path(), empty.path() / "missing"});
  const impetus::PluginListing listing = host.discover();
  EXPECT_EQ(listing.searched.size(), host.search_path().size());
  for (const auto& info : listing.plugins) EXPECT_NE(info.path.parent_path(), empty.path());
}

TEST(PluginDiscover, ALibraryInUseIsReusedNotReloaded) {
  auto host = fixture_host();
  auto module = host.create_integrator(integrator_request("fixture_good"));
  const impetus::PluginListing listing = host.discover();
  ASSERT_NE(find_plugin(listing, integrator_fixture("fixture_good")), nullptr);
  EXPECT_TRUE(is_loaded(integrator_fixture("fixture_good")));
  module.reset();
  EXPECT_FALSE(is_loaded(integrator_fixture("fixture_good")));
}

}  // namespace
