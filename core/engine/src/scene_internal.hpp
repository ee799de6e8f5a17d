#pragma once
// Internal to the scene loader: the pieces scene.cpp assembles. Each reads one part of the YAML tree
// with SceneReader and throws Error located at the offending node.

#include "impetus/engine/scene.hpp"
#include "impetus/plugins/abi.hpp"
#include "scene_reader.hpp"

#include <map>
#include <string>
#include <vector>

namespace impetus::scene_detail {

/// A body read from the scene with the node that named it (for duplicate-name messages).
struct ReadBody {
  RigidBody body;
  YAML::Node where;  ///< the `name` value, or the generator entry that made the body
};

/// Reads one entry of `bodies:` (the `index`-th, for messages before its name is known).
ReadBody read_body(const SceneReader& reader, const YAML::Node& node, std::size_t index);

/// The bodies a scene already holds and the most it may hold (SceneLimits::bodies).
struct BodyRoom {
  std::size_t used = 0;
  std::size_t limit = 0;
};

/// Reads one entry of `generators:` and returns the bodies it makes; refuses, before making them, a
/// generator whose bodies (a ground or wall included) would not fit in `room`.
std::vector<ReadBody> read_generator(const SceneReader& reader, const YAML::Node& node, BodyRoom room);

/// Reads `modules.<kind>`; `node` is null when the scene omits it (the default plugin is used).
ModuleRequest read_module(const SceneReader& reader, const YAML::Node* node, ModuleKind kind);

/// Reads one entry of `constraints:`; bodies are looked up by name in `bodies`.
Constraint read_constraint(const SceneReader& reader, const YAML::Node& node,
                           const std::vector<RigidBody>& bodies,
                           const std::map<std::string, BodyIndex>& index_by_name);

/// Applies `--set` overrides to the parsed tree, before any validation, recording which nodes they
/// wrote so messages about them say "--set KEY".
void apply_overrides(YAML::Node& root, const std::vector<SceneOverride>& overrides, SceneReader& reader);

}  // namespace impetus::scene_detail
