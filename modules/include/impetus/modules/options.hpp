#pragma once
/// \file
/// Options given to a module in a scene (`detector: {plugin: fcl, margin: 1.0e-4}`) or with
/// `--set modules.detector.margin=…`. Header-only, so plugins read them without linking the core.
///
/// A plugin reads each option it knows with a typed getter; a value of the wrong type throws
/// OptionError (caught inside the plugin's factory, never across the plugin boundary). After the factory
/// returns, the host reports every option the plugin did not read as unknown, naming the plugin, the
/// option and where it was written.

#include "impetus/core/format.hpp"
#include "impetus/core/math.hpp"

#include <cerrno>
#include <cstdlib>
#include <initializer_list>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace impetus {

/// A bad option value, with where it was written.
class OptionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One option as written: scalar text or a list of scalars, and its source location ("file:line:col").
struct OptionValue {
  std::string text;                ///< scalar value (empty for a list)
  std::vector<std::string> items;  ///< list elements (empty for a scalar)
  bool is_list = false;
  std::string where;               ///< "scene.yaml:12:5" or "--set"
};

/// The options of one module instance. Keys are plain names (no dots).
class ModuleOptions {
 public:
  ModuleOptions() = default;
  explicit ModuleOptions(std::string module_label) : label_(std::move(module_label)) {}

  /// Sets (or replaces) an option.
  void set(const std::string& key, OptionValue value) { values_[key] = std::move(value); }
  /// True if the option was written.
  bool has(const std::string& key) const { return values_.count(key) != 0; }
  /// All options as written.
  const std::map<std::string, OptionValue>& values() const { return values_; }
  /// Options written but never read by the module (checked by the host after creation).
  std::vector<std::string> unread() const {
    std::vector<std::string> out;
    for (const auto& [key, value] : values_)
      if (!read_.count(key)) out.push_back(key);
    return out;
  }
  /// Option keys the module asked for (to list them when one is unknown).
  const std::set<std::string>& known() const { return read_; }

  /// A real number option (default if absent). Throws OptionError for a non-number or non-finite value.
  double number(const std::string& key, double fallback) const {
    const OptionValue* v = scalar(key);
    return v ? parse_number(key, *v) : fallback;
  }
  /// A number option with bounds [lo, hi].
  double number(const std::string& key, double fallback, double lo, double hi) const {
    const double x = number(key, fallback);
    if (x < lo || x > hi)
      fail(key, "must be between " + format_number(lo) + " and " + format_number(hi) + ", got " +
                    values_.at(key).text);
    return x;
  }
  /// An integer option with bounds [lo, hi].
  long long integer(const std::string& key, long long fallback, long long lo, long long hi) const {
    const OptionValue* v = scalar(key);
    if (!v) return fallback;
    errno = 0;
    char* end = nullptr;
    const long long x = std::strtoll(v->text.c_str(), &end, 10);
    if (v->text.empty() || *end != '\0' || errno != 0) fail(key, "expects an integer, got '" + v->text + "'");
    if (x < lo || x > hi)
      fail(key, "must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " + v->text);
    return x;
  }
  /// A boolean option (true/false, yes/no, on/off).
  bool boolean(const std::string& key, bool fallback) const {
    const OptionValue* v = scalar(key);
    if (!v) return fallback;
    if (v->text == "true" || v->text == "yes" || v->text == "on") return true;
    if (v->text == "false" || v->text == "no" || v->text == "off") return false;
    fail(key, "expects true or false, got '" + v->text + "'");
  }
  /// A string option restricted to `choices`.
  std::string choice(const std::string& key, const std::string& fallback,
                     std::initializer_list<const char*> choices) const {
    const OptionValue* v = scalar(key);
    if (!v) return fallback;
    std::string list;
    for (const char* c : choices) {
      if (v->text == c) return v->text;
      list += list.empty() ? c : std::string(", ") + c;
    }
    fail(key, "expects one of " + list + ", got '" + v->text + "'");
  }
  /// A free string option.
  std::string string(const std::string& key, const std::string& fallback) const {
    const OptionValue* v = scalar(key);
    return v ? v->text : fallback;
  }
  /// A 3-vector option written as [x, y, z].
  Vec3 vector3(const std::string& key, const Vec3& fallback) const {
    read_.insert(key);
    auto it = values_.find(key);
    if (it == values_.end()) return fallback;
    if (!it->second.is_list || it->second.items.size() != 3) fail(key, "expects a list of 3 numbers");
    Vec3 out;
    for (int i = 0; i < 3; ++i) out[i] = parse_number(key, OptionValue{it->second.items[i], {}, false, {}});
    return out;
  }

  /// "plugin 'fcl' (detector)" or similar, used in messages.
  const std::string& label() const { return label_; }

 private:
  const OptionValue* scalar(const std::string& key) const {
    read_.insert(key);
    auto it = values_.find(key);
    if (it == values_.end()) return nullptr;
    if (it->second.is_list) fail(key, "expects a single value, got a list");
    return &it->second;
  }
  double parse_number(const std::string& key, const OptionValue& v) const {
    errno = 0;
    char* end = nullptr;
    const double x = std::strtod(v.text.c_str(), &end);
    if (v.text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(x))
      fail(key, "expects a finite number, got '" + v.text + "'");
    return x;
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    auto it = values_.find(key);
    const std::string where = it != values_.end() && !it->second.where.empty() ? it->second.where + ": " : "";
    throw OptionError(where + label_ + " option '" + key + "' " + what);
  }

  std::string label_;
  std::map<std::string, OptionValue> values_;
  mutable std::set<std::string> read_;
};

}  // namespace impetus
