#include "impetus/detection/fcl/mesh_contacts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus::collision {
namespace {

/// The mesh side's 32-bit feature id: the triangle index mixed with the piece's vertex/clip id.
std::uint32_t triangle_feature(std::uint32_t triangle, std::uint32_t id) { return triangle * 2654435761u ^ id; }

/// Re-keys the points appended since `first` so their mesh-side ids name the triangle.
void tag(std::vector<ManifoldPoint>& out, std::size_t first, std::uint32_t triangle, bool mesh_is_a) {
  for (std::size_t i = first; i < out.size(); ++i) {
    const auto on_a = static_cast<std::uint32_t>(out[i].feature >> 32);
    const auto on_b = static_cast<std::uint32_t>(out[i].feature);
    out[i].feature = mesh_is_a ? feature_key(triangle_feature(triangle, on_a), on_b)
                               : feature_key(on_a, triangle_feature(triangle, on_b));
  }
}

bool boxes_overlap(const Aabb& x, const Aabb& y) {
  return (x.min.array() <= y.max.array()).all() && (y.min.array() <= x.max.array()).all();
}

/// Pushes the unit direction from `from` to `to` if they are apart.
void push_direction(const Vec3& from, const Vec3& to, double eps, SmallVec<Vec3, 64>& out) {
  const Vec3 d = to - from;
  if (d.norm() > eps) out.push_back(d.normalized());
}

}  // namespace

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& t0, const Vec3& t1, const Vec3& t2) {
  // Voronoi regions of the vertices, then the edges, then the face (barycentric coordinates).
  const Vec3 e01 = t1 - t0, e02 = t2 - t0, p0 = p - t0;
  const double d1 = e01.dot(p0), d2 = e02.dot(p0);
  if (d1 <= 0.0 && d2 <= 0.0) return t0;
  const Vec3 p1 = p - t1;
  const double d3 = e01.dot(p1), d4 = e02.dot(p1);
  if (d3 >= 0.0 && d4 <= d3) return t1;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return t0 + d1 / (d1 - d3) * e01;
  const Vec3 p2 = p - t2;
  const double d5 = e01.dot(p2), d6 = e02.dot(p2);
  if (d6 >= 0.0 && d5 <= d6) return t2;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return t0 + d2 / (d2 - d6) * e02;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
    return t1 + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (t2 - t1);
  const double sum = va + vb + vc;
  return t0 + (vb / sum) * e01 + (vc / sum) * e02;
}

void closest_points_segment_triangle(const Vec3& p0, const Vec3& p1, const std::array<Vec3, 3>& tri, Vec3& on_segment,
                                     Vec3& on_triangle) {
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](const Vec3& s, const Vec3& t) {
    if (const double d = (s - t).squaredNorm(); d < best) best = d, on_segment = s, on_triangle = t;
  };
  // The closest pair has a segment end against the face, or the segment against an edge…
  for (const Vec3& e : {p0, p1}) consider(e, closest_point_on_triangle(e, tri[0], tri[1], tri[2]));
  for (int i = 0; i < 3; ++i) {
    Vec3 s, t;
    closest_points_segments(p0, p1, tri[i], tri[(i + 1) % 3], s, t);
    consider(s, t);
  }
  // …or the segment pierces the face (distance zero).
  const Vec3 n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
  const double h0 = n.dot(p0 - tri[0]), h1 = n.dot(p1 - tri[0]);
  if ((h0 <= 0.0) != (h1 <= 0.0)) {
    const Vec3 x = p0 + h0 / (h0 - h1) * (p1 - p0);
    consider(x, closest_point_on_triangle(x, tri[0], tri[1], tri[2]));
  }
}

MeshContacts::MeshContacts() {
  for (Piece* p : {&piece_a_, &piece_b_}) {
    p->geometry.kind = ShapeKind::convex;
    // Non-owning: the geometry points at its own piece's data (pieces are never copied).
    p->geometry.mesh = std::shared_ptr<const MeshData>(std::shared_ptr<const MeshData>(), &p->data);
    p->data.vertices.resize(3);
    p->placed.geometry = &p->geometry;
  }
}

void MeshContacts::Piece::set(const Placed& mesh, std::uint32_t triangle, double margin) {
  const MeshData& m = *mesh.geometry->mesh;
  const auto& t = m.triangles[triangle];
  Vec3 center = Vec3::Zero();
  for (int i = 0; i < 3; ++i) center += (world[i] = mesh.x + mesh.R * m.vertices[t[i]]);
  center /= 3.0;
  geometry.size = 0.0;
  box = {world[0], world[0]};
  for (int i = 0; i < 3; ++i) {
    data.vertices[i] = world[i] - center;
    geometry.size = std::max(geometry.size, data.vertices[i].norm());
    box.min = box.min.cwiseMin(world[i]);
    box.max = box.max.cwiseMax(world[i]);
  }
  // Triangles are flat: grow by half their size as well, so pieces that interpenetrate still overlap.
  box.min.array() -= margin + 0.5 * geometry.size;
  box.max.array() += margin + 0.5 * geometry.size;
  placed.x = center;
  placed.R = Mat3::Identity();
  normal = mesh.R * m.triangle_normals[triangle];
}

void MeshContacts::mesh_vs_convex(const Placed& mesh, const FclShape& mesh_fcl, const Placed& other,
                                  const FclShape& other_fcl, bool mesh_is_a, const PairSettings& s,
                                  std::vector<ManifoldPoint>& out, std::uint64_t& failures) {
  Aabb reach = world_aabb(other);
  reach.min.array() -= s.margin;
  reach.max.array() += s.margin;
  if (!fcl_triangles_near(mesh_fcl, mesh, reach, kMaxTriangles, near_a_)) {
    ++failures;
    return;
  }
  Piece& tri = piece_a_;
  for (std::uint32_t t : near_a_) {
    tri.set(mesh, t, s.margin);
    const Vec3& m = tri.normal;
    if (m.isZero()) continue;
    const double plane = m.dot(tri.world[0]);
    if (-support_height(other, -m) > plane + s.margin) continue;  // wholly in front, beyond the margin
    if (m.dot(other.x) < plane) continue;  // one-sided: the other body's center must be on the outer side
    const double eps = 1e-12 * (tri.geometry.size + other.size());
    SmallVec<Vec3, 64> candidates;
    candidates.push_back(m);
    candidate_axes(other, m, tri.placed.x, candidates);
    switch (other.kind()) {
      case ShapeKind::sphere:
        push_direction(closest_point_on_triangle(other.x, tri.world[0], tri.world[1], tri.world[2]), other.x, eps,
                       candidates);
        break;
      case ShapeKind::capsule: {
        const Vec3 half = other.geometry->half_length * other.axis();
        Vec3 on_core, on_tri;
        closest_points_segment_triangle(other.x - half, other.x + half, tri.world, on_core, on_tri);
        push_direction(on_tri, on_core, eps, candidates);
        break;
      }
      case ShapeKind::box:  // with the face normals above: the complete separating-axis set
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            push_direction(Vec3::Zero(), (tri.world[(i + 1) % 3] - tri.world[i]).cross(other.R.col(j)), 1e-9,
                           candidates);
        break;
      default: {  // cylinder, convex mesh: FCL's signed distance to the triangle
        const SignedDistance sd = fcl_signed_distance_triangle(tri.world, other_fcl, other);
        if (!sd.ok) ++failures;
        else if (sd.distance > 0.0) push_direction(sd.on_a, sd.on_b, eps, candidates);
        else push_direction(sd.on_b, sd.on_a, eps, candidates);
        break;
      }
    }
    const Vec3 outward[] = {m};
    const AxisResult axis = least_overlap_axis(tri.placed, other, {candidates.begin(), candidates.end()}, eps, outward);
    if (!axis.valid || axis.overlap < -s.margin) continue;
    const std::size_t first = out.size();
    if (mesh_is_a) convex_contacts(tri.placed, other, axis, s, out, false);
    else convex_contacts(other, tri.placed, AxisResult{-axis.normal, axis.overlap, true}, s, out, false);
    tag(out, first, t, mesh_is_a);
  }
}

void MeshContacts::mesh_vs_mesh(const Placed& a, const FclShape& a_fcl, const Placed& b, const FclShape& b_fcl,
                                const PairSettings& s, std::vector<ManifoldPoint>& out, std::uint64_t& failures) {
  Aabb reach_a = world_aabb(a), reach_b = world_aabb(b);
  for (Aabb* r : {&reach_a, &reach_b}) r->min.array() -= s.margin, r->max.array() += s.margin;
  if (!fcl_triangles_near(a_fcl, a, reach_b, kMaxTriangles, near_a_) ||
      !fcl_triangles_near(b_fcl, b, reach_a, kMaxTriangles, near_b_)) {
    ++failures;
    return;
  }
  Piece &ta = piece_a_, &tb = piece_b_;
  for (std::uint32_t i : near_a_) {
    ta.set(a, i, s.margin);
    // One-sided, as for a convex body: b's center must be on the outer side of a's triangle, and the
    // other way round below.
    if (ta.normal.isZero() || ta.normal.dot(b.x - ta.world[0]) < 0.0) continue;
    for (std::uint32_t j : near_b_) {
      tb.set(b, j, s.margin);
      if (tb.normal.isZero() || tb.normal.dot(a.x - tb.world[0]) < 0.0 || !boxes_overlap(ta.box, tb.box)) continue;
      // Two triangles are polytopes: both normals and the 9 edge cross products are a complete set.
      SmallVec<Vec3, 64> candidates;
      candidates.push_back(ta.normal);
      candidates.push_back(tb.normal);
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q)
          push_direction(Vec3::Zero(), (ta.world[(p + 1) % 3] - ta.world[p]).cross(tb.world[(q + 1) % 3] - tb.world[q]),
                         1e-9 * ta.geometry.size * tb.geometry.size, candidates);
      const Vec3 sides[] = {ta.normal, -tb.normal};  // leave a's triangle outwards, enter b's from outside
      const double eps = 1e-12 * (ta.geometry.size + tb.geometry.size);
      const AxisResult axis =
          least_overlap_axis(ta.placed, tb.placed, {candidates.begin(), candidates.end()}, eps, sides);
      if (!axis.valid || axis.overlap < -s.margin) continue;
      const std::size_t first = out.size();
      convex_contacts(ta.placed, tb.placed, axis, s, out, false);
      tag(out, first, i, true);
      tag(out, first, j, false);
    }
  }
}

}  // namespace impetus::collision
