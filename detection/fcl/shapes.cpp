#include "impetus/detection/fcl/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <variant>

namespace impetus::collision {

std::string mesh_problem(const TriangleMesh& mesh, bool convex) {
  if (mesh.vertices.empty() || mesh.triangles.empty()) return "has no triangles";
  double size = 0.0;
  for (const Vec3& v : mesh.vertices) {
    if (!v.allFinite()) return "has a non-finite vertex";
    size = std::max(size, v.norm());
  }
  for (const auto& t : mesh.triangles)
    for (std::uint32_t i : t)
      if (i >= mesh.vertices.size()) return "has a triangle index out of range (" + std::to_string(i) + ")";
  if (!convex) return "";
  // Every vertex must lie behind (or on) every face plane; the check is O(triangles × vertices), once.
  const double tol = 1e-6 * size;
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    const auto& t = mesh.triangles[k];
    const Vec3& v0 = mesh.vertices[t[0]];
    const Vec3 n = (mesh.vertices[t[1]] - v0).cross(mesh.vertices[t[2]] - v0);
    const double len = n.norm();
    if (len <= 1e-12 * size * size) continue;  // degenerate triangle: no plane
    for (const Vec3& v : mesh.vertices)
      if (n.dot(v - v0) > tol * len)
        return "is not convex (a vertex lies in front of triangle " + std::to_string(k) +
               "); use collision: triangles";
  }
  return "";
}

std::shared_ptr<MeshData> make_mesh_data(const TriangleMesh& mesh, bool convex) {
  auto data = std::make_shared<MeshData>();
  data->vertices = mesh.vertices;
  data->triangles = mesh.triangles;
  data->triangle_normals.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    const double len = n.norm();
    data->triangle_normals.push_back(len > 0.0 ? Vec3(n / len) : Vec3::Zero());
    if (!convex || len == 0.0) continue;
    const Vec3 unit = n / len;
    const bool seen = std::any_of(data->face_normals.begin(), data->face_normals.end(),
                                  [&](const Vec3& m) { return m.dot(unit) > 1.0 - 1e-9; });
    if (!seen) data->face_normals.push_back(unit);
  }
  return data;
}

ShapeGeometry make_geometry(const Shape& shape, std::shared_ptr<const MeshData> mesh) {
  ShapeGeometry g;
  auto bounds = [&g](const Vec3& half) {
    g.local_min = -half;
    g.local_max = half;
  };
  std::visit(
      [&](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, Sphere>) {
          g.kind = ShapeKind::sphere;
          g.radius = s.radius;
          bounds(Vec3::Constant(s.radius));
          g.size = s.radius;
        } else if constexpr (std::is_same_v<T, Box>) {
          g.kind = ShapeKind::box;
          g.half_extents = 0.5 * s.size;
          bounds(g.half_extents);
          g.size = g.half_extents.norm();
        } else if constexpr (std::is_same_v<T, Capsule>) {
          g.kind = ShapeKind::capsule;
          g.radius = s.radius;
          g.half_length = 0.5 * s.length;
          bounds(Vec3(s.radius, s.radius, g.half_length + s.radius));
          g.size = g.half_length + s.radius;
        } else if constexpr (std::is_same_v<T, Cylinder>) {
          g.kind = ShapeKind::cylinder;
          g.radius = s.radius;
          g.half_length = 0.5 * s.length;
          bounds(Vec3(s.radius, s.radius, g.half_length));
          g.size = std::hypot(s.radius, g.half_length);
        } else if constexpr (std::is_same_v<T, Plane>) {
          g.kind = ShapeKind::plane;
          g.plane_normal = s.normal.normalized();
          g.plane_offset = s.offset;
        } else {
          g.kind = s.collision == MeshCollision::convex ? ShapeKind::convex : ShapeKind::triangles;
          g.mesh = std::move(mesh);
          g.local_min = Vec3::Constant(INFINITY);
          g.local_max = Vec3::Constant(-INFINITY);
          for (const Vec3& v : g.mesh->vertices) {
            g.local_min = g.local_min.cwiseMin(v);
            g.local_max = g.local_max.cwiseMax(v);
            g.size = std::max(g.size, v.norm());
          }
        }
      },
      shape);
  return g;
}

WorldPlane world_plane(const Placed& plane) {
  const Vec3 n = plane.R * plane.geometry->plane_normal;
  return {n, plane.geometry->plane_offset + n.dot(plane.x)};
}

Aabb world_aabb(const Placed& s) {
  const ShapeGeometry& g = *s.geometry;
  Vec3 center = s.x, half;
  switch (g.kind) {
    case ShapeKind::sphere: half = Vec3::Constant(g.radius); break;
    case ShapeKind::box: half = s.R.cwiseAbs() * g.half_extents; break;
    case ShapeKind::capsule: half = s.axis().cwiseAbs() * g.half_length + Vec3::Constant(g.radius); break;
    case ShapeKind::cylinder: {
      const Vec3 u = s.axis();
      for (int i = 0; i < 3; ++i)
        half[i] = std::abs(u[i]) * g.half_length + g.radius * std::sqrt(std::max(0.0, 1.0 - u[i] * u[i]));
      break;
    }
    default:
      center = s.x + s.R * (0.5 * (g.local_min + g.local_max));
      half = s.R.cwiseAbs() * (0.5 * (g.local_max - g.local_min));
      break;
  }
  return {center - half, center + half};
}

Vec3 support(const Placed& s, const Vec3& d) {
  const ShapeGeometry& g = *s.geometry;
  switch (g.kind) {
    case ShapeKind::sphere: return s.x + g.radius * d;
    case ShapeKind::box: {
      const Vec3 dl = s.R.transpose() * d;
      const Vec3 p(dl.x() >= 0 ? g.half_extents.x() : -g.half_extents.x(),
                   dl.y() >= 0 ? g.half_extents.y() : -g.half_extents.y(),
                   dl.z() >= 0 ? g.half_extents.z() : -g.half_extents.z());
      return s.x + s.R * p;
    }
    case ShapeKind::capsule: {
      const Vec3 u = s.axis();
      return s.x + (u.dot(d) >= 0 ? g.half_length : -g.half_length) * u + g.radius * d;
    }
    case ShapeKind::cylinder: {
      // In the body frame, where the radial part of d is exactly perpendicular to the axis: in the world
      // frame, d − (u·d)u keeps a rounding error along u (u is unit only to 1e-16), and divided by a
      // tiny radial length it moved the height by up to 1e-5 m for d within 1e-8 rad of the axis.
      const Vec3 dl = s.R.transpose() * d;
      const double wn = std::hypot(dl.x(), dl.y());
      const Vec3 rim = wn > 0.0 ? Vec3(g.radius * dl.x() / wn, g.radius * dl.y() / wn, 0.0) : Vec3::Zero();
      return s.x + s.R * (rim + Vec3(0.0, 0.0, dl.z() >= 0 ? g.half_length : -g.half_length));
    }
    case ShapeKind::convex:
    case ShapeKind::triangles: {
      const Vec3 dl = s.R.transpose() * d;
      const std::vector<Vec3>& v = g.mesh->vertices;
      std::size_t best = 0;
      double top = -INFINITY;
      for (std::size_t i = 0; i < v.size(); ++i)
        if (const double h = dl.dot(v[i]); h > top) top = h, best = i;
      return s.x + s.R * v[best];
    }
    case ShapeKind::plane: break;
  }
  assert(false && "support() of a plane");
  return s.x;
}

}  // namespace impetus::collision
