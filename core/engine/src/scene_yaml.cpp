// Bounded YAML loading (see scene_yaml.hpp).

#include "scene_yaml.hpp"

#include "impetus/core/error.hpp"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <sstream>
#include <vector>

namespace impetus::scene_detail {
namespace {

std::string at(const std::string& label, const YAML::Mark& mark) {
  if (mark.is_null()) return label;
  return label + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

// Counts the nodes of one document as a reader walking the tree meets them: an alias counts as the
// whole subtree of its anchor, and nests as deep as that subtree does.
class ExpansionCounter : public YAML::EventHandler {
 public:
  ExpansionCounter(std::string label, const YamlLimits& limits) : label_(std::move(label)), limits_(limits) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { leaf(mark, anchor); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor, const std::string&) override {
    leaf(mark, anchor);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    for (const Frame& open : open_)
      if (open.anchor == anchor)
        throw Error(at(label_, mark) + ": an alias refers to the node that contains it (a cycle); "
                    "a scene is a tree, so write the value out or alias a finished node");
    const Subtree sub = anchor < anchors_.size() ? anchors_[anchor] : Subtree{1, 0};
    add(mark, sub.nodes, sub.height);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Subtree {
    std::size_t nodes = 0;   // with aliases expanded
    std::size_t height = 0;  // 0 for a scalar
  };
  struct Frame {
    YAML::anchor_t anchor;
    std::size_t nodes_before;  // count_ when the collection opened
    std::size_t height = 1;    // an empty collection is one level
  };

  // Adds a subtree of `nodes` nodes and `height` levels at the current depth.
  void add(const YAML::Mark& mark, std::size_t nodes, std::size_t height) {
    if (nodes > limits_.nodes - std::min(count_, limits_.nodes))
      throw Error(at(label_, mark) + ": the YAML expands to more than " + std::to_string(limits_.nodes) +
                  " nodes (counting every alias as written out); a larger scene should use generators");
    count_ += nodes;
    if (open_.size() + height > limits_.depth)
      throw Error(at(label_, mark) + ": the YAML nests more than " + std::to_string(limits_.depth) +
                  " levels deep (counting every alias as written out)");
    if (!open_.empty()) open_.back().height = std::max(open_.back().height, height + 1);
  }
  void remember(YAML::anchor_t anchor, Subtree sub) {
    if (anchor == YAML::NullAnchor) return;
    if (anchors_.size() <= anchor) anchors_.resize(anchor + 1);
    anchors_[anchor] = sub;
  }
  void leaf(const YAML::Mark& mark, YAML::anchor_t anchor) {
    add(mark, 1, 0);
    remember(anchor, {1, 0});
  }
  void open(const YAML::Mark& mark, YAML::anchor_t anchor) {
    add(mark, 1, 1);
    open_.push_back({anchor, count_ - 1});
  }
  void close() {
    const Frame frame = open_.back();
    open_.pop_back();
    if (!open_.empty()) open_.back().height = std::max(open_.back().height, frame.height + 1);
    remember(frame.anchor, {count_ - frame.nodes_before, frame.height});
  }

  std::string label_;
  YamlLimits limits_;
  std::size_t count_ = 0;
  std::vector<Frame> open_;
  std::vector<Subtree> anchors_;  // by anchor id (yaml-cpp numbers a document's anchors from 1)
};

// Stops at the start of a second document: it is only there to be refused.
class DocumentStart : public YAML::EventHandler {
 public:
  explicit DocumentStart(YAML::Mark& mark) : mark_(mark) {}
  void OnDocumentStart(const YAML::Mark& mark) override {
    mark_ = mark;
    throw Found{};
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
  struct Found {};

 private:
  YAML::Mark& mark_;
};

}  // namespace

YAML::Node load_bounded_yaml(const std::string& text, const std::string& label, const YamlLimits& limits) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  ExpansionCounter counter(label, limits);
  if (!parser.HandleNextDocument(counter)) return YAML::Node();  // empty text: a null document
  YAML::Mark second = YAML::Mark::null_mark();
  try {
    DocumentStart probe(second);
    parser.HandleNextDocument(probe);
  } catch (const DocumentStart::Found&) {
    throw Error(at(label, second) + ": a second YAML document (after '---') is not read; a scene is one document");
  }
  return YAML::Load(text);
}

}  // namespace impetus::scene_detail
