// `modules:` entries: which plugin provides each module, and its options.

#include "scene_internal.hpp"

#include <optional>

namespace impetus::scene_detail {
namespace {

// The plugins a scene gets when it does not name one (docs/conventions.md).
const char* default_plugin(ModuleKind kind) {
  switch (kind) {
    case ModuleKind::integrator: return "momentum";
    case ModuleKind::detector: return "fcl";
    case ModuleKind::resolver: return "ledas";
  }
  return "";
}

OptionValue read_option(const SceneReader& r, const std::string& key, const YAML::Node& value) {
  OptionValue option;
  option.where = r.where(value);
  if (value.IsSequence()) {
    option.is_list = true;
    for (const YAML::Node& item : value) {
      if (!item.IsScalar())
        r.fail(item, "option '" + key + "' expects a value or a list of values, got a list containing " +
                         SceneReader::describe(item));
      option.items.push_back(item.Scalar());
    }
  } else if (value.IsMap()) {
    r.fail(value, "option '" + key + "' expects a value or a list of values, got a mapping");
  } else {
    option.text = value.IsScalar() ? value.Scalar() : "";
  }
  return option;
}

}  // namespace

ModuleRequest read_module(const SceneReader& r, const YAML::Node* node, ModuleKind kind) {
  const std::string kind_name = module_kind_name(kind);
  ModuleRequest request;
  request.plugin = default_plugin(kind);
  request.where = r.file() + " (default " + kind_name + ")";
  std::optional<YAML::Node> plugin_node;  // a handle, not a pointer: the Fields below is scoped
  if (node && node->IsScalar()) {
    // Short form: `integrator: euler`.
    plugin_node.emplace(*node);
  } else if (node && node->IsMap()) {
    // Long form: `detector: {plugin: fcl, path: ./lib.so, margin: 1.0e-4}`; every other key is an option
    // the plugin checks itself. Without `plugin` the default plugin gets the options.
    const Fields f(r, *node, "modules." + kind_name, {});
    request.where = r.where(*node);
    for (const Fields::Entry& e : f.entries()) {
      if (e.key == "plugin") {
        plugin_node.emplace(e.value);
      } else if (e.key == "path") {
        request.path = r.resolve_path(r.string(e.value, "path"));
        if (r.string(e.value, "path").empty()) r.fail(e.value, "'path' must not be empty");
      } else {
        request.options.set(e.key, read_option(r, e.key, e.value));
      }
    }
  } else if (node && !node->IsNull()) {
    r.fail(*node, "'" + kind_name + "' expects a plugin name or a mapping {plugin: NAME, OPTION: VALUE, ...}, got " +
                      SceneReader::describe(*node));
  }
  if (plugin_node) {
    request.plugin = r.string(*plugin_node, "plugin");
    request.where = r.where(*plugin_node);
    if (request.plugin.empty()) r.fail(*plugin_node, "the " + kind_name + " plugin name must not be empty");
  }
  if (request.plugin == "none") {
    if (kind == ModuleKind::integrator)
      r.fail(*plugin_node, "the integrator is required; 'none' is allowed only for the detector and the resolver");
    if (!request.options.values().empty() || !request.path.empty())
      r.fail(*node, "'none' (no " + kind_name + ") takes no path and no options");
  }
  // Rebuild with the label now that the plugin's name is known (ModuleOptions has no label setter).
  ModuleOptions labelled("plugin '" + request.plugin + "' (" + kind_name + ")");
  for (const auto& [key, value] : request.options.values()) labelled.set(key, value);
  request.options = std::move(labelled);
  return request;
}

}  // namespace impetus::scene_detail
