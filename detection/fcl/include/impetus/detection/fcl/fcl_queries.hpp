#pragma once
/// \file
/// The FCL queries behind an FCL-free interface: building FCL geometry from the engine's shapes, the
/// signed-distance query (GJK for a gap; MPR, then closest points, for penetration; never EPA) used for
/// generic convex pairs and against mesh triangles, and the BVH midphase of triangle meshes. No FCL header here (see fcl_shape.hpp).

#include "impetus/detection/fcl/manifold.hpp"
#include "impetus/detection/fcl/shapes.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace impetus::collision {

struct FclShape;  // defined in fcl_shape.hpp
using FclShapePtr = std::shared_ptr<const FclShape>;

/// FCL geometry for `g`: sphere, box, capsule, cylinder → the FCL primitives (same conventions: full
/// lengths along z); a convex mesh → fcl::Convex (its triangles as faces); a triangle mesh →
/// BVHModel<OBBRSS>. Null for a plane (planes are handled analytically). Throws std::exception when
/// FCL rejects the geometry.
FclShapePtr make_fcl_shape(const ShapeGeometry& g);

/// Signed distance between two convex shapes: > 0 the gap, < 0 minus the penetration depth (m), with
/// witness points: the nearest points for a gap (GJK); for penetration two points with on_a − on_b =
/// depth · n along the least-overlap direction n found by closest points (see fcl_queries.cpp; exact
/// only to ~1e-6 m, and deep in possibly a local minimum: a hint for the separating-axis refinement).
/// `ok` is false if FCL failed (it throws on a few degenerate configurations; the caller falls back to
/// candidate axes). Never FCL's EPA, whose assertions abort the process (FCL issue 322).
struct SignedDistance {
  bool ok = false;
  double distance = 0.0;
  Vec3 on_a = Vec3::Zero();
  Vec3 on_b = Vec3::Zero();
};
SignedDistance fcl_signed_distance(const FclShape& ga, const Placed& a, const FclShape& gb, const Placed& b);

/// Midphase for a triangle mesh: the indices of its triangles that intersect the world box `box`
/// (FCL's BVH<OBBRSS> against a box proxy), sorted, at most `max_triangles`. False if FCL failed.
bool fcl_triangles_near(const FclShape& mesh, const Placed& pose, const Aabb& box, std::size_t max_triangles,
                        std::vector<std::uint32_t>& out);

/// Signed distance (as fcl_signed_distance) from the world triangle `tri` (a) to a convex shape (b),
/// the triangle as a two-sided flat fcl::Convex.
SignedDistance fcl_signed_distance_triangle(const std::array<Vec3, 3>& tri, const FclShape& shape, const Placed& pose);

}  // namespace impetus::collision
