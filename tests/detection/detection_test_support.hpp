#pragma once
// Helpers shared by the detector tests: bodies of each shape, a cube / octahedron mesh, one-call
// detection.
#include "impetus/detection/fcl/fcl_detector.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace impetus::test {

inline RigidBody make_body(const std::string& name, Shape shape, const Vec3& position,
                           const Mat3& rotation = Mat3::Identity(), bool fixed = false) {
  RigidBody b;
  b.name = name;
  b.shape = std::move(shape);
  b.position = position;
  b.rotation = rotation;
  if (fixed) make_fixed(b);
  return b;
}

/// The fixed half-space z ≤ height, its body placed on its surface (so (x_b − x_a)·n > 0 holds).
inline RigidBody ground(double height = 0.0) {
  return make_body("ground", Plane{Vec3::UnitZ(), 0.0}, Vec3(0, 0, height), Mat3::Identity(), true);
}

/// Closed triangle mesh from vertices and (possibly non-triangular) convex faces given by their corner
/// indices in any order: each face is sorted around its outward normal and fanned.
inline std::shared_ptr<TriangleMesh> mesh_from_faces(std::vector<Vec3> vertices,
                                                     const std::vector<std::vector<std::uint32_t>>& faces) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->vertices = std::move(vertices);
  Vec3 center = Vec3::Zero();
  for (const Vec3& v : mesh->vertices) center += v;
  center /= static_cast<double>(mesh->vertices.size());
  for (std::vector<std::uint32_t> f : faces) {
    Vec3 c = Vec3::Zero();
    for (auto i : f) c += mesh->vertices[i];
    c /= static_cast<double>(f.size());
    const Vec3 n = (c - center).normalized();
    const Vec3 t1 = (mesh->vertices[f[0]] - c).normalized(), t2 = n.cross(t1);
    std::sort(f.begin(), f.end(), [&](auto a, auto b) {
      const Vec3 da = mesh->vertices[a] - c, db = mesh->vertices[b] - c;
      return std::atan2(da.dot(t2), da.dot(t1)) < std::atan2(db.dot(t2), db.dot(t1));
    });
    for (std::size_t k = 1; k + 1 < f.size(); ++k) mesh->triangles.push_back({f[0], f[k], f[k + 1]});
  }
  return mesh;
}

/// Axis-aligned cube mesh of half-width `h` centered on the origin (12 triangles).
inline std::shared_ptr<TriangleMesh> cube_mesh(double h) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) v.emplace_back((i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h);
  return mesh_from_faces(v, {{0, 2, 4, 6}, {1, 3, 5, 7}, {0, 1, 4, 5}, {2, 3, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7}});
}

/// Regular octahedron with vertices at distance `r` on the axes.
inline std::shared_ptr<TriangleMesh> octahedron_mesh(double r) {
  std::vector<Vec3> v{{r, 0, 0}, {-r, 0, 0}, {0, r, 0}, {0, -r, 0}, {0, 0, r}, {0, 0, -r}};
  std::vector<std::vector<std::uint32_t>> faces;
  for (std::uint32_t x : {0u, 1u})
    for (std::uint32_t y : {2u, 3u})
      for (std::uint32_t z : {4u, 5u}) faces.push_back({x, y, z});
  return mesh_from_faces(v, faces);
}

inline MeshShape mesh_shape(std::shared_ptr<TriangleMesh> mesh, MeshCollision collision) {
  MeshShape m;
  m.file = "test.obj";
  m.mesh = std::move(mesh);
  m.collision = collision;
  return m;
}

/// set_bodies + one detect; fails the test if set_bodies refuses.
inline std::vector<Contact> detect_once(const std::vector<RigidBody>& bodies, const FclDetectorSettings& settings = {},
                                        const std::vector<BodyPair>& excluded = {},
                                        DetectorCounters* counters = nullptr) {
  FclDetector detector(settings);
  const ModuleStatus status = detector.set_bodies(bodies, excluded);
  EXPECT_TRUE(status.ok) << status.message;
  std::vector<Contact> contacts;
  DetectorCounters local;
  detector.detect(bodies, StepContext{}, contacts, counters ? *counters : local);
  return contacts;
}

inline Mat3 rotation_about(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

}  // namespace impetus::test
