// Mesh validation: the checks of mesh_validation.hpp, each failing with a count, the defect and one
// example located by coordinates (vertex numbers after welding mean nothing to the user).

#include "impetus/assets/mesh_validation.hpp"

#include "impetus/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <unordered_map>

namespace impetus::assets {
namespace {

std::string point(const Vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.6g, %.6g, %.6g)", p.x(), p.y(), p.z());
  return text;
}

std::string count(std::size_t n, const char* singular, const char* plural) {
  return std::to_string(n) + " " + (n == 1 ? singular : plural);
}

ValidationResult failure(MeshDefect defect, std::string message) {
  ValidationResult r;
  r.defect = defect;
  r.message = std::move(message);
  return r;
}

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
}

// How the triangles use one undirected edge {lo, hi}.
struct EdgeUse {
  int forward = 0;   // triangles that run it lo → hi
  int backward = 0;  // triangles that run it hi → lo
  std::uint32_t first_triangle = 0;
};

// Union-find over triangles, joined across shared edges: the connected shells.
std::vector<std::uint32_t> shells_of(const TriangleMesh& mesh, const std::unordered_map<std::uint64_t, EdgeUse>& edges,
                                     std::size_t& shell_count) {
  std::vector<std::uint32_t> parent(mesh.triangles.size());
  std::iota(parent.begin(), parent.end(), 0u);
  const auto root = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (std::uint32_t k = 0; k < mesh.triangles.size(); ++k)
    for (int e = 0; e < 3; ++e) {
      const auto& t = mesh.triangles[k];
      const std::uint32_t other = edges.at(edge_key(t[e], t[(e + 1) % 3])).first_triangle;
      parent[root(k)] = root(other);
    }
  std::unordered_map<std::uint32_t, std::uint32_t> number;
  std::vector<std::uint32_t> shell(mesh.triangles.size());
  for (std::uint32_t k = 0; k < shell.size(); ++k)
    shell[k] = number.emplace(root(k), static_cast<std::uint32_t>(number.size())).first->second;
  shell_count = number.size();
  return shell;
}

// Signed volume of the triangles k with keep(k), about `origin`: Σ a·(b×c)/6 (divergence theorem).
template <class Keep>
double volume_of(const TriangleMesh& mesh, const Vec3& origin, Keep keep) {
  double six_v = 0.0;
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    if (!keep(k)) continue;
    const auto& t = mesh.triangles[k];
    six_v += (mesh.vertices[t[0]] - origin).dot((mesh.vertices[t[1]] - origin).cross(mesh.vertices[t[2]] - origin));
  }
  return six_v / 6.0;
}

// Winding number of the triangles of `shell` around `q`: Σ solid angles / 4π (Van Oosterom and
// Strackee's formula for a triangle's solid angle). ±1 inside a closed shell, 0 outside.
double winding_number(const TriangleMesh& mesh, const std::vector<std::uint32_t>& shell_of, std::uint32_t shell,
                      const Vec3& q) {
  double sum = 0.0;
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    if (shell_of[k] != shell) continue;
    const auto& t = mesh.triangles[k];
    const Vec3 a = mesh.vertices[t[0]] - q, b = mesh.vertices[t[1]] - q, c = mesh.vertices[t[2]] - q;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    sum += 2.0 * std::atan2(numerator, denominator);
  }
  return sum / (4.0 * std::numbers::pi);
}

struct Shell {
  double volume = 0.0;
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  std::vector<Vec3> probes;  // a few of its vertices, for containment tests
  int depth = 0;             // how many other shells contain it
};

// Orientation of several shells: a shell inside an odd number of others is a cavity and must be
// wound inward; one inside an even number (usually none) is solid and must be wound outward.
ValidationResult orient_shells(TriangleMesh& mesh, const std::unordered_map<std::uint64_t, EdgeUse>& edges,
                               double size) {
  ValidationResult result;
  std::size_t n = 0;
  const std::vector<std::uint32_t> shell_of = shells_of(mesh, edges, n);
  Vec3 lo = mesh.vertices.front(), hi = lo;
  for (const Vec3& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const Vec3 origin = 0.5 * (lo + hi);
  std::vector<Shell> shells(n);
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k)
    for (std::uint32_t i : mesh.triangles[k]) {
      Shell& s = shells[shell_of[k]];
      s.lo = s.lo.cwiseMin(mesh.vertices[i]), s.hi = s.hi.cwiseMax(mesh.vertices[i]);
      if (s.probes.size() < 3 && std::find(s.probes.begin(), s.probes.end(), mesh.vertices[i]) == s.probes.end())
        s.probes.push_back(mesh.vertices[i]);
    }
  double total = 0.0;
  for (std::uint32_t s = 0; s < n; ++s)
    total += shells[s].volume = volume_of(mesh, origin, [&](std::size_t k) { return shell_of[k] == s; });
  const double zero = 1e-10 * size * size * size;
  for (std::uint32_t s = 0; s < n; ++s)
    if (std::abs(shells[s].volume) <= zero)
      return failure(MeshDefect::zero_volume,
                     (n == 1 ? std::string("the mesh") : "a shell of the mesh (near " + point(shells[s].probes[0]) + ")") +
                         " encloses no volume: it is flat or its faces cancel");
  // Wholly inside out (the common case of a wrong winding convention): flip everything first.
  const bool inverted = total < 0.0;
  if (inverted) {
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
    for (Shell& s : shells) s.volume = -s.volume;
    result.flipped_shells = n;
    result.warnings.push_back(
        "the mesh is wound inward (its triangles run clockwise seen from outside); flipped it");
  }
  if (n == 1) return result;
  // Containment by winding number at a probe vertex; a probe on the other shell's surface gives
  // about ½, so the first probe that is clearly inside or outside decides.
  for (std::uint32_t s = 0; s < n; ++s)
    for (std::uint32_t t = 0; t < n; ++t) {
      if (s == t) continue;
      const Shell& outer = shells[t];
      for (const Vec3& probe : shells[s].probes) {
        if ((probe.array() < outer.lo.array()).any() || (probe.array() > outer.hi.array()).any()) break;
        const double w = std::abs(winding_number(mesh, shell_of, t, probe));
        if (std::abs(w - 0.5) < 0.25) continue;
        if (w > 0.5) ++shells[s].depth;
        break;
      }
    }
  for (std::uint32_t s = 0; s < n; ++s) {
    const bool should_be_solid = shells[s].depth % 2 == 0;
    if (should_be_solid == (shells[s].volume > 0.0)) continue;
    if (!should_be_solid)
      return failure(MeshDefect::overlapping_shells,
                     "two closed shells are wound outward and one lies inside the other (near " +
                         point(shells[s].probes[0]) +
                         "): their common volume would count twice (wind the inner one inward if it is a cavity)");
    for (std::size_t k = 0; k < mesh.triangles.size(); ++k)
      if (shell_of[k] == s) std::swap(mesh.triangles[k][1], mesh.triangles[k][2]);
    ++result.flipped_shells;
    result.warnings.push_back("a shell of the mesh (near " + point(shells[s].probes[0]) +
                              ") is wound inward; flipped it");
  }
  return result;
}

}  // namespace

ValidationResult validate_mesh(TriangleMesh& mesh) {
  const std::size_t nv = mesh.vertices.size();
  if (mesh.triangles.empty()) return failure(MeshDefect::empty, "the mesh has no triangles");
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k)
    for (std::uint32_t i : mesh.triangles[k])
      if (i >= nv)
        return failure(MeshDefect::bad_index, "triangle " + std::to_string(k) + " refers to vertex " +
                                                  std::to_string(i) + ", but there are " +
                                                  count(nv, "vertex", "vertices"));
  // No count: importers copy a vertex once per corner, so a count would not be the file's.
  for (const Vec3& v : mesh.vertices)
    if (!v.allFinite())
      return failure(MeshDefect::not_finite, "a vertex is not a finite point (NaN or infinite): " + point(v));

  Vec3 lo = mesh.vertices.front(), hi = lo;
  for (const Vec3& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double size = (hi - lo).norm();
  std::size_t degenerate = 0;
  std::string first_degenerate;
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const bool repeated = t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
    if (!repeated && (b - a).cross(c - a).norm() > kDegenerateArea * size * size) continue;
    if (degenerate++ == 0) first_degenerate = point(a) + ", " + point(b) + ", " + point(c);
  }
  if (degenerate)
    return failure(MeshDefect::degenerate, count(degenerate, "degenerate triangle", "degenerate triangles") +
                                               " (zero area): the first has corners " + first_degenerate);

  std::unordered_map<std::uint64_t, EdgeUse> edges;
  edges.reserve(3 * mesh.triangles.size() / 2 + 1);
  for (std::uint32_t k = 0; k < mesh.triangles.size(); ++k)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = mesh.triangles[k][e], b = mesh.triangles[k][(e + 1) % 3];
      EdgeUse& use = edges[edge_key(a, b)];
      if (use.forward + use.backward == 0) use.first_triangle = k;
      ++(a < b ? use.forward : use.backward);
    }
  std::size_t boundary = 0, crowded = 0, same_way = 0;
  std::uint64_t boundary_example = 0, crowded_example = 0, same_way_example = 0;
  int crowded_count = 0;
  for (const auto& [key, use] : edges) {
    const int uses = use.forward + use.backward;
    if (uses == 1 && boundary++ == 0) boundary_example = key;
    if (uses > 2 && crowded++ == 0) crowded_example = key, crowded_count = uses;
    if (uses == 2 && use.forward != 1 && same_way++ == 0) same_way_example = key;
  }
  const auto edge_text = [&](std::uint64_t key) {
    return "from " + point(mesh.vertices[key >> 32]) + " to " + point(mesh.vertices[key & 0xFFFFFFFFu]);
  };
  if (boundary)
    return failure(MeshDefect::not_closed, count(boundary, "boundary edge", "boundary edges") +
                                               ": the mesh is not closed (one runs " + edge_text(boundary_example) +
                                               ")");
  if (crowded)
    return failure(MeshDefect::non_manifold,
                   count(crowded, "edge is", "edges are") + " shared by more than two triangles: the mesh is not " +
                       "manifold (the one " + edge_text(crowded_example) + " has " + std::to_string(crowded_count) +
                       ")");
  if (same_way)
    return failure(MeshDefect::inconsistent,
                   count(same_way, "edge is", "edges are") + " run the same way by both triangles that share it: the mesh " +
                       "is not consistently oriented (the one " + edge_text(same_way_example) + ")");
  return orient_shells(mesh, edges, size);
}

void require_valid_mesh(TriangleMesh& mesh, const std::string& label, std::vector<std::string>& warnings) {
  const ValidationResult result = validate_mesh(mesh);
  if (!result.ok()) throw Error(label + ": " + result.message);
  for (const std::string& w : result.warnings) warnings.push_back(label + ": " + w);
}

double signed_volume(const TriangleMesh& mesh) {
  if (mesh.vertices.empty()) return 0.0;
  Vec3 lo = mesh.vertices.front(), hi = lo;
  for (const Vec3& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return volume_of(mesh, 0.5 * (lo + hi), [](std::size_t) { return true; });
}

}  // namespace impetus::assets
