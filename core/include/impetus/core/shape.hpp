#pragma once
/// \file
/// Collision shapes in the body frame, centered on the body's center of mass (docs/conventions.md,
/// "Scene files"). Shapes carry geometry only; mass properties live in RigidBody.

#include "impetus/core/math.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace impetus {

/// Sphere of `radius` (m) centered on the center of mass.
struct Sphere {
  double radius = 0.5;
};

/// Box with full edge lengths `size` (m) along the body axes.
struct Box {
  Vec3 size{1.0, 1.0, 1.0};
};

/// Capsule: a segment of `length` (m) along body z, swept by a sphere of `radius`.
struct Capsule {
  double radius = 0.5;
  double length = 1.0;
};

/// Solid cylinder of `radius` and `length` (m), axis along body z.
struct Cylinder {
  double radius = 0.5;
  double length = 1.0;
};

/// The solid half-space n·p ≤ offset (world frame for a fixed body with identity pose), its unit
/// `normal` pointing out of the solid. Only fixed bodies may have a plane.
struct Plane {
  Vec3 normal{0.0, 0.0, 1.0};
  double offset = 0.0;
};

/// A closed triangle mesh in the body frame (m), the engine's own mesh type: detectors build their
/// geometry from it, never from importer types. Triangles index `vertices`, counter-clockwise seen
/// from outside.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// How a detector should treat a mesh.
enum class MeshCollision : std::uint8_t {
  convex,    ///< use the convex hull (exact penetration depth)
  triangles  ///< use the triangles as given (non-convex)
};

/// A mesh shape: the file it came from (for messages), its scale, and the imported geometry (shared
/// between bodies that use the same file). `mesh` is null until the asset pipeline fills it; the
/// pipeline (assets/mesh_body.hpp) has moved it so the body frame's origin is its center of mass.
struct MeshShape {
  std::filesystem::path file;
  double scale = 1.0;
  MeshCollision collision = MeshCollision::convex;
  std::shared_ptr<const TriangleMesh> mesh;
  /// The convex hull of `mesh` (same frame; closed, outward, only hull vertices), filled by the asset
  /// pipeline. Null for a shape built in code without one.
  std::shared_ptr<const TriangleMesh> hull;

  /// What a detector should collide: the hull for convex collision when there is one, else `mesh`.
  const TriangleMesh* collision_mesh() const {
    return collision == MeshCollision::convex && hull ? hull.get() : mesh.get();
  }
};

/// One of the shape kinds above.
using Shape = std::variant<Sphere, Box, Capsule, Cylinder, Plane, MeshShape>;

/// Lower-case name of the shape kind ("sphere", "box", …) for messages and output.
inline const char* shape_kind_name(const Shape& shape) {
  static constexpr const char* names[] = {"sphere", "box", "capsule", "cylinder", "plane", "mesh"};
  return names[shape.index()];
}

}  // namespace impetus
