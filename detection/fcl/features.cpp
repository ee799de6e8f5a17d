// Supporting features and candidate axes of the shapes (declared in shapes.hpp).
#include "impetus/detection/fcl/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace impetus::collision {
namespace {

constexpr int kRimPoints = 12;  // a cylinder cap as a 12-gon: reduced to 4 spanning points later

/// Orthonormal t1, t2 with (t1, t2, d) right-handed, so counter-clockwise in (t1, t2) is
/// counter-clockwise seen from the +d side.
void basis_for(const Vec3& d, Vec3& t1, Vec3& t2) {
  t1 = std::abs(d.x()) < 0.57 ? Vec3::UnitX().cross(d) : Vec3::UnitY().cross(d);
  t1.normalize();
  t2 = d.cross(t1);
}

double cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

/// Polygon normal by Newell's method (robust for nearly planar loops), unit or zero.
Vec3 newell_normal(const SmallVec<Vec3, 32>& p) {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3& a = p[i];
    const Vec3& b = p[(i + 1) % p.size()];
    n += Vec3((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()), (a.x() - b.x()) * (a.y() + b.y()));
  }
  const double len = n.norm();
  return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
}

struct Candidate {
  Eigen::Vector2d q;  // coordinates in the plane ⊥ d
  std::uint32_t id;
};

/// Supporting feature of a vertex set (box corners or convex-mesh vertices), body frame `local`.
template <typename VertexAt>
Feature polytope_feature(const Placed& s, const Vec3& d, std::size_t count, VertexAt vertex_at,
                         const FeatureTolerance& tol) {
  const Vec3 dl = s.R.transpose() * d;
  double top = -INFINITY;
  for (std::size_t i = 0; i < count; ++i) top = std::max(top, dl.dot(vertex_at(i)));
  const double band = 2.0 * s.size() * tol.sin_angle;  // a face tilted < angle_tol lies within this band

  thread_local std::vector<Candidate> set;
  set.clear();
  Vec3 t1, t2;
  basis_for(dl, t1, t2);
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3 v = vertex_at(i);
    if (dl.dot(v) >= top - band) set.push_back({Eigen::Vector2d(t1.dot(v), t2.dot(v)), static_cast<std::uint32_t>(i)});
  }
  Feature f;
  f.normal = d;
  auto world = [&](std::uint32_t id) { return Vec3(s.x + s.R * vertex_at(id)); };
  if (set.size() == 1) {
    f.type = Feature::Type::point;
    f.points.push_back(world(set[0].id));
    f.ids.push_back(set[0].id);
    f.id = set[0].id;
    return f;
  }
  // Andrew's monotone chain: counter-clockwise hull, collinear points dropped; deterministic order.
  std::sort(set.begin(), set.end(), [](const Candidate& a, const Candidate& b) {
    return a.q.x() < b.q.x() || (a.q.x() == b.q.x() && (a.q.y() < b.q.y() || (a.q.y() == b.q.y() && a.id < b.id)));
  });
  thread_local std::vector<Candidate> hull;
  hull.assign(2 * set.size(), Candidate{});
  std::size_t k = 0;
  for (std::size_t i = 0; i < set.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 2].q, hull[k - 1].q, set[i].q) <= 0.0) --k;
    hull[k++] = set[i];
  }
  for (std::size_t i = set.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross2(hull[k - 2].q, hull[k - 1].q, set[i].q) <= 0.0) --k;
    hull[k++] = set[i];
  }
  hull.resize(k > 1 ? k - 1 : k);
  std::uint32_t min_id = UINT32_MAX;
  for (const Candidate& c : set) min_id = std::min(min_id, c.id);
  f.id = min_id;
  if (hull.size() < 3) {  // collinear: the segment between the extreme points
    f.type = Feature::Type::segment;
    for (const Candidate* c : {&set.front(), &set.back()}) {
      f.points.push_back(world(c->id));
      f.ids.push_back(c->id);
    }
    return f;
  }
  // A face with more vertices than a feature holds is decimated evenly (a slightly smaller polygon).
  const std::size_t n = hull.size(), keep = std::min(n, f.points.capacity());
  for (std::size_t j = 0; j < keep; ++j) {
    const Candidate& c = hull[j * n / keep];
    f.points.push_back(world(c.id));
    f.ids.push_back(c.id);
  }
  f.type = Feature::Type::polygon;
  const Vec3 n_face = newell_normal(f.points);
  f.normal = n_face.dot(d) > 0.0 ? n_face : d;
  return f;
}

/// Supporting feature of a box, directly: an axis whose edge is within the tolerance band of level
/// is "free" (both of its corners support): no free axis → a corner, one → an edge, two → a face.
Feature box_feature(const Placed& s, const Vec3& d, const FeatureTolerance& tol) {
  const Vec3& h = s.geometry->half_extents;
  const Vec3 dl = s.R.transpose() * d;
  const double band = 2.0 * s.size() * tol.sin_angle;
  std::array<bool, 3> free{};
  int free_count = 0;
  std::uint32_t top = 0;  // the extreme corner's index
  for (int i = 0; i < 3; ++i) {
    if (dl[i] >= 0.0) top |= 1u << i;
    free[i] = 2.0 * h[i] * std::abs(dl[i]) <= band;
    free_count += free[i];
  }
  Feature f;
  f.normal = d;
  auto add = [&](std::uint32_t corner) {
    f.points.push_back(s.x + s.R * box_corner(h, static_cast<int>(corner)));
    f.ids.push_back(corner);
  };
  if (free_count == 0 || free_count == 3) {  // (3: a zero direction, never asked)
    f.type = Feature::Type::point;
    f.id = top;
    add(top);
  } else if (free_count == 1) {
    const int i = free[0] ? 0 : free[1] ? 1 : 2;
    f.type = Feature::Type::segment;
    f.id = 8 + static_cast<std::uint32_t>(i);
    add(top & ~(1u << i));
    add(top | (1u << i));
  } else {
    const int k = !free[0] ? 0 : !free[1] ? 1 : 2;  // the face's axis
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    f.type = Feature::Type::polygon;
    f.id = 16 + 2 * static_cast<std::uint32_t>(k) + ((top >> k) & 1u);
    f.normal = ((top >> k) & 1u ? 1.0 : -1.0) * s.R.col(k);
    const std::uint32_t base = top & (1u << k);
    for (const auto& [bi, bj] : {std::pair{0u, 0u}, {1u, 0u}, {1u, 1u}, {0u, 1u}}) add(base | (bi << i) | (bj << j));
  }
  return f;
}

}  // namespace

Feature supporting_feature(const Placed& s, const Vec3& d, const FeatureTolerance& tol) {
  const ShapeGeometry& g = *s.geometry;
  Feature f;
  f.normal = d;
  auto point = [&f](const Vec3& p, std::uint32_t id) {
    f.type = Feature::Type::point;
    f.points.push_back(p);
    f.ids.push_back(id);
    f.id = id;
  };
  switch (g.kind) {
    case ShapeKind::sphere: point(s.x + g.radius * d, 0); return f;
    case ShapeKind::capsule: {
      const Vec3 u = s.axis();
      const double a = u.dot(d);
      if (std::abs(a) <= tol.sin_angle) {  // lying across d: the whole side line supports
        f.type = Feature::Type::segment;
        f.points.push_back(s.x - g.half_length * u + g.radius * d);
        f.points.push_back(s.x + g.half_length * u + g.radius * d);
        f.ids.push_back(0);
        f.ids.push_back(1);
        return f;
      }
      point(s.x + (a > 0 ? g.half_length : -g.half_length) * u + g.radius * d, a > 0 ? 1 : 0);
      return f;
    }
    case ShapeKind::cylinder: {
      const Vec3 u = s.axis();
      const double a = u.dot(d);
      const double sign = a >= 0 ? 1.0 : -1.0;
      const Vec3 cap = s.x + sign * g.half_length * u;
      const std::uint32_t cap_id = a >= 0 ? 16u : 0u;
      Vec3 w = d - a * u;
      const double wn = w.norm();
      w = wn > 1e-12 ? Vec3(w / wn) : Vec3(s.R.col(0));
      if (std::abs(a) >= tol.cos_angle) {  // a cap faces d: its rim as a polygon, deepest point first
        f.type = Feature::Type::polygon;
        f.normal = sign * u;
        f.id = 1 + cap_id;
        const Vec3 w2 = f.normal.cross(w);  // counter-clockwise seen from outside
        for (int k = 0; k < kRimPoints; ++k) {
          const double t = 2.0 * std::numbers::pi * k / kRimPoints;
          f.points.push_back(cap + g.radius * (std::cos(t) * w + std::sin(t) * w2));
          f.ids.push_back(cap_id + static_cast<std::uint32_t>(k));
        }
        return f;
      }
      if (std::abs(a) <= tol.sin_angle) {  // lying across d: a side line supports
        f.type = Feature::Type::segment;
        f.points.push_back(s.x - g.half_length * u + g.radius * w);
        f.points.push_back(s.x + g.half_length * u + g.radius * w);
        f.ids.push_back(32);
        f.ids.push_back(33);
        f.id = 32;
        return f;
      }
      point(cap + g.radius * w, cap_id);
      return f;
    }
    case ShapeKind::box: return box_feature(s, d, tol);
    case ShapeKind::convex:
    case ShapeKind::triangles: {
      const std::vector<Vec3>& v = g.mesh->vertices;
      return polytope_feature(s, d, v.size(), [&v](std::size_t i) { return v[i]; }, tol);
    }
    case ShapeKind::plane: break;
  }
  assert(false && "supporting_feature() of a plane");
  return f;
}

// A convex hull with at most this many distinct face normals offers all of them as candidate axes.
constexpr std::size_t kAllFaceNormals = 24;  // two such hulls and the hint fit the 64 candidates

void candidate_axes(const Placed& s, const Vec3& hint, const Vec3& other_center, SmallVec<Vec3, 64>& out) {
  const auto radial = [&] {
    const Vec3 u = s.axis(), d = other_center - s.x;
    const Vec3 w = d - d.dot(u) * u;
    if (w.norm() > 1e-9 * s.size()) out.push_back(w.normalized());
  };
  switch (s.kind()) {
    case ShapeKind::box:
      for (int i = 0; i < 3; ++i) out.push_back(s.R.col(i));
      break;
    case ShapeKind::capsule: radial(); break;
    case ShapeKind::cylinder:
      out.push_back(s.axis());
      radial();
      break;
    case ShapeKind::convex: {
      // Only faces nearly facing the contact can be the separating axis the narrowphase missed. A hull
      // with few faces gives them all: the hint can be far off (FCL's EPA on a thin hull touched
      // exactly: a ball resting on a 1 cm plate got a normal 84° from the face).
      const bool all = s.geometry->mesh->face_normals.size() <= kAllFaceNormals;
      for (const Vec3& n : s.geometry->mesh->face_normals) {
        const Vec3 w = s.R * n;
        if ((all || std::abs(w.dot(hint)) >= 0.9) && !out.push_back(w)) break;
      }
      break;
    }
    default: break;
  }
}

}  // namespace impetus::collision
