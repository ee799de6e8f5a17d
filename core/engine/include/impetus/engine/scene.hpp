#pragma once
/// \file
/// Scene files (YAML): loading, overriding with `--set`, and building a World from them.
/// The format is documented key by key in README.md, "Scene files". Unknown keys, wrong
/// types, non-finite numbers and out-of-range values are errors naming file, line and column.

#include "impetus/engine/world.hpp"
#include "impetus/modules/options.hpp"

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace impetus {

class PluginHost;

/// Which plugin to use for one module, with its options, as a scene or the command line gave it.
struct ModuleRequest {
  std::string plugin;             ///< plugin name, or "none" (detector and resolver only)
  std::filesystem::path path;     ///< explicit library file (empty: search by name)
  ModuleOptions options;          ///< everything else in the module's mapping
  std::string where;              ///< "scene.yaml:4:15" for messages
};

/// A `KEY=VALUE` override from the command line (`--set modules.resolver.mode=paper`).
struct SceneOverride {
  std::string key;    ///< dotted path; list elements by index or, in `bodies`, by name
  std::string value;  ///< YAML text (a scalar or a flow sequence like [0, 0, 1])
};

/// A loaded scene: settings, module requests, bodies (with mass properties) and constraints.
struct Scene {
  std::filesystem::path file;                 ///< the scene file (empty for one built in code)
  WorldSettings settings;
  ModuleRequest integrator;
  ModuleRequest detector;
  ModuleRequest resolver;
  std::vector<std::filesystem::path> plugin_path;  ///< extra plugin directories, highest precedence
  std::vector<RigidBody> bodies;
  std::vector<Constraint> constraints;
  /// Where each body was written, or the generator that made it ("<file>:<line>:<col>"), and where
  /// each constraint was, for errors found when the world is built (a resolver that refuses a body's
  /// friction or a constraint); may be empty for a scene built in code.
  std::vector<std::string> body_where;
  std::vector<std::string> constraint_where;  ///< (see body_where)
  /// Load-time warnings, each "<file>:<line>:<col>: <what>" (e.g. a mesh wound inward and flipped, or
  /// converted from centimetres); the CLI prints them on stderr.
  std::vector<std::string> warnings;
};

/// Bounds on what one scene may make, so that a few lines of text cannot ask for unbounded memory
/// (README, "Hostile input, second sweep"). A scene past one is refused at the body or generator
/// that crosses it, before that generator makes anything.
struct SceneLimits {
  /// Bodies written and generated, together: 2^20, room for the largest generated line (10^6
  /// spheres and its wall). Each generator alone is also bounded (a line by 10^6 spheres, a pyramid by
  /// 1,000 rows), but several of them are not. A body takes about 1 KB once in a World.
  std::size_t bodies = std::size_t{1} << 20;
};

/// Loads and validates a scene file, applying `overrides` first. Throws Error with file, line, column
/// and reason.
Scene load_scene(const std::filesystem::path& file, const std::vector<SceneOverride>& overrides = {},
                 const SceneLimits& limits = {});

/// Same from YAML text; `name` is used in messages and relative paths resolve against `base_dir`.
Scene load_scene_text(const std::string& yaml, const std::string& name,
                      const std::filesystem::path& base_dir,
                      const std::vector<SceneOverride>& overrides = {}, const SceneLimits& limits = {});

/// Parses "KEY=VALUE". Throws Error if there is no '=' or the key is empty.
SceneOverride parse_override(const std::string& text);

/// Builds a world from a scene: adds bodies and constraints and loads the requested plugins through
/// `host` (adding the scene's plugin_path to it). Throws Error on any failure.
std::unique_ptr<World> build_world(const Scene& scene, PluginHost& host);

}  // namespace impetus
