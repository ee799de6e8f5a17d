#pragma once
/// \file
/// The plugin host: finds, checks, loads and unloads module plugins.
///
/// Search order (first match wins): the scene's explicit file (`path:`) or directories (`plugin_path:`),
/// then each directory in the environment variable IMPETUS_PLUGIN_PATH (colon-separated), then the
/// directory `impetus/plugins` next to the loaded libimpetus_plugin_host.so (the same rule finds the build
/// tree's plugins and an installed, relocated copy's). A plugin for kind K and name N is the file
/// `impetus_K_N.so`; only the plugins a scene names are loaded.
///
/// Libraries are opened with dlopen(RTLD_NOW | RTLD_LOCAL) and stay loaded while any module they
/// created lives (each module's shared_ptr holds its library).

#include "impetus/modules/detector.hpp"
#include "impetus/modules/integrator.hpp"
#include "impetus/modules/options.hpp"
#include "impetus/modules/resolver.hpp"
#include "impetus/plugins/abi.hpp"

#include <concepts>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace impetus {

/// A plugin that loaded and passed every check.
struct PluginInfo {
  ModuleKind kind = ModuleKind::integrator;
  std::string name;
  std::string version;
  std::string summary;
  std::filesystem::path path;
  bool shadowed = false;  ///< an earlier directory in the search path has the same kind and name
};

/// A library in the search path that could not be used, and why.
struct PluginFailure {
  std::filesystem::path path;
  std::string reason;
};

/// Everything found in the search path.
struct PluginListing {
  std::vector<std::filesystem::path> searched;  ///< directories, in precedence order
  std::vector<PluginInfo> plugins;
  std::vector<PluginFailure> failures;
};

/// What to load: kind, name, optional explicit file, options, and where the request was written.
struct PluginRequest {
  ModuleKind kind = ModuleKind::integrator;
  std::string name;
  std::filesystem::path file;  ///< explicit library file; empty to search by name
  ModuleOptions* options = nullptr;  ///< may be null (no options)
  std::string where;           ///< "scene.yaml:5:3" or "--integrator", prefixed to messages
};

class LoadedLibrary;

/// Typed settings of a plugin (impetus/settings/): the options they stand for, and the plugin they
/// configure by default.
template <class Settings>
concept PluginSettings = requires(const Settings& s) {
  { s.to_options() } -> std::same_as<ModuleOptions>;
  { Settings::plugin_name } -> std::convertible_to<std::string>;
};

/// Finds and loads plugins. Not thread-safe; one per process is typical but not required.
class PluginHost {
 public:
  /// Search path from IMPETUS_PLUGIN_PATH and the default directory.
  PluginHost();
  ~PluginHost();

  /// Adds directories searched before all others (e.g. a scene's plugin_path), in the given order.
  void prepend_directories(const std::vector<std::filesystem::path>& dirs);
  /// Directories searched, in precedence order.
  const std::vector<std::filesystem::path>& search_path() const { return search_path_; }
  /// `<directory of libimpetus_plugin_host.so>/impetus/plugins`.
  static std::filesystem::path default_directory();

  /// Loads the plugin and creates a module. Throws Error with a message for each failure: unknown name
  /// (listing the available plugins of that kind and the directories searched), dlopen failure (its
  /// text), missing entry symbol, ABI version or descriptor size mismatch, config word mismatch, layout
  /// mismatch (naming each type whose layout word differs), wrong kind, name mismatch, duplicate name
  /// (two different libraries loaded for one kind and name), a factory that fails (its message), or
  /// options the plugin does not know. Messages start with
  /// `request.where` and name the file tried; plugins/README.md lists them all.
  /// The kind is the function's (request.kind is ignored). With `request.file`, that file is loaded
  /// whatever its name, and must declare `request.name` if one is given; by name, the first
  /// `impetus_<kind>_<name>.so` in the search path is used (a broken one is an error, not skipped).
  /// An already open library (same canonical path) is reused.
  std::shared_ptr<Integrator> create_integrator(const PluginRequest& request);
  std::shared_ptr<CollisionDetector> create_detector(const PluginRequest& request);
  std::shared_ptr<CollisionResolver> create_resolver(const PluginRequest& request);

  /// Typed settings (impetus/settings/: LedasSettings, MirtichSettings, FclDetectorSettings,
  /// EulerSettings, …; any type with `ModuleOptions to_options() const` and `plugin_name`):
  /// `host.create_resolver(settings)` loads the plugin the type names with the options the settings
  /// stand for; `host.create_resolver("name", settings)` loads another plugin that reads the same
  /// options. The options go through the same checks as a scene's; messages start with "code".
  template <PluginSettings Settings>
  std::shared_ptr<Integrator> create_integrator(const Settings& settings, const std::string& name = Settings::plugin_name) {
    ModuleOptions options = settings.to_options();
    return create_integrator(typed_request(ModuleKind::integrator, name, options));
  }
  template <PluginSettings Settings>
  std::shared_ptr<CollisionDetector> create_detector(const Settings& settings, const std::string& name = Settings::plugin_name) {
    ModuleOptions options = settings.to_options();
    return create_detector(typed_request(ModuleKind::detector, name, options));
  }
  template <PluginSettings Settings>
  std::shared_ptr<CollisionResolver> create_resolver(const Settings& settings, const std::string& name = Settings::plugin_name) {
    ModuleOptions options = settings.to_options();
    return create_resolver(typed_request(ModuleKind::resolver, name, options));
  }
  std::shared_ptr<Integrator> create_integrator(const std::string& name, const PluginSettings auto& settings) {
    return create_integrator(settings, name);
  }
  std::shared_ptr<CollisionDetector> create_detector(const std::string& name, const PluginSettings auto& settings) {
    return create_detector(settings, name);
  }
  std::shared_ptr<CollisionResolver> create_resolver(const std::string& name, const PluginSettings auto& settings) {
    return create_resolver(settings, name);
  }

  /// Loads every `impetus_*.so` in the search path and reports what each is, or why it failed. A file
  /// named `impetus_<kind>_<name>.so` must declare that kind and name. A kind+name already found in an
  /// earlier directory is listed as shadowed; found twice in one directory, the second file (files
  /// reachable by name first, then by file name) is a failure. Libraries not in use are unloaded again.
  PluginListing discover();

 private:
  std::shared_ptr<void> create(const PluginRequest& request);
  static PluginRequest typed_request(ModuleKind kind, const std::string& name, ModuleOptions& options) {
    PluginRequest request;
    request.kind = kind;
    request.name = name;
    request.options = &options;
    request.where = "code";
    return request;
  }
  // Opens `file` (or reuses it if already open) and runs the ABI checks; null with `reason` on failure.
  std::shared_ptr<LoadedLibrary> load(const std::filesystem::path& file, std::string& reason);
  // First `impetus_<kind>_<name>.so` in the search path; empty if none.
  std::filesystem::path find_by_name(ModuleKind kind, const std::string& name) const;
  // The "no such plugin" message: what was searched and which plugins of that kind exist.
  std::string unknown_name_message(const PluginRequest& request);

  std::vector<std::filesystem::path> search_path_;
  std::map<std::filesystem::path, std::weak_ptr<LoadedLibrary>> open_;  // by canonical path
  std::map<std::pair<ModuleKind, std::string>, std::filesystem::path> registered_;  // kind+name → file
};

}  // namespace impetus
