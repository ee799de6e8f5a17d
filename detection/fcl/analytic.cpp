#include "impetus/detection/fcl/analytic.hpp"

#include <algorithm>
#include <cmath>

namespace impetus::collision {
namespace {

/// The core of a sphere (a point) or capsule (its segment) in the world frame.
void core_segment(const Placed& s, Vec3& p0, Vec3& p1) {
  const Vec3 half = s.geometry->half_length * s.axis();  // zero for a sphere
  p0 = s.x - half;
  p1 = s.x + half;
}

/// A unit vector for a degenerate normal: along the centers if they differ, else perpendicular to a's
/// axis (deep penetration of coinciding cores has no preferred direction).
Vec3 fallback_normal(const Placed& a, const Placed& b) {
  const Vec3 d = b.x - a.x;
  if (d.norm() > 1e-12 * (a.size() + b.size())) return d.normalized();
  return a.R.col(0);
}

Vec3 centroid(const Feature& f) {
  Vec3 c = Vec3::Zero();
  for (const Vec3& p : f.points) c += p;
  return c / static_cast<double>(f.points.size());
}

}  // namespace

double overlap_along(const Placed& a, const Placed& b, const Vec3& n) {
  return support_height(a, n) + support_height(b, -n);
}

AxisResult least_overlap_axis(const Placed& a, const Placed& b, std::span<const Vec3> candidates, double tie,
                              std::span<const Vec3> half_spaces) {
  AxisResult best;
  for (const Vec3& c : candidates) {
    if (!c.allFinite() || std::abs(c.squaredNorm() - 1.0) > 1e-6) continue;
    for (const Vec3& n : {Vec3(c), Vec3(-c)}) {
      if (std::any_of(half_spaces.begin(), half_spaces.end(), [&](const Vec3& h) { return n.dot(h) < -1e-9; }))
        continue;
      const double ov = overlap_along(a, b, n);
      if (!best.valid || ov < best.overlap - tie) best = {n, ov, true};
    }
  }
  return best;
}

AxisResult box_box_axis(const Placed& a, const Placed& b) {
  const Vec3& ha = a.geometry->half_extents;
  const Vec3& hb = b.geometry->half_extents;
  const Vec3 t = b.x - a.x;
  // Boxes are centrally symmetric, so the overlap along L is r_a + r_b − |L·t| and the orientation is
  // the sign of L·t.
  auto test = [&](const Vec3& axis) {
    double ra = 0.0, rb = 0.0;
    for (int i = 0; i < 3; ++i) {
      ra += ha[i] * std::abs(axis.dot(a.R.col(i)));
      rb += hb[i] * std::abs(axis.dot(b.R.col(i)));
    }
    const double along = axis.dot(t);
    return AxisResult{along >= 0.0 ? axis : Vec3(-axis), ra + rb - std::abs(along), true};
  };
  AxisResult face, edge;
  for (const Placed* s : {&a, &b})
    for (int i = 0; i < 3; ++i)
      if (const AxisResult r = test(s->R.col(i)); !face.valid || r.overlap < face.overlap) face = r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      Vec3 axis = a.R.col(i).cross(b.R.col(j));
      const double len = axis.norm();
      if (len < 1e-6) continue;  // parallel edges: their axis is a face axis already tested
      if (const AxisResult r = test(axis / len); !edge.valid || r.overlap < edge.overlap) edge = r;
    }
  }
  // Prefer faces: an edge axis must overlap clearly less (stable manifolds for resting boxes).
  const double bias = 1e-5 * (a.size() + b.size());
  return edge.valid && edge.overlap < face.overlap - bias ? edge : face;
}

AxisResult capsule_box_axis(const Placed& a, const Placed& b) {
  const bool capsule_is_a = a.kind() == ShapeKind::capsule;
  const Placed& capsule = capsule_is_a ? a : b;
  const Placed& box = capsule_is_a ? b : a;
  const Vec3& h = box.geometry->half_extents;
  // The capsule's core segment p(t) = p0 + t·(p1 − p0), t ∈ [0, 1], in the box frame.
  Vec3 w0, w1;
  core_segment(capsule, w0, w1);
  const Vec3 p0 = box.R.transpose() * (w0 - box.x), d = box.R.transpose() * (w1 - w0);
  // Its squared distance to the box, |p(t) − clamp(p(t))|², is convex in t: golden-section search, a
  // fixed number of steps (deterministic), to the width of rounding in t.
  const auto gap = [&](double t) {
    const Vec3 p = p0 + t * d;
    return (p - p.cwiseMax(-h).cwiseMin(h)).squaredNorm();
  };
  constexpr double kInv = 0.6180339887498949;  // (√5 − 1)/2
  double lo = 0.0, hi = 1.0, t1 = hi - kInv, t2 = lo + kInv, g1 = gap(t1), g2 = gap(t2);
  for (int i = 0; i < 80; ++i) {
    if (g1 <= g2) {
      hi = t2, t2 = t1, g2 = g1, t1 = hi - kInv * (hi - lo), g1 = gap(t1);
    } else {
      lo = t1, t1 = t2, g1 = g2, t2 = lo + kInv * (hi - lo), g2 = gap(t2);
    }
  }
  double t = 0.5 * (lo + hi);
  for (double end : {0.0, 1.0})  // a minimum at an end is where the search ends nearest, not exactly on it
    if (gap(end) <= gap(t)) t = end;
  const Vec3 p = p0 + t * d, q = p.cwiseMax(-h).cwiseMin(h);
  // Candidates, in the box frame: its face normals; the segment direction crossed with each (the edge
  // axes of the Minkowski difference of segment and box); the direction between the closest points. The
  // least overlap over directions is the penetration depth, or minus the distance, and one of these
  // attains it: the closest-point direction when the core is outside the box, the face and edge axes of
  // the (polyhedral) difference when the core cuts into it. Faces first, so that they win ties.
  SmallVec<Vec3, 8> candidates;
  for (int i = 0; i < 3; ++i) candidates.push_back(box.R.col(i));
  const double scale = a.size() + b.size();
  if ((p - q).norm() > 1e-9 * scale) candidates.push_back(box.R * (p - q).normalized());
  for (int i = 0; i < 3; ++i) {
    const Vec3 axis = d.cross(Vec3::Unit(i));
    if (axis.norm() > 1e-6 * d.norm()) candidates.push_back(box.R * axis.normalized());
  }
  return least_overlap_axis(a, b, {candidates.begin(), candidates.end()}, 1e-12 * scale);
}

void rounded_contacts(const Placed& a, const Placed& b, const PairSettings& s, std::vector<ManifoldPoint>& out) {
  Vec3 a0, a1, b0, b1, pa, pb;
  core_segment(a, a0, a1);
  core_segment(b, b0, b1);
  closest_points_segments(a0, a1, b0, b1, pa, pb);
  const double ra = a.geometry->radius, rb = b.geometry->radius;
  const Vec3 v = pb - pa;
  const double dist = v.norm();
  const double depth = ra + rb - dist;
  if (depth < -s.margin) return;
  const Vec3 n = dist > 1e-12 * (a.size() + b.size()) ? Vec3(v / dist) : fallback_normal(a, b);
  if (a.kind() == ShapeKind::capsule && b.kind() == ShapeKind::capsule) {
    // Side by side: both supporting features are segments and the manifold is their common part.
    const Feature fa = supporting_feature(a, n, s.tol), fb = supporting_feature(b, -n, s.tol);
    if (fa.type == Feature::Type::segment && fb.type == Feature::Type::segment &&
        feature_contacts(fa, fb, n, depth, s.margin, s.tol, out) > 0)
      return;
  }
  out.push_back({0.5 * ((pa + ra * n) + (pb - rb * n)), n, depth, 0});
}

void sphere_box_contacts(const Placed& a, const Placed& b, const PairSettings& s, std::vector<ManifoldPoint>& out) {
  const bool sphere_is_a = a.kind() == ShapeKind::sphere;
  const Placed& sphere = sphere_is_a ? a : b;
  const Placed& box = sphere_is_a ? b : a;
  const Vec3& h = box.geometry->half_extents;
  const double r = sphere.geometry->radius;
  const Vec3 c = box.R.transpose() * (sphere.x - box.x);  // sphere center in the box frame
  const Vec3 q = c.cwiseMax(-h).cwiseMin(h);
  Vec3 n_local, surface = q;
  double depth;
  if (q == c) {  // center inside: leave through the nearest face
    int k = 0;
    for (int i = 1; i < 3; ++i)
      if (h[i] - std::abs(c[i]) < h[k] - std::abs(c[k])) k = i;
    const double sign = c[k] >= 0.0 ? 1.0 : -1.0;
    n_local = sign * Vec3::Unit(k);
    surface[k] = sign * h[k];
    depth = r + (h[k] - std::abs(c[k]));
  } else {
    const Vec3 v = c - q;
    const double dist = v.norm();
    n_local = v / dist;
    depth = r - dist;
  }
  if (depth < -s.margin) return;
  const Vec3 n_out = box.R * n_local;  // out of the box, towards the sphere
  const Vec3 on_box = box.x + box.R * surface;
  const Vec3 on_sphere = sphere.x - r * n_out;
  out.push_back({0.5 * (on_box + on_sphere), sphere_is_a ? Vec3(-n_out) : n_out, depth, 0});
}

void halfspace_contacts(const Placed& a, const Placed& b, const PairSettings& s, std::vector<ManifoldPoint>& out) {
  const bool plane_is_a = a.kind() == ShapeKind::plane;
  const Placed& other = plane_is_a ? b : a;
  const WorldPlane plane = world_plane(plane_is_a ? a : b);
  const Vec3& m = plane.normal;
  const Vec3 n = plane_is_a ? m : Vec3(-m);
  // A point q of the other body is below the plane surface by depth = offset − m·q.
  auto add = [&](const Vec3& q, std::uint32_t id) {
    const double depth = plane.offset - m.dot(q);
    if (depth >= -s.margin)
      out.push_back({q + 0.5 * depth * m, n, depth, plane_is_a ? feature_key(0, id) : feature_key(id, 0)});
  };
  const ShapeGeometry& g = *other.geometry;
  switch (g.kind) {
    case ShapeKind::sphere: add(other.x - g.radius * m, 0); break;
    case ShapeKind::capsule:
      add(other.x - g.half_length * other.axis() - g.radius * m, 0);
      add(other.x + g.half_length * other.axis() - g.radius * m, 1);
      break;
    case ShapeKind::box:
      for (int i = 0; i < 8; ++i) add(other.x + other.R * box_corner(g.half_extents, i), static_cast<std::uint32_t>(i));
      break;
    case ShapeKind::cylinder: {
      const Feature f = supporting_feature(other, -m, s.tol);
      for (std::size_t i = 0; i < f.points.size(); ++i) add(f.points[i], f.ids[i]);
      break;
    }
    case ShapeKind::convex:
    case ShapeKind::triangles: {
      const std::vector<Vec3>& v = g.mesh->vertices;
      for (std::size_t i = 0; i < v.size(); ++i) add(other.x + other.R * v[i], static_cast<std::uint32_t>(i));
      break;
    }
    case ShapeKind::plane: break;  // two planes are both fixed: never a pair
  }
}

void convex_contacts(const Placed& a, const Placed& b, const AxisResult& axis, const PairSettings& s,
                     std::vector<ManifoldPoint>& out, bool fallback) {
  const Vec3& n = axis.normal;
  const Feature fa = supporting_feature(a, n, s.tol);
  const Feature fb = supporting_feature(b, -n, s.tol);
  if (feature_contacts(fa, fb, n, axis.overlap, s.margin, s.tol, out) > 0 || !fallback) return;
  // The features do not face each other within the margin (e.g. a gap across a corner): one point
  // between them, at the depth the separating axis gives.
  out.push_back({0.5 * (centroid(fa) + centroid(fb)), n, axis.overlap, feature_key(fa.id, fb.id)});
}

}  // namespace impetus::collision
