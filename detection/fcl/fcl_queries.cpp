#include "impetus/detection/fcl/fcl_queries.hpp"

#include "fcl_shape.hpp"
#include "impetus/detection/fcl/analytic.hpp"

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
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace impetus::collision {
namespace {

fcl::Transform3d transform_of(const Placed& s) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = s.R;
  t.translation() = s.x;
  return t;
}

/// GJK's distance between a and b, b moved by `shift` (m): the gap (> 0) with witness points (the one on
/// b moved back), or not ok if they touch or FCL failed. Unsigned: no EPA (see signed_distance).
SignedDistance gjk_gap(const fcl::CollisionGeometryd& ga, const fcl::Transform3d& ta,
                       const fcl::CollisionGeometryd& gb, fcl::Transform3d tb, const Vec3& shift, double scale) {
  tb.translation() += shift;
  fcl::DistanceRequestd request(true);  // nearest points; enable_signed_distance stays off
  request.gjk_solver_type = fcl::GST_LIBCCD;
  request.distance_tolerance = 1e-9 * scale;
  fcl::DistanceResultd result;
  fcl::distance(&ga, ta, &gb, tb, request, result);
  if (!(result.min_distance > 0.0) || !std::isfinite(result.min_distance) || !result.nearest_points[0].allFinite() ||
      !result.nearest_points[1].allFinite())
    return {};
  return {true, result.min_distance, result.nearest_points[0], result.nearest_points[1] - shift};
}

/// The signed distance (see fcl_queries.hpp) without FCL's signed-distance query, which runs EPA on
/// penetration: Debian's FCL 0.7 is built with assertions, and EPA's `isOutsidePolytopeFace` aborts the
/// process on flat, aligned contacts (FCL issue 322; a cylinder standing on a box is enough).
///
/// A gap: GJK's distance and witness points. Penetration: libccd's MPR (through FCL's collision query)
/// gives a first direction n, not always the least-overlap one; then, by closest points, each step
/// moves b out along n to a small gap δ past its overlap `overlap(n)` and takes the direction between
/// GJK's witness points as the next n. The least-overlap direction n* is a fixed point (moved out along
/// n*, the deepest points are the nearest), and near it the error shrinks by about (depth + δ) / (radius
/// of curvature + δ) per step; on a flat face one step lands on its normal. The lowest overlap seen
/// wins. `scale` (the smaller shape's size) sets δ and the tolerances; `center_a` is a's center (world).
template <class Overlap>
SignedDistance signed_distance(const fcl::CollisionGeometryd& ga, const fcl::Transform3d& ta,
                               const fcl::CollisionGeometryd& gb, const fcl::Transform3d& tb, double scale,
                               const Vec3& center_a, const Overlap& overlap) {
  try {
    if (const SignedDistance gap = gjk_gap(ga, ta, gb, tb, Vec3::Zero(), scale); gap.ok) return gap;
    fcl::CollisionRequestd contact_request(1, true);
    contact_request.gjk_solver_type = fcl::GST_LIBCCD;
    fcl::CollisionResultd contact_result;
    fcl::collide(&ga, ta, &gb, tb, contact_request, contact_result);
    // Starts: MPR's direction, the line of centers and, deep in (past 2 % of the smaller shape), the
    // lowest of 128 directions spread evenly over the sphere (a Fibonacci lattice); deep in, the overlap
    // over directions can have a lower minimum than the one MPR's direction leads to.
    std::array<Vec3, 3> starts{tb.translation() - center_a, tb.translation() - center_a, Vec3::Zero()};
    if (contact_result.numContacts() > 0) starts[0] = contact_result.getContact(0).normal;  // a to b
    if (starts[0].allFinite() && starts[0].norm() > 0.0 && overlap(starts[0].normalized()) > 0.02 * scale) {
      constexpr int kLattice = 128;
      double lowest = std::numeric_limits<double>::infinity();
      for (int k = 0; k < kLattice; ++k) {
        const double z = 1.0 - (2.0 * k + 1.0) / kLattice, r = std::sqrt(1.0 - z * z);
        const double phi = k * std::numbers::pi * (3.0 - std::sqrt(5.0));
        const Vec3 n(r * std::cos(phi), r * std::sin(phi), z);
        if (const double o = overlap(n); o < lowest) lowest = o, starts[2] = n;
      }
    }
    constexpr int kSteps = 24;
    const double delta = 0.01 * scale;
    double least = std::numeric_limits<double>::infinity();
    Vec3 least_n = Vec3::Zero();
    for (Vec3 n : starts) {
      if (!n.allFinite() || !(n.norm() > 0.0)) continue;
      n.normalize();
      for (int step = 0; step < kSteps; ++step) {
        const double depth = overlap(n);
        if (!std::isfinite(depth)) break;
        if (depth < least) least = depth, least_n = n;
        const Vec3 out = (depth + delta) * n;
        const SignedDistance gap = gjk_gap(ga, ta, gb, tb, out, scale);
        if (!gap.ok) break;
        const Vec3 next = (gap.on_b + out - gap.on_a).normalized();
        if (!next.allFinite() || (next - n).norm() < 1e-12) break;
        n = next;
      }
    }
    if (!std::isfinite(least)) return {};
    // Witness points about the midpoint of the centers with on_a − on_b = depth · n (only n is used).
    const Vec3 mid = 0.5 * (center_a + tb.translation());
    return {true, -least, mid + 0.5 * least * least_n, mid - 0.5 * least * least_n};
  } catch (const std::exception&) {
    return {};
  }
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
  return signed_distance(*ga.geometry, transform_of(a), *gb.geometry, transform_of(b), std::min(a.size(), b.size()),
                         a.x, [&](const Vec3& n) { return overlap_along(a, b, n); });
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
  const auto overlap = [&](const Vec3& n) {
    return std::max({n.dot(tri[0]), n.dot(tri[1]), n.dot(tri[2])}) + support_height(pose, -n);
  };
  return signed_distance(triangle, fcl::Transform3d::Identity(), *shape.geometry, transform_of(pose),
                         std::min(size, pose.size()), (tri[0] + tri[1] + tri[2]) / 3.0, overlap);
}

}  // namespace impetus::collision
