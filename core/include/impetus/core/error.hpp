#pragma once
/// \file
/// Load-time errors (scene, mesh, plugin, options). The message names the file, line/column or field,
/// the value, and what was expected; the CLI prints it as is and exits non-zero.

#include <stdexcept>
#include <string>

namespace impetus {

/// A load-time error with a complete, user-facing message.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace impetus
