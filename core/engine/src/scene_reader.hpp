#pragma once
// Internal to the scene loader: typed, located reading of a yaml-cpp tree. Every failure throws Error
// with a message that starts with where the value was written: "scene.yaml:12:3: " for a node from the
// file, "--set KEY: " for one that an override put there.

#include "impetus/core/error.hpp"
#include "impetus/core/math.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace impetus::assets {
class MeshCache;
}

namespace impetus::scene_detail {

/// Where messages point and what relative paths resolve against, for one scene being read.
class SceneReader {
 public:
  SceneReader(std::string file_label, std::filesystem::path base_dir)
      : file_(std::move(file_label)), base_dir_(std::move(base_dir)) {}

  /// "file:line:col" (1-based) for a node read from the file, "--set KEY" for one an override wrote,
  /// the bare file name for a node with no position.
  std::string where(const YAML::Node& node) const;
  /// "file:line:col" for a yaml-cpp mark (parser errors).
  std::string where(const YAML::Mark& mark) const;
  /// Throws Error("<where(node)>: <message>").
  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const;
  /// Records `node` (and, if `recursive`, everything under it) as written by `--set key`.
  void mark_override(const YAML::Node& node, const std::string& key, bool recursive = true);

  const std::string& file() const { return file_; }
  /// `path` as written in the scene: absolute kept, relative taken from the scene file's directory.
  std::filesystem::path resolve_path(const std::string& path) const;

  // Typed reads of one value; `what` is its key, quoted in messages ("'mass' expects a number, …").
  /// A finite real number (.nan and .inf are refused).
  double number(const YAML::Node& node, std::string_view what) const;
  /// A finite number > 0.
  double positive(const YAML::Node& node, std::string_view what) const;
  /// A finite number ≥ 0.
  double non_negative(const YAML::Node& node, std::string_view what) const;
  /// A finite number in [lo, hi].
  double in_range(const YAML::Node& node, std::string_view what, double lo, double hi) const;
  /// A decimal (or 0x-prefixed hexadecimal) integer in [lo, hi].
  long long integer(const YAML::Node& node, std::string_view what, long long lo, long long hi) const;
  /// true/false (also yes/no, on/off).
  bool boolean(const YAML::Node& node, std::string_view what) const;
  /// A scalar, taken as text.
  std::string string(const YAML::Node& node, std::string_view what) const;
  /// A scalar that must be one of `choices`.
  std::string choice(const YAML::Node& node, std::string_view what,
                     std::initializer_list<std::string_view> choices) const;
  /// A list of exactly `n` finite numbers.
  std::vector<double> numbers(const YAML::Node& node, std::string_view what, std::size_t n) const;
  /// [x, y, z] of finite numbers.
  Vec3 vec3(const YAML::Node& node, std::string_view what) const;
  /// [x, y, z] of finite numbers, not all zero, as a unit vector: divided by its largest component
  /// before it is normalized, so [0, 1e200, 1e200] and [1e-300, 0, 0] keep their direction.
  Vec3 direction(const YAML::Node& node, std::string_view what) const;
  /// The elements of a list (a missing or null value is an empty list).
  std::vector<YAML::Node> list(const YAML::Node& node, std::string_view what) const;

  /// "'abc'", "a list", "a mapping" or "nothing": what a node holds, for "got …" in messages.
  static std::string describe(const YAML::Node& node);

  /// Records the warning "<where(node)>: <message>" (the scene loader hands them to Scene::warnings).
  void warn(const YAML::Node& node, const std::string& message) const;
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// Meshes imported while reading this scene: bodies naming the same file and scale share one
  /// import and one geometry (assets/mesh_body.hpp). Created on first use.
  assets::MeshCache& meshes() const;

 private:
  std::string file_;
  std::filesystem::path base_dir_;
  mutable std::vector<std::string> warnings_;
  mutable std::shared_ptr<assets::MeshCache> meshes_;
  std::vector<std::pair<YAML::Node, std::string>> overridden_;  // node → "--set KEY", latest last
};

/// The entries of one mapping, checked on construction: it is a mapping, every key is a plain scalar
/// listed in `allowed`, and no key repeats. An unknown key is an error that lists the allowed ones.
class Fields {
 public:
  /// `context` names the mapping in messages ("scene", "body 'ball'", "sphere"). An empty `allowed`
  /// accepts any key (a module's options).
  Fields(const SceneReader& reader, const YAML::Node& map, std::string context,
         std::initializer_list<std::string_view> allowed);

  /// The value of `key`, or null when absent.
  const YAML::Node* find(std::string_view key) const;
  /// The value of `key`; an error naming it and the context when absent.
  const YAML::Node& require(std::string_view key) const;
  /// The mapping itself (for messages about it as a whole).
  const YAML::Node& node() const { return map_; }
  const std::string& context() const { return context_; }

  /// One written entry, in file order.
  struct Entry {
    std::string key;
    YAML::Node key_node;
    YAML::Node value;
  };
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  const SceneReader& reader_;
  YAML::Node map_;
  std::string context_;
  std::vector<Entry> entries_;
};

}  // namespace impetus::scene_detail
