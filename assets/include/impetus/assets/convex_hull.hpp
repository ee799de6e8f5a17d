#pragma once
/// \file
/// Convex hull of a point set (3D quickhull), for meshes a scene collides as convex.

#include "impetus/core/shape.hpp"

#include <vector>

namespace impetus::assets {

/// The convex hull of `points` as a closed triangle mesh wound outward, holding only the points
/// that are hull vertices (points within a relative 1e-11 of the bounding-box diagonal of a hull face
/// count as on it, so coplanar faces come out as several triangles). Throws Error when the points
/// span no volume (fewer than four, or all collinear or coplanar) and when the construction fails
/// its own closedness check (a bug, reported rather than returned).
TriangleMesh convex_hull(const std::vector<Vec3>& points);

/// True when the hull of `mesh` encloses no more volume than `mesh` itself, within a relative
/// `tolerance`: the mesh is convex (a closed, outward-wound mesh is assumed).
bool is_convex(const TriangleMesh& mesh, const TriangleMesh& hull, double tolerance = 1e-9);

}  // namespace impetus::assets
