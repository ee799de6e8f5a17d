#include "impetus/detection/fcl/fcl_queries.hpp"

#include "fcl_shape.hpp"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace impetus::collision {
namespace {

fcl::Transform3d transform_of(const Placed& s) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = s.R;
  t.translation() = s.x;
  return t;
}

/// FCL's signed distance with witness points (see fcl_queries.hpp); `scale` sets the tolerance.
SignedDistance signed_distance(const fcl::CollisionGeometryd& ga, const fcl::Transform3d& ta,
                               const fcl::CollisionGeometryd& gb, const fcl::Transform3d& tb, double scale) {
  // The default request gives no witness points and no penetration: ask for both. GJK for a gap, EPA
  // (libccd, as fixed in FCL 0.6) for penetration; the tolerance follows the smaller shape.
  fcl::DistanceRequestd request(true, true);
  request.gjk_solver_type = fcl::GST_LIBCCD;
  request.distance_tolerance = 1e-6 * scale;
  fcl::DistanceResultd result;
  try {
    fcl::distance(&ga, ta, &gb, tb, request, result);
  } catch (const std::exception&) {
    return {};
  }
  if (!std::isfinite(result.min_distance) || !result.nearest_points[0].allFinite() ||
      !result.nearest_points[1].allFinite())
    return {};
  return {true, result.min_distance, result.nearest_points[0], result.nearest_points[1]};
}

std::shared_ptr<fcl::CollisionGeometryd> convex_geometry(const MeshData& mesh) {
  auto vertices = std::make_shared<std::vector<fcl::Vector3d>>(mesh.vertices.begin(), mesh.vertices.end());
  auto faces = std::make_shared<std::vector<int>>();
  faces->reserve(4 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) faces->insert(faces->end(), {3, int(t[0]), int(t[1]), int(t[2])});
  // throw_if_invalid: FCL checks the topology (every edge shared by two faces); convexity is ours.
  return std::make_shared<fcl::Convexd>(vertices, static_cast<int>(mesh.triangles.size()), faces, true);
}

std::shared_ptr<fcl::CollisionGeometryd> triangle_geometry(const MeshData& mesh) {
  auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  const std::vector<fcl::Vector3d> vertices(mesh.vertices.begin(), mesh.vertices.end());
  if (model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(vertices.size())) != fcl::BVH_OK ||
      model->addSubModel(vertices, triangles) != fcl::BVH_OK || model->endModel() != fcl::BVH_OK)
    throw std::runtime_error("FCL could not build a BVH<OBBRSS> from the triangles");
  return model;
}

}  // namespace

FclShapePtr make_fcl_shape(const ShapeGeometry& g) {
  auto shape = std::make_shared<FclShape>();
  switch (g.kind) {
    case ShapeKind::sphere: shape->geometry = std::make_shared<fcl::Sphered>(g.radius); break;
    case ShapeKind::box: shape->geometry = std::make_shared<fcl::Boxd>(2.0 * g.half_extents); break;
    case ShapeKind::capsule: shape->geometry = std::make_shared<fcl::Capsuled>(g.radius, 2.0 * g.half_length); break;
    case ShapeKind::cylinder:
      shape->geometry = std::make_shared<fcl::Cylinderd>(g.radius, 2.0 * g.half_length);
      break;
    case ShapeKind::convex: shape->geometry = convex_geometry(*g.mesh); break;
    case ShapeKind::triangles: shape->geometry = triangle_geometry(*g.mesh); break;
    case ShapeKind::plane: return nullptr;
  }
  shape->geometry->computeLocalAABB();
  return shape;
}

SignedDistance fcl_signed_distance(const FclShape& ga, const Placed& a, const FclShape& gb, const Placed& b) {
  return signed_distance(*ga.geometry, transform_of(a), *gb.geometry, transform_of(b), std::min(a.size(), b.size()));
}

bool fcl_triangles_near(const FclShape& mesh, const Placed& pose, const Aabb& box, std::size_t max_triangles,
                        std::vector<std::uint32_t>& out) {
  out.clear();
  const auto proxy = std::make_shared<fcl::Boxd>(box.max - box.min);
  fcl::Transform3d proxy_pose = fcl::Transform3d::Identity();
  proxy_pose.translation() = 0.5 * (box.min + box.max);
  // Contact data is not needed, only which triangles (b1, the BVH's primitive) touch the box.
  fcl::CollisionRequestd request(max_triangles, false);
  fcl::CollisionResultd result;
  try {
    fcl::collide(mesh.geometry.get(), transform_of(pose), proxy.get(), proxy_pose, request, result);
  } catch (const std::exception&) {
    return false;
  }
  for (std::size_t i = 0; i < result.numContacts(); ++i)
    if (const std::intptr_t t = result.getContact(i).b1; t >= 0) out.push_back(static_cast<std::uint32_t>(t));
  std::sort(out.begin(), out.end());  // FCL's traversal order is not ours to depend on
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return true;
}

SignedDistance fcl_signed_distance_triangle(const std::array<Vec3, 3>& tri, const FclShape& shape, const Placed& pose) {
  // A flat two-sided convex: front and back faces share the three edges, a valid closed topology.
  auto vertices = std::make_shared<std::vector<fcl::Vector3d>>(tri.begin(), tri.end());
  auto faces = std::make_shared<std::vector<int>>(std::vector<int>{3, 0, 1, 2, 3, 0, 2, 1});
  const fcl::Convexd triangle(vertices, 2, faces, false);
  const double size = std::max({(tri[1] - tri[0]).norm(), (tri[2] - tri[1]).norm(), (tri[0] - tri[2]).norm()});
  return signed_distance(triangle, fcl::Transform3d::Identity(), *shape.geometry, transform_of(pose),
                         std::min(size, pose.size()));
}

}  // namespace impetus::collision
