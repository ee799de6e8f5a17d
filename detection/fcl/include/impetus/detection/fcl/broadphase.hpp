#pragma once
/// \file
/// The broadphase: a hierarchical grid, rebuilt from the bodies' boxes at every collect() in time about
/// linear in the bodies: bodies of similar size share one uniform grid whose cell is a little larger
/// than their largest box, and much larger ones go to coarser grids (detection/fcl/README.md).
/// Two fixed bodies never form a pair. Planes are unbounded and never enter a grid: the detector tests
/// them against the movable bodies' boxes itself.

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
  /// Registers body `index` with its world box (already grown by the margin). Call finish() after the
  /// last one.
  void add(BodyIndex index, bool fixed, const Aabb& box);
  /// Ends the registration (sizes the scratch, so collect() allocates nothing while the scene is stable).
  void finish();
  /// Gives a movable body a new box.
  void move(BodyIndex index, const Aabb& box);
  /// Appends every pair whose boxes overlap (boxes touching count), lower index first, each once:
  /// movable–movable and movable–fixed. In no particular order (the caller sorts). Stops once `pairs`
  /// holds `limit` entries and returns false (the pairs are then a partial list); true when every pair
  /// was appended.
  bool collect(std::vector<BodyPair>& pairs, std::size_t limit);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace impetus::collision
