#pragma once
/// \file
/// Contacts of non-convex triangle meshes (`collision: triangles`). FCL's BVH<OBBRSS> is the midphase
/// (which triangles come near the other body, margin included); each such triangle is then a one-sided
/// convex piece tested with the same separating-axis and clipping code as convex pairs, because FCL's
/// own triangle contacts were found unreliable (normals of either sign, negative depths; see README).
/// The normal out of a mesh always leaves a triangle on its outer side (counter-clockwise side).

#include "impetus/detection/fcl/analytic.hpp"
#include "impetus/detection/fcl/fcl_queries.hpp"
#include "impetus/detection/fcl/manifold.hpp"
#include "impetus/detection/fcl/shapes.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace impetus::collision {

/// Closest point of the triangle (t0, t1, t2) to p (world, m).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& t0, const Vec3& t1, const Vec3& t2);

/// Closest points between the segment [p0, p1] and the triangle `tri` (world, m).
void closest_points_segment_triangle(const Vec3& p0, const Vec3& p1, const std::array<Vec3, 3>& tri, Vec3& on_segment,
                                     Vec3& on_triangle);

/// Reusable scratch state for triangle-mesh pairs (no allocation per triangle once warmed up).
class MeshContacts {
 public:
  MeshContacts();
  MeshContacts(const MeshContacts&) = delete;
  MeshContacts& operator=(const MeshContacts&) = delete;

  /// A triangle mesh against a convex shape; `mesh_is_a` says which body of the pair the mesh is.
  /// Adds the FCL queries that failed to `failures`.
  void mesh_vs_convex(const Placed& mesh, const FclShape& mesh_fcl, const Placed& other, const FclShape& other_fcl,
                      bool mesh_is_a, const PairSettings& s, std::vector<ManifoldPoint>& out, std::uint64_t& failures);

  /// Two triangle meshes: every pair of nearby triangles whose boxes overlap (within the margin).
  void mesh_vs_mesh(const Placed& a, const FclShape& a_fcl, const Placed& b, const FclShape& b_fcl,
                    const PairSettings& s, std::vector<ManifoldPoint>& out, std::uint64_t& failures);

  /// Most triangles taken from one mesh per pair (FCL's midphase stops there).
  static constexpr std::size_t kMaxTriangles = 4096;

 private:
  /// One triangle as a convex shape: vertices around their centroid, identity rotation.
  struct Piece {
    MeshData data;
    ShapeGeometry geometry;
    std::array<Vec3, 3> world{};
    Vec3 normal = Vec3::Zero();  ///< outward unit normal, zero for a degenerate triangle
    Placed placed;
    Aabb box{};
    void set(const Placed& mesh, std::uint32_t triangle, double margin);
  };

  std::vector<std::uint32_t> near_a_, near_b_;
  Piece piece_a_, piece_b_;
};

}  // namespace impetus::collision
