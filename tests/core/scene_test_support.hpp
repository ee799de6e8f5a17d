#pragma once
// Helpers for the scene tests: load inline YAML as if it were the file "scene.yaml" in /scenes, and
// capture the Error a bad scene raises.

#include "impetus/core/error.hpp"
#include "impetus/engine/scene.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace impetus::test {

inline Scene load(const std::string& yaml, const std::vector<SceneOverride>& overrides = {}) {
  return load_scene_text(yaml, "scene.yaml", "/scenes", overrides);
}

/// The message of the Error that loading `yaml` throws; a test failure (and "") if it loads.
inline std::string load_error(const std::string& yaml, const std::vector<SceneOverride>& overrides = {}) {
  try {
    load(yaml, overrides);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "the scene loaded, but an Error was expected";
  return {};
}

/// Expects loading to fail with a message that starts with `prefix` (location and reason) and, if
/// given, also contains `detail`.
inline void expect_error(const std::string& yaml, const std::string& prefix, const std::string& detail = {},
                         const std::vector<SceneOverride>& overrides = {}) {
  const std::string message = load_error(yaml, overrides);
  EXPECT_TRUE(message.starts_with(prefix)) << "message: " << message << "\nexpected prefix: " << prefix;
  if (!detail.empty()) {
    EXPECT_NE(message.find(detail), std::string::npos) << "message: " << message;
  }
}

}  // namespace impetus::test
