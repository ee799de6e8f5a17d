#include "impetus/detection/fcl/manifold.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace impetus::collision {
namespace {

constexpr std::uint32_t kClippedBit = 0x80000000u;  // marks a point made by clipping, not a vertex

Vec3 centroid(const SmallVec<Vec3, 32>& polygon) {
  Vec3 c = Vec3::Zero();
  for (const Vec3& p : polygon) c += p;
  return c / static_cast<double>(polygon.size());
}

/// Outward unit normal of side plane i of `clip` (through clip[i], containing `clip_normal`), or zero.
Vec3 side_normal(const SmallVec<Vec3, 32>& clip, std::size_t i, const Vec3& clip_normal, const Vec3& center) {
  const Vec3& a = clip[i];
  const Vec3& b = clip[(i + 1) % clip.size()];
  Vec3 s = (b - a).cross(clip_normal);
  if (s.dot(center - a) > 0.0) s = -s;  // whatever the winding, point away from the polygon
  const double len = s.norm();
  return len > 0.0 ? Vec3(s / len) : Vec3::Zero();
}

/// Clips the segment subject[0]–subject[1] against the side planes of `clip` (parametric, no duplicates).
void clip_segment(ClipPolygon& subject, const SmallVec<Vec3, 32>& clip, const Vec3& clip_normal) {
  const ClipPoint p0 = subject[0], p1 = subject[1];
  const Vec3 center = centroid(clip);
  double t0 = 0.0, t1 = 1.0;
  std::uint32_t id0 = p0.id, id1 = p1.id;
  for (std::size_t i = 0; i < clip.size(); ++i) {
    const Vec3 s = side_normal(clip, i, clip_normal, center);
    const double d0 = s.dot(p0.p - clip[i]), d1 = s.dot(p1.p - clip[i]);
    if (d0 > 0.0 && d1 > 0.0) {
      subject.clear();
      return;
    }
    const std::uint32_t cut = kClippedBit | static_cast<std::uint32_t>(i << 16);
    if (d0 > 0.0) {
      if (const double t = d0 / (d0 - d1); t > t0) t0 = t, id0 = cut | (p0.id & 0xFFFFu);
    } else if (d1 > 0.0) {
      if (const double t = d0 / (d0 - d1); t < t1) t1 = t, id1 = cut | (p1.id & 0xFFFFu);
    }
  }
  subject.clear();
  if (t0 > t1) return;
  subject.push_back({p0.p + t0 * (p1.p - p0.p), id0});
  if (t1 > t0) subject.push_back({p0.p + t1 * (p1.p - p0.p), id1});
}

/// Twice the signed area of triangle (a, b, p) seen along `axis`.
double signed_area2(const Vec3& a, const Vec3& b, const Vec3& p, const Vec3& axis) {
  return (b - a).cross(p - a).dot(axis);
}

}  // namespace

void clip_polygon(ClipPolygon& subject, const SmallVec<Vec3, 32>& clip, const Vec3& clip_normal) {
  const Vec3 center = centroid(clip);
  for (std::size_t i = 0; i < clip.size() && !subject.empty(); ++i) {
    const Vec3 s = side_normal(clip, i, clip_normal, center);
    if (s.isZero()) continue;
    ClipPolygon out;
    const std::size_t n = subject.size();
    for (std::size_t j = 0; j < n; ++j) {
      const ClipPoint& cur = subject[j];
      const ClipPoint& next = subject[(j + 1) % n];
      const double dc = s.dot(cur.p - clip[i]), dn = s.dot(next.p - clip[i]);
      if (dc <= 0.0) out.push_back(cur);
      if ((dc <= 0.0) != (dn <= 0.0)) {
        const double t = dc / (dc - dn);
        out.push_back({cur.p + t * (next.p - cur.p),
                       kClippedBit | static_cast<std::uint32_t>(i << 16) | (cur.id & 0xFFFFu)});
      }
    }
    subject = out;
  }
}

void closest_points_segments(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, Vec3& on_p,
                             Vec3& on_q) {
  // Minimize |p0 + s d1 − (q0 + t d2)|² over s, t ∈ [0, 1].
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.dot(d1), e = d2.dot(d2), f = d2.dot(r);
  constexpr double eps = 1e-300;
  auto clamp01 = [](double x) { return std::clamp(x, 0.0, 1.0); };
  double s = 0.0, t = 0.0;
  if (a <= eps && e <= eps) {
    s = t = 0.0;
  } else if (a <= eps) {
    t = clamp01(f / e);
  } else {
    const double c = d1.dot(r);
    if (e <= eps) {
      s = clamp01(-c / a);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      // Parallel segments (denom ≈ 0): any s works; 0 is as good as another, the caller handles them.
      s = denom > 1e-14 * a * e ? clamp01((b * f - c * e) / denom) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = clamp01(-c / a);
      } else if (t > 1.0) {
        t = 1.0;
        s = clamp01((b - c) / a);
      }
    }
  }
  on_p = p0 + s * d1;
  on_q = q0 + t * d2;
}

std::size_t feature_contacts(const Feature& fa, const Feature& fb, const Vec3& n, double overlap, double margin,
                             const FeatureTolerance& tol, std::vector<ManifoldPoint>& out) {
  using Type = Feature::Type;
  const std::size_t start = out.size();
  if (fa.type == Type::polygon || fb.type == Type::polygon) {
    // The reference face is the one more aligned with n; the other feature is clipped against it.
    const bool ref_is_a = fa.type == Type::polygon &&
                          (fb.type != Type::polygon || std::abs(fa.normal.dot(n)) >= std::abs(fb.normal.dot(n)));
    const Feature& ref = ref_is_a ? fa : fb;
    const Feature& inc = ref_is_a ? fb : fa;
    if (inc.type != Type::point) {
      ClipPolygon clipped;
      for (std::size_t i = 0; i < inc.points.size(); ++i) clipped.push_back({inc.points[i], inc.ids[i]});
      if (inc.type == Type::segment) clip_segment(clipped, ref.points, ref.normal);
      else clip_polygon(clipped, ref.points, ref.normal);
      const Vec3& m = ref.normal;  // outward normal of the reference body
      double height = 0.0;
      for (const Vec3& p : ref.points) height += m.dot(p);
      height /= static_cast<double>(ref.points.size());
      for (const ClipPoint& q : clipped) {
        const double depth = height - m.dot(q.p);
        if (depth < -margin) continue;
        out.push_back({q.p + 0.5 * depth * m, ref_is_a ? m : Vec3(-m), depth,
                       ref_is_a ? feature_key(ref.id, q.id) : feature_key(q.id, ref.id)});
      }
      return out.size() - start;
    }
  } else if (fa.type == Type::segment && fb.type == Type::segment) {
    const Vec3 da = fa.points[1] - fa.points[0], db = fb.points[1] - fb.points[0];
    const double la = da.norm(), lb = db.norm();
    if (la > 0.0 && lb > 0.0 && da.cross(db).norm() <= tol.sin_angle * la * lb) {
      // Parallel: the part of b's segment alongside a's, at most its two ends.
      const Vec3 u = da / la;
      const double ta0 = u.dot(fa.points[0]), tb0 = u.dot(fb.points[0]), tb1 = u.dot(fb.points[1]);
      const double lo = std::max(ta0, std::min(tb0, tb1)), hi = std::min(ta0 + la, std::max(tb0, tb1));
      if (lo > hi || tb1 == tb0) return 0;
      const std::array<double, 2> ends{lo, hi};
      for (std::size_t k = 0; k < (hi > lo ? 2u : 1u); ++k) {
        const Vec3 qa = fa.points[0] + (ends[k] - ta0) * u;
        const Vec3 qb = fb.points[0] + (ends[k] - tb0) / (tb1 - tb0) * db;
        const double depth = n.dot(qa - qb);
        if (depth >= -margin)
          out.push_back({0.5 * (qa + qb), n, depth, feature_key(fa.ids[k], fb.ids[k])});
      }
      return out.size() - start;
    }
    Vec3 pa, pb;
    closest_points_segments(fa.points[0], fa.points[1], fb.points[0], fb.points[1], pa, pb);
    out.push_back({0.5 * (pa + pb), n, overlap, feature_key(fa.id, fb.id)});
    return 1;
  }
  // A point feature on either side: one contact at that point, moved half the overlap onto the midsurface.
  Vec3 p;
  if (fa.type == Type::point && fb.type == Type::point) p = 0.5 * (fa.points[0] + fb.points[0]);
  else if (fa.type == Type::point) p = fa.points[0] - 0.5 * overlap * n;
  else p = fb.points[0] + 0.5 * overlap * n;
  out.push_back({p, n, overlap, feature_key(fa.id, fb.id)});
  return 1;
}

std::size_t merge_duplicates(std::vector<ManifoldPoint>& points, double distance) {
  std::size_t removed = 0;
  const double d2 = distance * distance;
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = i + 1; j < points.size();) {
      if ((points[i].point - points[j].point).squaredNorm() <= d2) {
        if (points[j].depth > points[i].depth) points[i] = points[j];
        points.erase(points.begin() + static_cast<std::ptrdiff_t>(j));
        ++removed;
      } else {
        ++j;
      }
    }
  }
  return removed;
}

std::size_t reduce_to_spanning(std::vector<ManifoldPoint>& points, std::size_t max_points) {
  const std::size_t n = points.size();
  if (n <= max_points || max_points == 0) return 0;
  std::array<std::size_t, 4> pick{};
  std::size_t picked = 0;
  auto best_by = [&](auto score) {
    std::size_t best = n;
    double top = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (std::find(pick.begin(), pick.begin() + static_cast<std::ptrdiff_t>(picked), i) !=
          pick.begin() + static_cast<std::ptrdiff_t>(picked))
        continue;
      if (const double s = score(points[i]); best == n || s > top) top = s, best = i;
    }
    return std::pair{best, top};
  };
  const auto deepest = best_by([](const ManifoldPoint& p) { return p.depth; }).first;
  if (max_points == 1) {
    pick[picked++] = deepest;
  } else {
    // 1: an extreme point (the farthest from the centroid); 2: the farthest from it.
    Vec3 c = Vec3::Zero();
    for (const ManifoldPoint& p : points) c += p.point;
    c /= static_cast<double>(n);
    pick[picked++] = best_by([&](const ManifoldPoint& p) { return (p.point - c).squaredNorm(); }).first;
    const Vec3 p0 = points[pick[0]].point;
    pick[picked++] = best_by([&](const ManifoldPoint& p) { return (p.point - p0).squaredNorm(); }).first;
    const Vec3 p1 = points[pick[1]].point;
    // 3: the largest triangle with those two; none if every point is collinear with them (a third
    // point would only make the contact set overdetermined).
    if (max_points >= 3) {
      const auto [i, area] = best_by([&](const ManifoldPoint& p) { return (p1 - p0).cross(p.point - p0).norm(); });
      if (area > 1e-9 * (p1 - p0).squaredNorm()) pick[picked++] = i;
    }
    // 4: the point adding the most area outside the triangle.
    if (max_points >= 4 && picked == 3) {
      const Vec3 p2 = points[pick[2]].point;
      const Vec3 axis = (p1 - p0).cross(p2 - p0);
      const auto [i, added] = best_by([&](const ManifoldPoint& p) {
        return std::max({0.0, -signed_area2(p0, p1, p.point, axis), -signed_area2(p1, p2, p.point, axis),
                         -signed_area2(p2, p0, p.point, axis)});
      });
      if (added > 1e-9 * axis.squaredNorm()) pick[picked++] = i;
    }
    // The deepest point is kept too: it replaces the nearest chosen point if it is clearly deeper.
    const double extent = std::sqrt((points[pick[1]].point - p0).squaredNorm());
    if (std::find(pick.begin(), pick.begin() + static_cast<std::ptrdiff_t>(picked), deepest) ==
        pick.begin() + static_cast<std::ptrdiff_t>(picked)) {
      std::size_t nearest = 0;
      for (std::size_t k = 1; k < picked; ++k)
        if ((points[pick[k]].point - points[deepest].point).squaredNorm() <
            (points[pick[nearest]].point - points[deepest].point).squaredNorm())
          nearest = k;
      if (points[deepest].depth > points[pick[nearest]].depth + 1e-6 * extent) pick[nearest] = deepest;
    }
  }
  for (std::size_t i = 1; i < picked; ++i)  // insertion sort of ≤ 4 indices (keeps the kept points' order)
    for (std::size_t j = i; j > 0 && pick[j - 1] > pick[j]; --j) std::swap(pick[j - 1], pick[j]);
  for (std::size_t k = 0; k < picked; ++k) points[k] = points[pick[k]];  // pick[k] ≥ k: in place
  points.resize(picked);
  return n - picked;
}

}  // namespace impetus::collision
