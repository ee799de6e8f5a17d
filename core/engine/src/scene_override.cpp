// `--set KEY=VALUE`: parsing, and applying to the YAML tree before validation, so an overridden value
// is checked exactly like a written one.

#include "scene_internal.hpp"
#include "scene_yaml.hpp"

#include <algorithm>
#include <cctype>
#include <optional>
#include <utility>

namespace impetus {
namespace scene_detail {
namespace {

std::vector<std::string> split_path(const std::string& key, const std::string& label) {
  std::vector<std::string> segments;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = key.find('.', start);
    segments.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (segments.back().empty()) throw Error(label + ": the path has an empty part");
    if (dot == std::string::npos) return segments;
    start = dot + 1;
  }
}

bool is_index(const std::string& s) {
  return !s.empty() && s.size() < 10 && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) != 0;
  });
}

// The entry of `map` under `key` (null handle when absent). Reading through iteration never creates
// entries, unlike yaml-cpp's non-const operator[].
std::optional<std::pair<YAML::Node, YAML::Node>> find_entry(const YAML::Node& map, const std::string& key) {
  for (const auto& entry : map)
    if (entry.first.IsScalar() && entry.first.Scalar() == key) return std::make_pair(entry.first, entry.second);
  return std::nullopt;
}

// Element `segment` of a list: by index, or in `bodies` by name.
YAML::Node find_element(const YAML::Node& list, const std::string& segment, const std::string& list_path,
                        const std::string& label) {
  if (is_index(segment)) {
    const std::size_t index = std::stoul(segment);
    if (index >= list.size())
      throw Error(label + ": '" + list_path + "' has " + std::to_string(list.size()) + " elements, no element " +
                  segment);
    return list[index];
  }
  if (list_path == "bodies") {
    for (const YAML::Node& body : list)
      if (body.IsMap())
        if (const auto name = find_entry(body, "name"); name && name->second.IsScalar() && name->second.Scalar() == segment)
          return body;
    throw Error(label + ": no body named '" + segment + "'");
  }
  const std::string name = list_path.empty() ? "the scene" : "'" + list_path + "'";
  throw Error(label + ": " + name + " is a list; select an element by its index, not '" + segment + "'");
}

}  // namespace

void apply_overrides(YAML::Node& root, const std::vector<SceneOverride>& overrides, SceneReader& reader) {
  for (const SceneOverride& o : overrides) {
    const std::string label = "--set " + o.key;
    const std::vector<std::string> path = split_path(o.key, label);
    YAML::Node value;
    try {
      value = load_bounded_yaml(o.value, label);
    } catch (const YAML::Exception& e) {
      const std::string shown = o.value.size() > 80 ? o.value.substr(0, 77) + "..." : o.value;
      throw Error(label + ": the value '" + shown + "' is not valid YAML: " + e.msg);
    }
    if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
    // `cur` walks down the tree; reset() rebinds it (operator= would overwrite the node it names).
    YAML::Node cur;
    cur.reset(root);
    std::string cur_path;
    for (std::size_t i = 0; i < path.size(); ++i) {
      const std::string& segment = path[i];
      const bool last = i + 1 == path.size();
      const bool module_node = i == 2 && path[0] == "modules";
      if (cur.IsNull()) {
        cur = YAML::Node(YAML::NodeType::Map);  // `modules:` with nothing under it
        reader.mark_override(cur, label);
      } else if (cur.IsScalar() && module_node) {
        // A module in short form (`resolver: ledas`) gains an option: rewrite it as
        // {plugin: ledas, OPTION: VALUE}, keeping the plugin name's own location.
        YAML::Node long_form(YAML::NodeType::Map);
        long_form["plugin"] = cur;
        cur = long_form;
        reader.mark_override(cur, label, false);
        reader.mark_override(find_entry(cur, "plugin")->first, label, false);
      }
      if (cur.IsMap()) {
        auto entry = find_entry(cur, segment);
        if (last) {
          if (entry) {
            entry->second = value;  // replaces the node in the tree; its key keeps its location
          } else {
            cur[segment] = value;
            entry = find_entry(cur, segment);
            reader.mark_override(entry->first, label);
          }
          reader.mark_override(value, label);
        } else if (entry) {
          cur.reset(entry->second);
        } else {
          cur[segment] = YAML::Node(YAML::NodeType::Map);  // new keys are allowed, then validated
          entry = find_entry(cur, segment);
          reader.mark_override(entry->first, label);
          reader.mark_override(entry->second, label);
          cur.reset(entry->second);
        }
      } else if (cur.IsSequence()) {
        YAML::Node element = find_element(cur, segment, cur_path, label);
        if (last) {
          element = value;
          reader.mark_override(value, label);
        } else {
          cur.reset(element);
        }
      } else {
        throw Error(label + ": '" + (cur_path.empty() ? "the scene" : cur_path) +
                    "' is a single value, so it has no '" + segment + "'");
      }
      cur_path += (cur_path.empty() ? "" : ".") + segment;
    }
  }
}

}  // namespace scene_detail

SceneOverride parse_override(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos) throw Error("--set " + text + ": expected KEY=VALUE, e.g. dt=0.01");
  std::string key = text.substr(0, eq);
  // Spaces around the key are a typing accident, not part of the path.
  const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
  key.erase(key.begin(), std::find_if_not(key.begin(), key.end(), space));
  key.erase(std::find_if_not(key.rbegin(), key.rend(), space).base(), key.end());
  if (key.empty()) throw Error("--set " + text + ": the key before '=' is empty");
  return {key, text.substr(eq + 1)};
}

}  // namespace impetus
