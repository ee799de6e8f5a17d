#pragma once
/// \file
/// Result of a module call that can fail at load time. Modules never throw across the plugin boundary:
/// they return a ModuleStatus instead.

#include <string>
#include <utility>

namespace impetus {

/// Success, or a message saying what went wrong (naming the body, shape or option).
struct ModuleStatus {
  bool ok = true;
  std::string message;

  static ModuleStatus success() { return {}; }
  static ModuleStatus failure(std::string why) { return {false, std::move(why)}; }
  explicit operator bool() const { return ok; }
};

}  // namespace impetus
