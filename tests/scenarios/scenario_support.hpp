#pragma once
// Loading a bundled scene (assets/scenes/) into a World through the real plugins, and skipping a test
// whose plugins are not built yet.
#include "impetus/engine/metrics.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/plugins/host.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace impetus::scenario {

/// Path of a bundled scene file.
inline std::string scene_path(const std::string& name) { return std::string(IMPETUS_SCENES) + "/" + name; }

/// The plugins of `{kind, name}` pairs that are not in the build tree's plugin directory, as
/// "detector fcl, resolver ledas" (empty when all are there).
inline std::string missing_plugins(std::initializer_list<std::pair<const char*, const char*>> plugins) {
  std::string missing;
  for (const auto& [kind, name] : plugins) {
    const std::filesystem::path file =
        std::filesystem::path(IMPETUS_PLUGIN_DIR) / ("impetus_" + std::string(kind) + "_" + name + ".so");
    if (!std::filesystem::exists(file)) missing += (missing.empty() ? "" : ", ") + std::string(kind) + " " + name;
  }
  return missing;
}

/// Fails the current test (naming them) unless every listed plugin is built: the build always makes
/// them (tests/scenarios/CMakeLists.txt), so a missing one is a broken build, not a reason to skip.
#define IMPETUS_REQUIRE_PLUGINS(...)                                                           \
  do {                                                                                         \
    const std::string impetus_missing = ::impetus::scenario::missing_plugins({__VA_ARGS__});   \
    if (!impetus_missing.empty()) FAIL() << "plugin(s) not built: " << impetus_missing;       \
  } while (0)

/// A scene loaded from assets/scenes/ with overrides and built into a World. The host outlives the
/// world (members are destroyed in reverse order), so plugin libraries stay loaded while used.
struct SceneRun {
  PluginHost host;
  Scene scene;
  std::unique_ptr<World> world;

  explicit SceneRun(const std::string& name, const std::vector<SceneOverride>& overrides = {})
      : scene(load_scene(scene_path(name), overrides)), world(build_world(scene, host)) {}

  /// The body named `name` (fails the test if absent).
  RigidBody& body(const std::string& name) {
    const auto index = world->find_body(name);
    EXPECT_TRUE(index.has_value()) << "no body named " << name;
    return world->bodies()[index.value_or(0)];
  }
};

/// Σ ½ m v² + ½ ωᵀ J ω over movable bodies (J).
inline double kinetic_energy(const World& world) { return measure(world).kinetic_energy; }

/// Σ m v over movable bodies (kg·m/s).
inline Vec3 momentum(const World& world) { return measure(world).linear_momentum; }

}  // namespace impetus::scenario
