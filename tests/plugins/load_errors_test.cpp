// One test per way a plugin can fail to load. Each asserts that impetus::Error is thrown and that its
// message names the problem, the file tried, and the expected and found values.
#include "larger_contact.hpp"
#include "plugin_test_support.hpp"

#include <cinttypes>
#include <cstdio>

namespace {

using namespace impetus_test;
using impetus::ModuleKind;
using impetus::PluginRequest;

/// "…: cannot load integrator plugin 'NAME' from PATH: "
std::string load_failure(const std::string& name) {
  return "cannot load integrator plugin '" + name + "' from " + integrator_fixture(name).string() + ": ";
}

TEST(PluginLoadErrors, DlopenFailureGivesTheLoaderText) {
  auto host = fixture_host();
  const std::string message =
      error_message([&] { host.create_integrator(integrator_request("fixture_unresolved", "scene.yaml:4:15")); });
  EXPECT_EQ(message.rfind("scene.yaml:4:15: ", 0), 0u) << message;
  expect_contains(message, {load_failure("fixture_unresolved") + "dlopen failed: ", "undefined symbol",
                            "impetus_fixture_nobody_defines_this"});
}

TEST(PluginLoadErrors, MissingEntrySymbol) {
  auto host = fixture_host();
  const std::string message = error_message([&] { host.create_integrator(integrator_request("fixture_no_entry")); });
  expect_contains(message, {load_failure("fixture_no_entry"),
                            "does not export the entry symbol 'impetus_plugin_descriptor'"});
}

TEST(PluginLoadErrors, AbiVersionMismatchShowsBothVersions) {
  auto host = fixture_host();
  const std::string message = error_message([&] { host.create_integrator(integrator_request("fixture_abi")); });
  expect_contains(message, {load_failure("fixture_abi") + "ABI version mismatch",
                            "built for plugin ABI " + std::to_string(impetus::kPluginAbiVersion + 41),
                            "this Impetus uses ABI " + std::to_string(impetus::kPluginAbiVersion)});
}

TEST(PluginLoadErrors, DescriptorSizeMismatchShowsBothSizes) {
  auto host = fixture_host();
  const std::string message = error_message([&] { host.create_integrator(integrator_request("fixture_size")); });
  // The fixture's descriptor is PluginDescriptor plus one pointer.
  expect_contains(message, {load_failure("fixture_size") + "descriptor size mismatch",
                            "is " + std::to_string(sizeof(impetus::PluginDescriptor) + sizeof(void*)) + " bytes",
                            "this Impetus's is " + std::to_string(sizeof(impetus::PluginDescriptor)) + " bytes"});
}

TEST(PluginLoadErrors, ConfigWordMismatchDescribesBothBuilds) {
  auto host = fixture_host();
  const std::string message = error_message([&] { host.create_integrator(integrator_request("fixture_config")); });
  const std::uint64_t host_word = impetus::plugin_config_word();
  const std::uint64_t plugin_word = host_word ^ impetus::config_bits::glibcxx_debug;
  expect_contains(message, {load_failure("fixture_config") + "build configuration mismatch",
                            "the plugin was built with [" + impetus::describe_config_word(plugin_word) + "]",
                            "this Impetus with [" + impetus::describe_config_word(host_word) + "]"});
}

// fixture_layout reports the layout word of a Contact with one more field: the host refuses it and
// names impetus::Contact with both words, and no other type (every other word agrees).
TEST(PluginLoadErrors, LayoutMismatchNamesTheTypeThatDiffers) {
  auto host = fixture_host();
  const std::string message = error_message([&] { host.create_integrator(integrator_request("fixture_layout")); });
  const impetus::LayoutWords host_words = impetus::plugin_layout_words();
  const std::uint64_t host_contact = host_words[static_cast<std::size_t>(impetus::LayoutType::contact)];
  const std::uint64_t plugin_contact = impetus_fixtures::larger_contact_layout_word();
  ASSERT_NE(plugin_contact, host_contact);
  char expected[160];
  std::snprintf(expected, sizeof expected, "impetus::Contact (plugin: 0x%016" PRIx64 ", host: 0x%016" PRIx64 ")",
                plugin_contact, host_contact);
  expect_contains(message, {load_failure("fixture_layout") +
                                "layout mismatch: the plugin was built with a different layout of " + expected,
                            "; rebuild it against this Impetus"});
  for (std::size_t type = 0; type < impetus::kLayoutTypeCount; ++type) {
    if (type == static_cast<std::size_t>(impetus::LayoutType::contact)) continue;
    EXPECT_EQ(message.find(std::string(impetus::kLayoutTypeNames[type]) + " ("), std::string::npos)
        << impetus::kLayoutTypeNames[type] << " agrees and must not be named: " << message;
  }
}

TEST(PluginLoadErrors, WrongKindFoundByName) {
  auto host = fixture_host();
  const std::string message = error_message([&] { host.create_integrator(integrator_request("fixture_kind")); });
  expect_contains(message, {load_failure("fixture_kind") + "wrong kind: it declares a resolver named "
                            "'fixture_kind', expected an integrator"});
}

TEST(PluginLoadErrors, WrongKindGivenAsFile) {
  auto host = fixture_host();
  PluginRequest request;
  request.file = integrator_fixture("fixture_good");
  const std::string message = error_message([&] { host.create_resolver(request); });
  expect_contains(message, {"cannot load resolver plugin from " + request.file.string(),
                            "it declares an integrator named 'fixture_good', expected a resolver"});
}

TEST(PluginLoadErrors, NameMismatchFoundByName) {
  auto host = fixture_host();
  const std::string message =
      error_message([&] { host.create_integrator(integrator_request("fixture_misnamed")); });
  expect_contains(message, {load_failure("fixture_misnamed") +
                            "name mismatch: it declares 'fixture_other', expected 'fixture_misnamed'"});
}

TEST(PluginLoadErrors, NameMismatchGivenAsFile) {
  auto host = fixture_host();
  PluginRequest request = integrator_request("fixture_good");
  request.file = integrator_fixture("fixture_dup");
  const std::string message = error_message([&] { host.create_integrator(request); });
  expect_contains(message, {request.file.string(), "it declares 'fixture_dup', expected 'fixture_good'"});
}

TEST(PluginLoadErrors, FactoryFailureCarriesThePluginsMessage) {
  auto host = fixture_host();
  const std::string message = error_message([&] { host.create_integrator(integrator_request("fixture_throws")); });
  expect_contains(message, {load_failure("fixture_throws") + "its factory failed: "
                            "fixture_throws: this constructor always fails"});
  EXPECT_FALSE(is_loaded(integrator_fixture("fixture_throws"))) << "nothing was created, nothing stays loaded";
}

TEST(PluginLoadErrors, BadOptionValueIsReportedThroughTheFactory) {
  auto host = fixture_host();
  impetus::ModuleOptions options("plugin 'fixture_good' (integrator)");
  options.set("scale", option("fast", "scene.yaml:7:12"));
  PluginRequest request = integrator_request("fixture_good");
  request.options = &options;
  const std::string message = error_message([&] { host.create_integrator(request); });
  expect_contains(message, {load_failure("fixture_good") + "its factory failed: ",
                            "scene.yaml:7:12: plugin 'fixture_good' (integrator) option 'scale' expects a "
                            "finite number, got 'fast'"});
}

TEST(PluginLoadErrors, DuplicateLibraryForOneKindAndName) {
  auto host = fixture_host();
  auto first = host.create_integrator(integrator_request("fixture_dup"));
  PluginRequest second = integrator_request("fixture_dup");
  second.file = fixture_dir() / "impetus_copy_of_fixture_dup.so";
  const std::string message = error_message([&] { host.create_integrator(second); });
  expect_contains(message, {"cannot load integrator plugin 'fixture_dup' from " + second.file.string(),
                            "duplicate: integrator plugin 'fixture_dup' is already loaded from " +
                                fs::canonical(integrator_fixture("fixture_dup")).string()});
  // Once the first library is gone, the other file may provide the plugin.
  first.reset();
  EXPECT_NE(host.create_integrator(second), nullptr);
}

TEST(PluginLoadErrors, UnknownOptionNamesPluginKeyPlaceAndKnownOptions) {
  auto host = fixture_host();
  impetus::ModuleOptions options("plugin 'fixture_good' (integrator)");
  options.set("scale", option("2", "scene.yaml:3:5"));
  options.set("sacle", option("3", "scene.yaml:4:5"));
  PluginRequest request = integrator_request("fixture_good", "scene.yaml:2:3");
  request.options = &options;
  const std::string message = error_message([&] { host.create_integrator(request); });
  EXPECT_EQ(message.rfind("scene.yaml:2:3: ", 0), 0u) << message;
  expect_contains(message, {"plugin 'fixture_good' (integrator) has no option 'sacle' (scene.yaml:4:5); "
                            "its options are: scale",
                            integrator_fixture("fixture_good").string()});
  EXPECT_FALSE(is_loaded(integrator_fixture("fixture_good"))) << "the rejected module was destroyed";
}

TEST(PluginLoadErrors, UnknownOptionOfAPluginWithoutOptions) {
  auto host = fixture_host();
  impetus::ModuleOptions options;
  options.set("speed", option("1", "--set"));
  PluginRequest request = integrator_request("fixture_dup");
  request.options = &options;
  expect_contains(error_message([&] { host.create_integrator(request); }),
                  {"plugin 'fixture_dup' (integrator) has no option 'speed' (--set); it takes no options"});
}

TEST(PluginLoadErrors, ExplicitFileThatDoesNotExist) {
  auto host = fixture_host();
  PluginRequest request = integrator_request("euler", "scene.yaml:9:9");
  request.file = "/nonexistent/impetus_integrator_euler.so";
  expect_contains(error_message([&] { host.create_integrator(request); }),
                  {"scene.yaml:9:9: cannot load integrator plugin 'euler': file "
                   "/nonexistent/impetus_integrator_euler.so does not exist"});
}

TEST(PluginLoadErrors, EmptyOrPathLikeName) {
  auto host = fixture_host();
  expect_contains(error_message([&] { host.create_detector(PluginRequest{}); }),
                  {"no detector plugin given: the name is empty"});
  PluginRequest request;
  request.name = "../fixture_good";
  expect_contains(error_message([&] { host.create_integrator(request); }),
                  {"'../fixture_good' is not a plugin name"});
}

}  // namespace
