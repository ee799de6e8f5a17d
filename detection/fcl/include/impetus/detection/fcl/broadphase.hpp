#pragma once
/// \file
/// The broadphase: FCL dynamic AABB trees behind an FCL-free interface. Movable bodies live in one
/// tree updated incrementally (only the bodies whose box changed are re-fitted); fixed bodies live in a
/// second tree built once, so two fixed bodies never form a pair. Planes are unbounded and never enter
/// a tree: the detector tests them against the movable bodies' boxes itself.

#include "impetus/detection/fcl/fcl_queries.hpp"
#include "impetus/modules/detector.hpp"
#include "impetus/detection/fcl/shapes.hpp"

#include <memory>
#include <vector>

namespace impetus::collision {

class Broadphase {
 public:
  Broadphase();
  ~Broadphase();
  Broadphase(const Broadphase&) = delete;
  Broadphase& operator=(const Broadphase&) = delete;

  /// Forgets every body.
  void clear();
  /// Registers body `index` with its FCL geometry and world box (already grown by the margin): a fixed
  /// body goes to the static tree, a movable one to the dynamic tree. Call finish() after the last one.
  void add(BodyIndex index, const FclShapePtr& shape, bool fixed, const Aabb& box);
  /// Builds both trees (bulk, balanced).
  void finish();
  /// Gives a movable body a new box. The tree keeps a fattened copy (grown by `slack`, m) and is only
  /// updated, in collect(), when the box leaves it: resting or slow bodies cost nothing. So the pairs
  /// are a superset of those whose boxes overlap; the caller checks the exact boxes.
  void move(BodyIndex index, const Aabb& box, double slack);
  /// Appends every pair whose boxes overlap, lower index first: movable–movable and movable–fixed.
  /// The order is FCL's traversal order (the caller sorts). Stops once `pairs` holds `limit` entries and
  /// returns false (the pairs are then a partial list); true when every pair was appended.
  bool collect(std::vector<BodyPair>& pairs, std::size_t limit);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace impetus::collision
