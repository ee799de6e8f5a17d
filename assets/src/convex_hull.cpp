// 3D quickhull: start from a tetrahedron of extreme points, then repeatedly take the point farthest
// outside some face, remove every face it sees, and close the hole with faces from the horizon to it.
// Points within a small tolerance of a face count as on it, which keeps coplanar and nearly
// coplanar points (box faces, cylinder caps) from creating slivers.

#include "impetus/assets/convex_hull.hpp"

#include "impetus/assets/mesh_validation.hpp"
#include "impetus/core/error.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>

namespace impetus::assets {
namespace {

struct HullFace {
  std::array<std::uint32_t, 3> v;
  Vec3 normal;    // unit, outward
  double offset;  // normal · p = offset on the face's plane
  std::vector<std::uint32_t> outside;  // points in front of this face (farthest first after assignment)
  bool alive = true;
};

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) { return (std::uint64_t{a} << 32) | b; }

class Quickhull {
 public:
  explicit Quickhull(const std::vector<Vec3>& points) : points_(points) {
    Vec3 lo = points.front(), hi = lo;
    for (const Vec3& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    // Work relative to the box center: distances to planes then lose nothing to a far-away origin.
    const Vec3 center = 0.5 * (lo + hi);
    for (Vec3& p : points_) p -= center;
    tolerance_ = 1e-11 * (hi - lo).norm();
  }

  TriangleMesh run(const std::vector<Vec3>& original) {
    initial_tetrahedron();
    while (!pending_.empty()) {
      const std::uint32_t f = pending_.back();
      pending_.pop_back();
      if (!faces_[f].alive || faces_[f].outside.empty()) continue;
      add_point(f);
    }
    return extract(original);
  }

 private:
  double distance(const HullFace& f, std::uint32_t p) const { return f.normal.dot(points_[p]) - f.offset; }

  std::uint32_t make_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    HullFace f;
    f.v = {a, b, c};
    const Vec3 n = (points_[b] - points_[a]).cross(points_[c] - points_[a]);
    const double length = n.norm();
    f.normal = length > 0.0 ? Vec3(n / length) : Vec3::Zero();
    f.offset = f.normal.dot(points_[a]);
    const auto index = static_cast<std::uint32_t>(faces_.size());
    for (int e = 0; e < 3; ++e) edges_[edge_key(f.v[e], f.v[(e + 1) % 3])] = index;
    faces_.push_back(std::move(f));
    return index;
  }

  // Gives each point to the first face in `faces` it lies in front of; points in front of none are
  // inside (or on) the hull and are dropped for good. The farthest point goes first in each list.
  void assign(const std::vector<std::uint32_t>& candidates, const std::vector<std::uint32_t>& faces) {
    for (std::uint32_t p : candidates)
      for (std::uint32_t f : faces) {
        HullFace& face = faces_[f];
        const double d = distance(face, p);
        if (d <= tolerance_) continue;
        face.outside.push_back(p);
        if (d > distance(face, face.outside.front())) std::swap(face.outside.front(), face.outside.back());
        break;
      }
    for (std::uint32_t f : faces)
      if (!faces_[f].outside.empty()) pending_.push_back(f);
  }

  void initial_tetrahedron() {
    const auto n = static_cast<std::uint32_t>(points_.size());
    // The two extreme points (along x, y or z) farthest apart.
    std::array<std::uint32_t, 6> extreme{};
    for (std::uint32_t i = 0; i < n; ++i)
      for (int axis = 0; axis < 3; ++axis) {
        if (points_[i][axis] < points_[extreme[2 * axis]][axis]) extreme[2 * axis] = i;
        if (points_[i][axis] > points_[extreme[2 * axis + 1]][axis]) extreme[2 * axis + 1] = i;
      }
    std::uint32_t a = 0, b = 0;
    for (std::uint32_t i : extreme)
      for (std::uint32_t j : extreme)
        if ((points_[i] - points_[j]).squaredNorm() > (points_[a] - points_[b]).squaredNorm()) a = i, b = j;
    // The point farthest from the line ab, then the one farthest from the plane abc.
    const Vec3 ab = points_[b] - points_[a];
    std::uint32_t c = a;
    double best = 0.0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const double d = ab.cross(points_[i] - points_[a]).norm() / std::max(ab.norm(), 1e-300);
      if (d > best) best = d, c = i;
    }
    if (best <= tolerance_) throw Error("the points are all on one line: they span no volume");
    const Vec3 normal = ab.cross(points_[c] - points_[a]).normalized();
    std::uint32_t d = a;
    best = 0.0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const double h = std::abs(normal.dot(points_[i] - points_[a]));
      if (h > best) best = h, d = i;
    }
    if (best <= tolerance_) throw Error("the points are all in one plane: they span no volume");
    if (normal.dot(points_[d] - points_[a]) > 0.0) std::swap(b, c);  // abc must face away from d
    const std::vector<std::uint32_t> faces = {make_face(a, b, c), make_face(a, d, b), make_face(b, d, c),
                                              make_face(c, d, a)};
    std::vector<std::uint32_t> rest;
    for (std::uint32_t i = 0; i < n; ++i)
      if (i != a && i != b && i != c && i != d) rest.push_back(i);
    assign(rest, faces);
  }

  // Adds the farthest point outside face `seed`: the faces it sees (found by walking from `seed`
  // across edges, so they form one connected cap) are replaced by a cone from their horizon to it.
  void add_point(std::uint32_t seed) {
    const std::uint32_t eye = faces_[seed].outside.front();
    std::vector<std::uint32_t> visible = {seed};
    faces_[seed].alive = false;  // "alive = false" marks visited-and-visible during the walk
    std::vector<std::pair<std::uint32_t, std::uint32_t>> horizon;
    for (std::size_t k = 0; k < visible.size(); ++k) {
      const HullFace& f = faces_[visible[k]];
      for (int e = 0; e < 3; ++e) {
        const std::uint32_t from = f.v[e], to = f.v[(e + 1) % 3];
        const std::uint32_t other = edges_.at(edge_key(to, from));
        if (!faces_[other].alive) continue;  // already in the cap
        if (distance(faces_[other], eye) > tolerance_) {
          faces_[other].alive = false;
          visible.push_back(other);
        } else {
          horizon.emplace_back(from, to);
        }
      }
    }
    std::vector<std::uint32_t> orphans;
    for (std::uint32_t f : visible) {
      HullFace& face = faces_[f];
      for (int e = 0; e < 3; ++e) edges_.erase(edge_key(face.v[e], face.v[(e + 1) % 3]));
      for (std::uint32_t p : face.outside)
        if (p != eye) orphans.push_back(p);
      face.outside.clear();
      face.outside.shrink_to_fit();
    }
    std::vector<std::uint32_t> cone;
    cone.reserve(horizon.size());
    for (const auto& [from, to] : horizon) cone.push_back(make_face(from, to, eye));
    assign(orphans, cone);
  }

  TriangleMesh extract(const std::vector<Vec3>& original) const {
    TriangleMesh hull;
    std::unordered_map<std::uint32_t, std::uint32_t> renumber;
    for (const HullFace& f : faces_) {
      if (!f.alive) continue;
      std::array<std::uint32_t, 3> t{};
      for (int k = 0; k < 3; ++k) {
        const auto [it, inserted] = renumber.emplace(f.v[k], static_cast<std::uint32_t>(hull.vertices.size()));
        if (inserted) hull.vertices.push_back(original[f.v[k]]);
        t[k] = it->second;
      }
      hull.triangles.push_back(t);
    }
    return hull;
  }

  std::vector<Vec3> points_;
  double tolerance_ = 0.0;
  std::vector<HullFace> faces_;
  std::unordered_map<std::uint64_t, std::uint32_t> edges_;  // directed edge → the face that has it
  std::vector<std::uint32_t> pending_;  // faces that may have points outside
};

}  // namespace

TriangleMesh convex_hull(const std::vector<Vec3>& points) {
  if (points.size() < 4) throw Error("fewer than four points: they span no volume");
  for (const Vec3& p : points)
    if (!p.allFinite()) throw Error("a point is not finite");
  TriangleMesh hull = Quickhull(points).run(points);
  // The construction must give a closed, outward surface (every directed edge met once, its reverse
  // once); anything else is a bug to report, not a geometry to collide with.
  std::unordered_map<std::uint64_t, int> balance;
  for (const auto& t : hull.triangles)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[e], b = t[(e + 1) % 3];
      balance[edge_key(std::min(a, b), std::max(a, b))] += a < b ? 1 : 100;
    }
  const bool closed = std::all_of(balance.begin(), balance.end(), [](const auto& e) { return e.second == 101; });
  if (!closed || !(signed_volume(hull) > 0.0))
    throw Error("the convex hull construction failed (it is not a closed, outward surface)");
  return hull;
}

bool is_convex(const TriangleMesh& mesh, const TriangleMesh& hull, double tolerance) {
  const double hull_volume = signed_volume(hull);
  return hull_volume - signed_volume(mesh) <= tolerance * hull_volume;
}

}  // namespace impetus::assets
