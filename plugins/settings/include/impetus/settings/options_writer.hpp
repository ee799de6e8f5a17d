#pragma once
/// \file
/// Writing typed settings back as module options (the text a scene would hold), so a settings struct
/// built in code goes through the same plugin path, checks and run summary as a scene's options.

#include "impetus/core/format.hpp"
#include "impetus/modules/options.hpp"

#include <string>

namespace impetus::settings_detail {

/// Sets `key` in `options` when `value` differs from `fallback` (the plugin's default): the options list
/// what was chosen, as a scene would.
inline void put(ModuleOptions& options, const char* key, double value, double fallback) {
  if (value != fallback) options.set(key, OptionValue{format_number(value), {}, false, "code"});
}
inline void put(ModuleOptions& options, const char* key, long long value, long long fallback) {
  if (value != fallback) options.set(key, OptionValue{std::to_string(value), {}, false, "code"});
}
inline void put(ModuleOptions& options, const char* key, bool value, bool fallback) {
  if (value != fallback) options.set(key, OptionValue{value ? "true" : "false", {}, false, "code"});
}
inline void put(ModuleOptions& options, const char* key, const char* value, const char* fallback) {
  if (std::string(value) != fallback) options.set(key, OptionValue{value, {}, false, "code"});
}

}  // namespace impetus::settings_detail
