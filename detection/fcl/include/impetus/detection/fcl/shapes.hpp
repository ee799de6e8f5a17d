#pragma once
/// \file
/// FCL-free shape geometry for the detector: each body's shape in its body frame (built once by
/// set_bodies), placed in the world at the body's pose, with the support queries the narrowphase and
/// the manifold builder need (support point, world AABB, supporting feature, candidate axes).
///
/// Frames: `ShapeGeometry` is in the body frame (origin = center of mass); `Placed` applies
/// p_world = x + R p_body. Every direction argument is a unit vector in the world frame.

#include "impetus/core/body.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace impetus::collision {

/// A fixed-capacity vector (no heap allocation in the per-pair hot path). push_back beyond the
/// capacity is ignored and reported by its return value.
template <typename T, std::size_t N>
class SmallVec {
 public:
  SmallVec() = default;
  // Copies only the elements in use (the storage is large and mostly empty).
  SmallVec(const SmallVec& other) : size_(other.size_) { std::copy(other.begin(), other.end(), data_.begin()); }
  SmallVec& operator=(const SmallVec& other) {
    size_ = other.size_;
    std::copy(other.begin(), other.end(), data_.begin());
    return *this;
  }
  bool push_back(const T& value) {
    if (size_ == N) return false;
    data_[size_++] = value;
    return true;
  }
  void clear() { size_ = 0; }
  void resize(std::size_t n) { size_ = n < N ? n : N; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  static constexpr std::size_t capacity() { return N; }
  T& operator[](std::size_t i) { assert(i < size_); return data_[i]; }
  const T& operator[](std::size_t i) const { assert(i < size_); return data_[i]; }
  T* begin() { return data_.data(); }
  T* end() { return data_.data() + size_; }
  const T* begin() const { return data_.data(); }
  const T* end() const { return data_.data() + size_; }

 private:
  std::array<T, N> data_;  // default-initialized: elements past size_ are never read
  std::size_t size_ = 0;
};

/// The shape kinds the detector distinguishes (a mesh becomes `convex` or `triangles`).
enum class ShapeKind : std::uint8_t { sphere, box, capsule, cylinder, convex, triangles, plane };

/// Geometry shared by every body that uses one mesh (body frame, m).
struct MeshData {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Vec3> triangle_normals;  ///< unit, outward (counter-clockwise seen from outside)
  std::vector<Vec3> face_normals;      ///< convex only: the distinct outward face normals
};

/// One body's collision geometry in its body frame.
struct ShapeGeometry {
  ShapeKind kind = ShapeKind::sphere;
  double radius = 0.0;              ///< sphere, capsule, cylinder (m)
  double half_length = 0.0;         ///< capsule, cylinder: half the straight part, along body z (m)
  Vec3 half_extents = Vec3::Zero(); ///< box (m)
  std::shared_ptr<const MeshData> mesh;  ///< convex, triangles
  Vec3 plane_normal = Vec3::UnitZ();     ///< plane: unit outward normal of the solid n·p ≤ offset
  double plane_offset = 0.0;             ///< plane (m)
  Vec3 local_min = Vec3::Zero();    ///< body-frame bounding box (bounded kinds)
  Vec3 local_max = Vec3::Zero();
  double size = 0.0;  ///< bounding radius about the center of mass (m): the scale of every tolerance
};

/// Why `mesh` cannot be used ("" if it can): no triangles, an index out of range, a non-finite vertex,
/// or, for `convex`, a vertex in front of a face plane by more than 1e-6 × its bounding radius.
std::string mesh_problem(const TriangleMesh& mesh, bool convex);

/// Builds the geometry of `shape`; `mesh` is the shared data for a mesh shape (null otherwise).
ShapeGeometry make_geometry(const Shape& shape, std::shared_ptr<const MeshData> mesh);

/// Derives triangle and face normals for a mesh (body frame). `convex` also collects the distinct face
/// normals used as separating-axis candidates.
std::shared_ptr<MeshData> make_mesh_data(const TriangleMesh& mesh, bool convex);

/// A shape at a pose: body-frame geometry, world position of the center of mass, rotation body→world.
struct Placed {
  const ShapeGeometry* geometry = nullptr;
  Vec3 x = Vec3::Zero();
  Mat3 R = Mat3::Identity();

  ShapeKind kind() const { return geometry->kind; }
  double size() const { return geometry->size; }
  /// Body z axis in the world frame (the capsule's and cylinder's axis).
  Vec3 axis() const { return R.col(2); }
};

/// World-frame plane of a `plane` shape: the solid n·p ≤ offset.
struct WorldPlane {
  Vec3 normal;
  double offset;
};
WorldPlane world_plane(const Placed& plane);

/// Axis-aligned box in the world frame (m).
struct Aabb {
  Vec3 min;
  Vec3 max;
};
/// Tight world AABB of a bounded shape (meshes: the body-frame box rotated, slightly loose).
Aabb world_aabb(const Placed& s);

/// The point of `s` farthest along `d` (world frame). Not for planes.
Vec3 support(const Placed& s, const Vec3& d);

/// max over s of d·p, the support function (m).
inline double support_height(const Placed& s, const Vec3& d) { return d.dot(support(s, d)); }

/// Tolerances for picking supporting features.
struct FeatureTolerance {
  double sin_angle = 0.01745;  ///< sin of the angle within which a face or edge counts as supporting (1°)
  double cos_angle = 0.99985;
};

/// The supporting feature of a convex shape along a direction: a point, a segment or a convex polygon
/// (world frame), each point with a stable id (vertex or rim index).
struct Feature {
  enum class Type : std::uint8_t { point, segment, polygon };
  Type type = Type::point;
  SmallVec<Vec3, 32> points;
  SmallVec<std::uint32_t, 32> ids;
  Vec3 normal = Vec3::UnitZ();  ///< polygon: its outward unit normal; otherwise the query direction
  std::uint32_t id = 0;         ///< id of the feature itself (face index, cap) for contact keys
};

/// Supporting feature of `s` along `d`: everything within `tol.sin_angle` × diameter of the extreme
/// point. Cylinder caps become a 12-gon starting at the deepest rim point. Not for planes or
/// triangle meshes.
Feature supporting_feature(const Placed& s, const Vec3& d, const FeatureTolerance& tol);

/// Candidate separating axes `s` contributes (world, unit): box face normals; the cylinder axis; for a
/// capsule or cylinder the perpendicular from its axis line to `other_center` (exact for parallel
/// neighbours and side contacts); convex-mesh face normals within ~25° of `hint`.
void candidate_axes(const Placed& s, const Vec3& hint, const Vec3& other_center, SmallVec<Vec3, 64>& out);

/// Body-frame corner `i` (0…7, bit k set = + side on axis k) of a box with these half extents.
inline Vec3 box_corner(const Vec3& half, int i) {
  return Vec3((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(), (i & 4) ? half.z() : -half.z());
}

}  // namespace impetus::collision
