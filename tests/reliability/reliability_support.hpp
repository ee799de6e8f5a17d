#pragma once
// Helpers shared by the reliability tests: scratch directories, error capture, and a World built from
// scene text with the shipped plugins (and the test fixtures, for the fault injectors).

#include "impetus/core/error.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/engine/world.hpp"
#include "impetus/plugins/host.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace impetus::reliability {

namespace fs = std::filesystem;

inline fs::path source_dir() { return IMPETUS_SOURCE_DIR; }
inline fs::path scenes_dir() { return source_dir() / "assets" / "scenes"; }
inline fs::path meshes_dir() { return source_dir() / "assets" / "meshes"; }
inline fs::path fixture_dir() { return IMPETUS_FIXTURE_DIR; }

/// A fresh directory under the system's temporary directory, removed with its contents at scope end.
class Scratch {
 public:
  explicit Scratch(const std::string& tag) {
    static int counter = 0;
    path_ = fs::temp_directory_path() /
            ("impetus-reliability-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + "-" + tag);
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  const fs::path& path() const { return path_; }
  /// Writes `bytes` to `name` in this directory; returns its path.
  fs::path write(const std::string& name, const std::string& bytes) const {
    const fs::path file = path_ / name;
    std::ofstream(file, std::ios::binary) << bytes;
    return file;
  }

 private:
  fs::path path_;
};

/// The message of the impetus::Error that `fn` throws, or "<no error>" / "<other exception: …>".
inline std::string error_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("<other exception: ") + e.what() + ">";
  }
  return "<no error>";
}

/// A plugin host that sees the shipped plugins (next to libimpetus_plugin_host.so) and then the fixtures.
inline std::unique_ptr<PluginHost> make_host() {
  auto host = std::make_unique<PluginHost>();
  host->prepend_directories({IMPETUS_PLUGIN_DIR, IMPETUS_FIXTURE_DIR});
  return host;
}

/// A world from a bundled scene file (assets/scenes/<name>.yaml) with overrides.
inline std::unique_ptr<World> bundled_world(const std::string& name, PluginHost& host,
                                            const std::vector<SceneOverride>& overrides = {}) {
  return build_world(load_scene(scenes_dir() / (name + ".yaml"), overrides), host);
}

/// The bits of every body's state (position, rotation, velocity, angular velocity), in body order.
inline std::vector<std::uint64_t> state_bits(const World& world) {
  std::vector<std::uint64_t> bits;
  for (const RigidBody& b : world.bodies()) {
    const auto add = [&](const auto& m) {
      for (Eigen::Index i = 0; i < m.size(); ++i) bits.push_back(std::bit_cast<std::uint64_t>(m.data()[i]));
    };
    add(b.position);
    add(b.rotation);
    add(b.velocity);
    add(b.angular_velocity);
  }
  return bits;
}

}  // namespace impetus::reliability
