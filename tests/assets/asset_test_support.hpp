#pragma once
// Helpers for the asset tests: bundled mesh paths, meshes built in memory (double precision), an
// independent reference for mass properties (signed-tetrahedron decomposition), and error capture.

#include "impetus/assets/mass_properties.hpp"
#include "impetus/core/error.hpp"
#include "impetus/core/shape.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <string>

namespace impetus::test {

/// A bundled mesh (assets/meshes/NAME).
inline std::string mesh_path(const std::string& name) {
  return std::string(IMPETUS_SOURCE_DIR) + "/assets/meshes/" + name;
}

/// Axis-aligned box from `lo` to `hi`, wound outward.
inline TriangleMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({std::uint32_t(q[0]), std::uint32_t(q[1]), std::uint32_t(q[2])});
    m.triangles.push_back({std::uint32_t(q[0]), std::uint32_t(q[2]), std::uint32_t(q[3])});
  }
  return m;
}

/// Torus around z in double precision: `ring` segments around z, a regular `tube`-gon of circumradius
/// `minor` centered at distance `major` (the generator's construction).
inline TriangleMesh torus_mesh(int ring, int tube, double major, double minor) {
  TriangleMesh m;
  for (int i = 0; i < ring; ++i)
    for (int j = 0; j < tube; ++j) {
      const double phi = 2 * std::numbers::pi * i / ring, theta = 2 * std::numbers::pi * j / tube;
      const double rho = major + minor * std::cos(theta);
      m.vertices.emplace_back(rho * std::cos(phi), rho * std::sin(phi), minor * std::sin(theta));
    }
  for (int i = 0; i < ring; ++i)
    for (int j = 0; j < tube; ++j) {
      const auto at = [&](int a, int b) { return std::uint32_t(((a % ring) * tube) + b % tube); };
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

/// `mesh` with every vertex mapped to R v + t.
inline TriangleMesh transformed(TriangleMesh mesh, const Mat3& R, const Vec3& t) {
  for (Vec3& v : mesh.vertices) v = R * v + t;
  return mesh;
}

/// Reference mass properties (density 1) by signed tetrahedra: each triangle (a, b, c) with a reference
/// point o makes the tetrahedron (o, a, b, c) of signed volume (a−o)·((b−o)×(c−o))/6, whose second
/// moments are V/20 (Σ vᵢvᵢᵀ + (Σ vᵢ)(Σ vᵢ)ᵀ) over its four vertices. Independent of Mirtich's method.
inline assets::MassProperties tetrahedra_reference(const TriangleMesh& mesh, const Vec3& o) {
  double volume = 0.0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();  // ∫ p pᵀ dV, p relative to o
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]] - o, b = mesh.vertices[t[1]] - o, c = mesh.vertices[t[2]] - o;
    const double v = a.dot(b.cross(c)) / 6.0;
    const Vec3 sum = a + b + c;  // the fourth vertex is 0
    volume += v;
    first += v * sum / 4.0;
    second += v / 20.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose());
  }
  const Vec3 com = first / volume;
  const Mat3 about_com = second - volume * com * com.transpose();
  assets::MassProperties p;
  p.volume = volume;
  p.density = 1.0;
  p.mass = volume;
  p.center_of_mass = o + com;
  p.inertia = about_com.trace() * Mat3::Identity() - about_com;
  return p;
}

/// max |a − b| / max |b| over the entries (b non-zero).
inline double relative_error(const Mat3& a, const Mat3& b) { return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff(); }
inline double relative_error(double a, double b) { return std::abs(a - b) / std::abs(b); }

/// A rotation about a skewed axis (no symmetry of any test body lines up with it).
inline Mat3 skew_rotation() {
  return Eigen::AngleAxisd(0.7, Vec3(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
}

/// The message of the Error `f` throws, or "(no error)".
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace impetus::test
