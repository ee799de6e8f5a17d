// Closed-form mass properties of the primitives (core/src/mass.cpp), each checked against an
// independent derivation: textbook formulas, exact quadrature over slices, and composition.
#include "impetus/core/mass.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <numbers>

namespace impetus {
namespace {

using std::numbers::pi;
constexpr double kRelative = 1e-12;  // every check here: relative to the largest coefficient

UnitMassProperties properties(const Shape& shape) {
  const auto p = primitive_mass_properties(shape);
  EXPECT_TRUE(p.has_value()) << shape_kind_name(shape);
  return p.value_or(UnitMassProperties{});
}

void expect_inertia(const Mat3& actual, const Mat3& expected) {
  EXPECT_LE((actual - expected).norm(), kRelative * expected.norm())
      << "actual\n" << actual << "\nexpected\n" << expected;
}

Mat3 diagonal(double xx, double yy, double zz) { return Vec3(xx, yy, zz).asDiagonal(); }

// A solid of revolution about z with radius ρ(z) on [z0, z1], integrated over discs: a disc of radius ρ
// has area π ρ², ∫ x² dA = π ρ⁴ / 4, so V = ∫ π ρ² dz, I_zz = ∫ π ρ⁴ / 2 dz and
// I_xx = I_yy = ∫ (π ρ⁴ / 4 + z² π ρ²) dz. Three-point Gauss–Legendre is exact up to degree 5; for the
// shapes here ρ² is a polynomial of degree ≤ 2 on each piece, so the integrands have degree ≤ 4 and
// the quadrature is exact (to rounding).
struct Slices {
  double volume = 0.0, transverse = 0.0, axial = 0.0;
  void add(double z0, double z1, const std::function<double(double)>& rho_squared) {
    static constexpr std::array<double, 3> nodes{-0.7745966692414834, 0.0, 0.7745966692414834};
    static constexpr std::array<double, 3> weights{5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    const double half = 0.5 * (z1 - z0), mid = 0.5 * (z0 + z1);
    for (int i = 0; i < 3; ++i) {
      const double z = mid + half * nodes[i], w = half * weights[i], r2 = rho_squared(z);
      volume += w * pi * r2;
      transverse += w * (pi * r2 * r2 / 4.0 + z * z * pi * r2);
      axial += w * pi * r2 * r2 / 2.0;
    }
  }
  Mat3 inertia() const { return diagonal(transverse, transverse, axial); }
};

// Law: sphere V = 4/3 π r³, I = 2/5 m r² about every axis (per unit density m = V).
TEST(PrimitiveMass, Sphere) {
  const double r = 0.7;
  const UnitMassProperties p = properties(Sphere{r});
  const double volume = 4.0 / 3.0 * pi * r * r * r;
  EXPECT_NEAR(p.volume, volume, kRelative * volume);
  expect_inertia(p.inertia_per_density, Mat3::Identity() * 0.4 * volume * r * r);
  Slices s;  // and by slices: ρ² = r² − z²
  s.add(-r, r, [r](double z) { return r * r - z * z; });
  EXPECT_NEAR(p.volume, s.volume, kRelative * volume);
  expect_inertia(p.inertia_per_density, s.inertia());
}

// Law: box with edges a, b, c: V = abc, I_xx = m (b² + c²)/12, I_yy = m (a² + c²)/12,
// I_zz = m (a² + b²)/12.
TEST(PrimitiveMass, Box) {
  const double a = 0.3, b = 1.1, c = 2.0;
  const UnitMassProperties p = properties(Box{Vec3(a, b, c)});
  const double m = a * b * c;
  EXPECT_NEAR(p.volume, m, kRelative * m);
  expect_inertia(p.inertia_per_density, diagonal(m * (b * b + c * c) / 12.0, m * (a * a + c * c) / 12.0,
                                                 m * (a * a + b * b) / 12.0));
}

// Law: cylinder of radius r, length h, axis z: V = π r² h, I_zz = m r²/2, I_xx = I_yy = m (3r² + h²)/12;
// also by slices.
TEST(PrimitiveMass, Cylinder) {
  const double r = 0.4, h = 1.5;
  const UnitMassProperties p = properties(Cylinder{r, h});
  const double m = pi * r * r * h;
  EXPECT_NEAR(p.volume, m, kRelative * m);
  const double transverse = m * (3 * r * r + h * h) / 12.0;
  expect_inertia(p.inertia_per_density, diagonal(transverse, transverse, m * r * r / 2.0));
  Slices s;
  s.add(-h / 2, h / 2, [r](double) { return r * r; });
  expect_inertia(p.inertia_per_density, s.inertia());
}

// Law: a capsule is a cylinder (length h) plus two hemispheres. Checked two independent ways:
// (1) exact quadrature over slices of the three pieces; (2) composition: the cylinder's own result
// plus each hemisphere, whose moment about a transverse axis through its centroid is
// 2/5 m r² − m (3r/8)², moved by the parallel-axis term m d² with d = h/2 + 3r/8.
TEST(PrimitiveMass, Capsule) {
  const double r = 0.35, h = 1.2;
  const UnitMassProperties p = properties(Capsule{r, h});

  Slices s;
  s.add(-h / 2 - r, -h / 2, [=](double z) { return r * r - (z + h / 2) * (z + h / 2); });
  s.add(-h / 2, h / 2, [=](double) { return r * r; });
  s.add(h / 2, h / 2 + r, [=](double z) { return r * r - (z - h / 2) * (z - h / 2); });
  EXPECT_NEAR(p.volume, s.volume, kRelative * s.volume);
  expect_inertia(p.inertia_per_density, s.inertia());

  const UnitMassProperties cyl = properties(Cylinder{r, h});
  const double m_half = 2.0 / 3.0 * pi * r * r * r;
  const double centroid = 3.0 * r / 8.0, d = h / 2 + centroid;
  const double half_transverse = 0.4 * m_half * r * r - m_half * centroid * centroid + m_half * d * d;
  const double half_axial = 0.4 * m_half * r * r;
  const Mat3 composed =
      cyl.inertia_per_density + 2.0 * diagonal(half_transverse, half_transverse, half_axial);
  EXPECT_NEAR(p.volume, cyl.volume + 2.0 * m_half, kRelative * p.volume);
  expect_inertia(p.inertia_per_density, composed);
}

// Law: limit cases. A capsule of length 0 is a sphere; a cylinder of length 0 has no volume.
TEST(PrimitiveMass, CapsuleOfZeroLengthIsASphere) {
  const UnitMassProperties capsule = properties(Capsule{0.6, 0.0});
  const UnitMassProperties sphere = properties(Sphere{0.6});
  EXPECT_NEAR(capsule.volume, sphere.volume, kRelative * sphere.volume);
  expect_inertia(capsule.inertia_per_density, sphere.inertia_per_density);
  EXPECT_EQ(properties(Cylinder{0.6, 0.0}).volume, 0.0);
}

// Planes are infinite and meshes belong to the asset pipeline: no closed form.
TEST(PrimitiveMass, PlaneAndMeshHaveNone) {
  EXPECT_FALSE(primitive_mass_properties(Plane{}).has_value());
  EXPECT_FALSE(primitive_mass_properties(MeshShape{}).has_value());
}

}  // namespace
}  // namespace impetus
