#pragma once
/// \file
/// The one internal header that includes FCL: the FCL geometry of a body. Included only by the
/// detector's FCL translation units (fcl_queries.cpp, broadphase.cpp), never by anything outside
/// detection/fcl/.

#include <fcl/geometry/collision_geometry.h>

#include <memory>

namespace impetus::collision {

/// A body's FCL geometry (body frame), shared by the broadphase object and the narrowphase queries.
struct FclShape {
  std::shared_ptr<fcl::CollisionGeometryd> geometry;
};

}  // namespace impetus::collision
