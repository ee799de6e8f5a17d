// Typed, located reading of a scene's YAML tree (see scene_reader.hpp).

#include "scene_reader.hpp"

#include "impetus/assets/mesh_body.hpp"
#include "impetus/core/format.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>

namespace impetus::scene_detail {
namespace {

std::string quote(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string join(std::initializer_list<std::string_view> items) {
  std::string out;
  for (std::string_view item : items) {
    if (!out.empty()) out += ", ";
    out += item;
  }
  return out;
}

// Levenshtein distance, for suggesting the key a typo meant.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// "; did you mean 'gravity'?" for a near miss, and a hint for "key:value" written without the space
// YAML needs after the colon.
std::string unknown_key_hint(std::string_view key, std::initializer_list<std::string_view> allowed) {
  if (key.find(':') != std::string_view::npos) return "; a ':' needs a space after it to separate key and value";
  std::string_view best;
  std::size_t best_distance = 3;  // more than two edits is not a typo
  for (std::string_view a : allowed) {
    const std::size_t d = edit_distance(key, a);
    if (d < best_distance && d < a.size()) best = a, best_distance = d;
  }
  return best.empty() ? "" : "; did you mean '" + std::string(best) + "'?";
}

}  // namespace

std::string SceneReader::where(const YAML::Mark& mark) const {
  if (mark.is_null()) return file_;
  return file_ + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

std::string SceneReader::where(const YAML::Node& node) const {
  // Latest override first: a later --set may have replaced part of an earlier one.
  for (auto it = overridden_.rbegin(); it != overridden_.rend(); ++it)
    if (it->first.is(node)) return it->second;
  return where(node.Mark());
}

void SceneReader::fail(const YAML::Node& node, const std::string& message) const {
  throw Error(where(node) + ": " + message);
}

void SceneReader::warn(const YAML::Node& node, const std::string& message) const {
  warnings_.push_back(where(node) + ": " + message);
}

assets::MeshCache& SceneReader::meshes() const {
  if (!meshes_) meshes_ = std::make_shared<assets::MeshCache>();
  return *meshes_;
}

void SceneReader::mark_override(const YAML::Node& node, const std::string& key, bool recursive) {
  overridden_.emplace_back(node, key);
  if (!recursive) return;
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) mark_override(item, key);
  } else if (node.IsMap()) {
    for (const auto& entry : node) {
      mark_override(entry.first, key);
      mark_override(entry.second, key);
    }
  }
}

std::filesystem::path SceneReader::resolve_path(const std::string& path) const {
  const std::filesystem::path p(path);
  return p.is_absolute() ? p : (base_dir_ / p).lexically_normal();
}

std::string SceneReader::describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar: return quote(node.Scalar());
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Map: return "a mapping";
    default: return "nothing";
  }
}

double SceneReader::number(const YAML::Node& node, std::string_view what) const {
  const auto expected = [&] { fail(node, quote(what) + " expects a number, got " + describe(node)); };
  if (!node.IsScalar()) expected();
  std::string_view text = node.Scalar();
  // YAML's spellings of the non-finite values (.nan, .inf, -.Inf, …), refused with their own reason.
  std::string bare(text.substr(!text.empty() && (text[0] == '+' || text[0] == '-') ? 1 : 0));
  for (char& c : bare) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (bare == ".nan" || bare == ".inf")
    fail(node, quote(what) + " must be a finite number, got " + quote(text));
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);  // from_chars does not take '+'
  double x = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), x);
  if (ec == std::errc::result_out_of_range)
    fail(node, quote(what) + " is out of the range of a double: " + describe(node));
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) expected();
  if (!std::isfinite(x)) fail(node, quote(what) + " must be a finite number, got " + describe(node));
  return x;
}

double SceneReader::positive(const YAML::Node& node, std::string_view what) const {
  const double x = number(node, what);
  if (!(x > 0.0)) fail(node, quote(what) + " must be positive, got " + format_number(x));
  return x;
}

double SceneReader::non_negative(const YAML::Node& node, std::string_view what) const {
  const double x = number(node, what);
  if (!(x >= 0.0)) fail(node, quote(what) + " must not be negative, got " + format_number(x));
  return x;
}

double SceneReader::in_range(const YAML::Node& node, std::string_view what, double lo, double hi) const {
  const double x = number(node, what);
  if (!(x >= lo && x <= hi))
    fail(node, quote(what) + " must be between " + format_number(lo) + " and " + format_number(hi) +
                   ", got " + format_number(x));
  return x;
}

long long SceneReader::integer(const YAML::Node& node, std::string_view what, long long lo,
                               long long hi) const {
  const auto expected = [&] { fail(node, quote(what) + " expects an integer, got " + describe(node)); };
  if (!node.IsScalar()) expected();
  std::string_view text = node.Scalar();
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;  // collision masks read better in hex
    text.remove_prefix(2);
  } else if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
  }
  long long x = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), x, base);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) expected();
  if (x < lo || x > hi)
    fail(node, quote(what) + " must be between " + std::to_string(lo) + " and " + std::to_string(hi) +
                   ", got " + describe(node));
  return x;
}

bool SceneReader::boolean(const YAML::Node& node, std::string_view what) const {
  if (node.IsScalar()) {
    const std::string& t = node.Scalar();
    if (t == "true" || t == "True" || t == "TRUE" || t == "yes" || t == "on") return true;
    if (t == "false" || t == "False" || t == "FALSE" || t == "no" || t == "off") return false;
  }
  fail(node, quote(what) + " expects true or false, got " + describe(node));
}

std::string SceneReader::string(const YAML::Node& node, std::string_view what) const {
  if (!node.IsScalar()) fail(node, quote(what) + " expects a text value, got " + describe(node));
  return node.Scalar();
}

std::string SceneReader::choice(const YAML::Node& node, std::string_view what,
                                std::initializer_list<std::string_view> choices) const {
  if (node.IsScalar())
    for (std::string_view c : choices)
      if (node.Scalar() == c) return node.Scalar();
  fail(node, quote(what) + " expects one of: " + join(choices) + "; got " + describe(node));
}

std::vector<double> SceneReader::numbers(const YAML::Node& node, std::string_view what,
                                         std::size_t n) const {
  if (!node.IsSequence() || node.size() != n)
    fail(node, quote(what) + " expects a list of " + std::to_string(n) + " numbers, got " +
                   (node.IsSequence() ? "a list of " + std::to_string(node.size()) : describe(node)));
  std::vector<double> out;
  out.reserve(n);
  for (const YAML::Node& item : node) out.push_back(number(item, what));
  return out;
}

Vec3 SceneReader::vec3(const YAML::Node& node, std::string_view what) const {
  const std::vector<double> v = numbers(node, what, 3);
  return {v[0], v[1], v[2]};
}

Vec3 SceneReader::direction(const YAML::Node& node, std::string_view what) const {
  const Vec3 v = vec3(node, what);
  const double largest = v.cwiseAbs().maxCoeff();
  if (largest == 0.0) fail(node, quote(what) + " must not be the zero vector");
  return (v / largest).normalized();
}

std::vector<YAML::Node> SceneReader::list(const YAML::Node& node, std::string_view what) const {
  if (node.IsNull()) return {};
  if (!node.IsSequence()) fail(node, quote(what) + " expects a list, got " + describe(node));
  return {node.begin(), node.end()};
}

Fields::Fields(const SceneReader& reader, const YAML::Node& map, std::string context,
               std::initializer_list<std::string_view> allowed)
    : reader_(reader), map_(map), context_(std::move(context)) {
  if (!map.IsMap()) reader.fail(map, context_ + " expects a mapping of keys, got " + SceneReader::describe(map));
  for (const auto& pair : map) {
    const YAML::Node& key = pair.first;
    if (!key.IsScalar())
      reader.fail(key, "keys in " + context_ + " must be plain names, got " + SceneReader::describe(key));
    const std::string& name = key.Scalar();
    bool known = allowed.size() == 0;
    for (std::string_view a : allowed) known = known || a == name;
    if (!known)
      reader.fail(key, "unknown key " + quote(name) + " in " + context_ + "; expected one of: " + join(allowed) +
                           unknown_key_hint(name, allowed));
    // yaml-cpp keeps both entries of a repeated key; which one wins would be an accident.
    for (const Entry& e : entries_)
      if (e.key == name)
        reader.fail(key, "key " + quote(name) + " appears twice in " + context_ + " (first at " +
                             reader.where(e.key_node) + ")");
    entries_.push_back({name, key, pair.second});
  }
}

const YAML::Node* Fields::find(std::string_view key) const {
  for (const Entry& e : entries_)
    if (e.key == key) return &e.value;
  return nullptr;
}

const YAML::Node& Fields::require(std::string_view key) const {
  if (const YAML::Node* value = find(key)) return *value;
  reader_.fail(map_, context_ + " needs " + quote(key));
}

}  // namespace impetus::scene_detail
