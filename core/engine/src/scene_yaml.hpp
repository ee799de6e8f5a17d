#pragma once
// Reading YAML text into a tree with bounds on what it expands to (README.md, "Scene files", limits).
// yaml-cpp shares an aliased node rather than copying it, but everything that reads the tree walks it
// as if each alias were written out, so a few hundred bytes of nested aliases stand for 10^9 nodes, and
// an alias inside its own anchor is a cycle that recursion never leaves. The text is therefore first
// streamed through yaml-cpp's event parser (no tree is built), counting nodes as the reader will see
// them; only text within the bounds is then loaded.

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>

namespace impetus::scene_detail {

/// Bounds on one YAML text, counted with every alias expanded.
struct YamlLimits {
  std::size_t nodes = 1'000'000;  ///< scalars, lists and maps (a body written out is about 20; yaml-cpp
                                  ///< needs about 0.5 KB per node, so this is about 0.5 GB)
  std::size_t depth = 64;         ///< nesting of lists and maps (a scene needs about 6)
};

/// Parses `text` as exactly one YAML document within `limits`. `label` begins every message (a file
/// name, or "--set KEY"). Throws Error naming the line and column of the node that crosses a bound, of
/// an alias that refers to the node containing it, or of a second document.
YAML::Node load_bounded_yaml(const std::string& text, const std::string& label, const YamlLimits& limits = {});

}  // namespace impetus::scene_detail
