#include "impetus/detection/fcl/broadphase.hpp"

#include "fcl_shape.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/narrowphase/collision_object.h>

#include <algorithm>
#include <cstdint>

namespace impetus::collision {
namespace {

/// An FCL collision object whose world box the detector sets itself: tight for rotated primitives
/// (FCL's own computeAABB bounds a rotated shape by its bounding sphere) and grown by the margin, so
/// bodies within the margin of touching become a pair.
class BodyObject final : public fcl::CollisionObjectd {
 public:
  BodyObject(const std::shared_ptr<fcl::CollisionGeometryd>& geometry, BodyIndex index)
      : fcl::CollisionObjectd(geometry), index_(index) {}
  BodyIndex index() const { return index_; }
  /// Replaces the world box; returns whether it changed.
  bool set_box(const Aabb& box) {
    if (aabb.min_ == box.min && aabb.max_ == box.max) return false;
    aabb.min_ = box.min;
    aabb.max_ = box.max;
    return true;
  }
  /// Whether `box` lies inside the current world box.
  bool contains(const Aabb& box) const {
    return (aabb.min_.array() <= box.min.array()).all() && (box.max.array() <= aabb.max_.array()).all();
  }

 private:
  BodyIndex index_;
};

// Where the callback appends, and when it stops: at `limit` pairs it records that it stopped and tells
// FCL to end the traversal (returning true), so a pathological scene never allocates every pair.
struct PairSink {
  std::vector<BodyPair>* pairs;
  std::size_t limit;
  bool stopped = false;
};

bool record_pair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
  auto& sink = *static_cast<PairSink*>(data);
  if (sink.pairs->size() >= sink.limit) {
    sink.stopped = true;
    return true;  // done: the caller refuses the detection
  }
  const BodyIndex i = static_cast<BodyObject*>(o1)->index(), j = static_cast<BodyObject*>(o2)->index();
  sink.pairs->emplace_back(std::min(i, j), std::max(i, j));
  return false;  // keep going: we want every pair
}

}  // namespace

struct Broadphase::Impl {
  fcl::DynamicAABBTreeCollisionManagerd movable;
  fcl::DynamicAABBTreeCollisionManagerd fixed;
  std::vector<std::unique_ptr<BodyObject>> objects;
  std::vector<BodyObject*> by_index;  // body index → its object (null for planes)
  std::vector<fcl::CollisionObjectd*> moved;
};

Broadphase::Broadphase() : impl_(std::make_unique<Impl>()) {}
Broadphase::~Broadphase() = default;

void Broadphase::clear() { impl_ = std::make_unique<Impl>(); }

void Broadphase::add(BodyIndex index, const FclShapePtr& shape, bool fixed, const Aabb& box) {
  auto object = std::make_unique<BodyObject>(shape->geometry, index);
  object->set_box(box);
  object->setUserData(fixed ? &impl_->fixed : &impl_->movable);  // which tree it belongs to
  if (impl_->by_index.size() <= index) impl_->by_index.resize(index + 1, nullptr);
  impl_->by_index[index] = object.get();
  impl_->objects.push_back(std::move(object));
}

void Broadphase::finish() {
  std::vector<fcl::CollisionObjectd*> movable, fixed;
  for (const auto& object : impl_->objects)
    (object->getUserData() == &impl_->fixed ? fixed : movable).push_back(object.get());
  impl_->movable.registerObjects(movable);
  impl_->fixed.registerObjects(fixed);
  impl_->movable.setup();
  impl_->fixed.setup();
  impl_->moved.reserve(movable.size());  // move() then never allocates
}

void Broadphase::move(BodyIndex index, const Aabb& box, double slack) {
  BodyObject* object = impl_->by_index[index];
  if (object->contains(box)) return;
  object->set_box({(box.min.array() - slack).matrix(), (box.max.array() + slack).matrix()});
  impl_->moved.push_back(object);
}

bool Broadphase::collect(std::vector<BodyPair>& pairs, std::size_t limit) {
  if (!impl_->moved.empty()) {
    impl_->movable.update(impl_->moved);  // incremental: re-inserts only leaves that left their box
    impl_->moved.clear();
  }
  PairSink sink{&pairs, limit};
  impl_->movable.collide(&sink, &record_pair);
  if (!sink.stopped && !impl_->fixed.empty()) impl_->movable.collide(&impl_->fixed, &sink, &record_pair);
  return !sink.stopped;
}

}  // namespace impetus::collision
