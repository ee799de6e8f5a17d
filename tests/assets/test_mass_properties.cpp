// Mirtich's mass properties against closed forms: cube, box a×b×c moved far away and rotated
// (I transforms as R I Rᵀ; parallel-axis theorem), regular tetrahedron, polygonal prism, polyhedral
// and smooth torus, icospheres converging to the sphere, and an independent cross-check by signed
// tetrahedra. Tolerances are relative to the largest entry compared.
#include "asset_test_support.hpp"

#include "impetus/assets/mesh_body.hpp"

#include <cstdio>

namespace impetus::test {
namespace {

using assets::MassProperties;
using assets::polyhedral_mass_properties;
using std::numbers::pi;

constexpr double kExact = 1e-12;  // for meshes whose vertices are exact (or exact up to rounding)

Mat3 diagonal(double a, double b, double c) { return Vec3(a, b, c).asDiagonal(); }

// The unit cube [0, 1]³: V = 1, center (½, ½, ½), I = diag(1/6) about it.
TEST(MassProperties, UnitCube) {
  const MassProperties p = polyhedral_mass_properties(box_mesh(Vec3::Zero(), Vec3::Ones()));
  EXPECT_NEAR(p.volume, 1.0, kExact);
  EXPECT_NEAR(p.mass, 1.0, kExact);
  EXPECT_LT((p.center_of_mass - Vec3::Constant(0.5)).norm(), kExact);
  EXPECT_LT(relative_error(p.inertia, diagonal(1, 1, 1) / 6.0), kExact);
}

// A box a×b×c: I = m/12 diag(b² + c², a² + c², a² + b²) in its axes; rotated by R and moved 2 km,
// I_world = R I Rᵀ and the center moves with it, to 1e-12 (the vertices themselves carry rounding of
// about 2e3 · 1e-16 m, which is what limits this).
TEST(MassProperties, BoxFarFromTheOriginAndRotated) {
  const double a = 0.3, b = 1.7, c = 2.9, density = 7800.0;
  const Vec3 center(0.1, -0.2, 0.3);
  const Mat3 R = skew_rotation();
  const Vec3 t(1000.0, -2000.0, 500.0);
  const TriangleMesh mesh =
      transformed(box_mesh(center - 0.5 * Vec3(a, b, c), center + 0.5 * Vec3(a, b, c)), R, t);
  const MassProperties p = polyhedral_mass_properties(mesh, density);
  const double m = density * a * b * c;
  EXPECT_LT(relative_error(p.volume, a * b * c), kExact);
  EXPECT_LT(relative_error(p.mass, m), kExact);
  EXPECT_LT((p.center_of_mass - (R * center + t)).norm() / t.norm(), kExact);
  const Mat3 I_body = m / 12.0 * diagonal(b * b + c * c, a * a + c * c, a * a + b * b);
  EXPECT_LT(relative_error(p.inertia, R * I_body * R.transpose()), kExact);
  const Vec3 expected_moments(m / 12.0 * (a * a + b * b), m / 12.0 * (a * a + c * c), m / 12.0 * (b * b + c * c));
  EXPECT_LT((p.principal_moments - expected_moments).norm() / expected_moments.norm(), kExact);
}

// With exactly representable vertices a million metres out, the result is exact to rounding: the
// integrals are taken about the mesh's own center. (About the world origin, the parallel-axis
// subtraction would cancel ~12 digits; printed for comparison.)
TEST(MassProperties, ExactBoxAMillionMetresOut) {
  const Vec3 lo(1e6, 1e6 + 0.5, -1e6), size(0.5, 1.25, 2.0);
  const TriangleMesh mesh = box_mesh(lo, lo + size);
  const MassProperties p = polyhedral_mass_properties(mesh);
  const double m = size.prod();
  const Mat3 I = m / 12.0 * diagonal(size.y() * size.y() + size.z() * size.z(), size.x() * size.x() + size.z() * size.z(),
                                      size.x() * size.x() + size.y() * size.y());
  EXPECT_LT(relative_error(p.inertia, I), kExact);
  EXPECT_EQ(p.center_of_mass, lo + 0.5 * size);
  const MassProperties naive = assets::mass_properties_from_integrals(assets::volume_integrals(mesh, Vec3::Zero()), 1.0);
  std::printf("[ mass     ] box at 1e6 m: relative inertia error %.2g about its center, %.2g about the origin\n",
              relative_error(p.inertia, I), relative_error(naive.inertia, I));
}

// Parallel-axis theorem on the raw integrals: about any point o, J_o = J_c + V (|d|² E − d dᵀ).
TEST(MassProperties, IntegralsAboutAnyPointObeyTheParallelAxisTheorem) {
  const TriangleMesh mesh = transformed(torus_mesh(12, 8, 1.0, 0.3), skew_rotation(), Vec3(0.2, 0.4, -0.1));
  const MassProperties c = polyhedral_mass_properties(mesh);
  const Vec3 o = c.center_of_mass + Vec3(0.3, -0.2, 0.5);
  const assets::VolumeIntegrals T = assets::volume_integrals(mesh, o);
  Mat3 J_o;
  J_o << T.squares.y() + T.squares.z(), -T.products.x(), -T.products.z(), -T.products.x(),
      T.squares.z() + T.squares.x(), -T.products.y(), -T.products.z(), -T.products.y(), T.squares.x() + T.squares.y();
  const Vec3 d = c.center_of_mass - o;
  const Mat3 expected = c.inertia + c.volume * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
  EXPECT_LT(relative_error(J_o, expected), kExact);
  EXPECT_LT((T.first / T.volume - d).norm(), kExact);
}

// Regular tetrahedron of edge a: V = a³ / (6√2), I = m a² / 20 · E about its center. The bundled one
// has edge √2 (alternate corners of the cube [−½, ½]³), vertices exact in every format.
TEST(MassProperties, RegularTetrahedron) {
  const MassProperties p = assets::load_mesh_body(mesh_path("tetrahedron.obj")).unit;
  const double a = std::sqrt(2.0), V = a * a * a / (6.0 * std::sqrt(2.0));
  EXPECT_LT(relative_error(p.volume, V), kExact);
  EXPECT_LT(relative_error(p.inertia, Mat3::Identity() * V * a * a / 20.0), kExact);
}

// Regular n-gon prism (circumradius r, length h, axis z): area A = n r² sin(2π/n) / 2, polar moment of
// the polygon J = n r⁴ sin(2π/n) (2 + cos(2π/n)) / 12 (n triangles from the center), so
// I_zz = h J and I_xx = I_yy = h J / 2 + A h³ / 12 (for n ≥ 3 the section is isotropic).
TEST(MassProperties, PolygonalPrism) {
  for (const int n : {3, 7, 32}) {
    const double r = 0.8, h = 1.3;
    TriangleMesh mesh;
    for (int k = 0; k < n; ++k)
      for (double z : {-h / 2, h / 2})
        mesh.vertices.emplace_back(r * std::cos(2 * pi * k / n), r * std::sin(2 * pi * k / n), z);
    mesh.vertices.emplace_back(0, 0, -h / 2);
    mesh.vertices.emplace_back(0, 0, h / 2);
    const auto bottom = std::uint32_t(2 * n), top = bottom + 1;
    for (int k = 0; k < n; ++k) {
      const auto lo = std::uint32_t(2 * k), hi = lo + 1, lo2 = std::uint32_t(2 * ((k + 1) % n)), hi2 = lo2 + 1;
      mesh.triangles.push_back({lo, lo2, hi2});
      mesh.triangles.push_back({lo, hi2, hi});
      mesh.triangles.push_back({bottom, lo2, lo});
      mesh.triangles.push_back({top, hi, hi2});
    }
    const double A = n * r * r * std::sin(2 * pi / n) / 2, J = n * std::pow(r, 4) * std::sin(2 * pi / n) * (2 + std::cos(2 * pi / n)) / 12;
    const MassProperties p = polyhedral_mass_properties(transformed(mesh, skew_rotation(), Vec3(5, -3, 2)));
    const Mat3 I = diagonal(h * J / 2 + A * h * h * h / 12, h * J / 2 + A * h * h * h / 12, h * J);
    EXPECT_LT(relative_error(p.volume, A * h), kExact) << n;
    EXPECT_LT(relative_error(p.inertia, skew_rotation() * I * skew_rotation().transpose()), kExact) << n;
  }
}

// ∫ ρ^a z^b over the regular tube polygon (vertices (R + r cos θ, r sin θ)), by a fan of triangles from
// its center and the 4-point triangle rule (weights −27/48 at the centroid, 25/48 at barycentrics
// (3/5, 1/5, 1/5) and permutations), exact for cubics.
double polygon_moment(int tube, double R, double r, int a, int b) {
  double sum = 0.0;
  const Eigen::Vector2d o(R, 0.0);
  for (int j = 0; j < tube; ++j) {
    const double t0 = 2 * pi * j / tube, t1 = 2 * pi * (j + 1) / tube;
    const Eigen::Vector2d p(R + r * std::cos(t0), r * std::sin(t0)), q(R + r * std::cos(t1), r * std::sin(t1));
    const double area = 0.5 * std::abs((p - o).x() * (q - o).y() - (p - o).y() * (q - o).x());
    const auto f = [&](const Eigen::Vector2d& x) { return std::pow(x.x(), a) * std::pow(x.y(), b); };
    double rule = -27.0 / 48.0 * f((o + p + q) / 3.0);
    rule += 25.0 / 48.0 * (f(0.6 * o + 0.2 * p + 0.2 * q) + f(0.2 * o + 0.6 * p + 0.2 * q) + f(0.2 * o + 0.2 * p + 0.6 * q));
    sum += area * rule;
  }
  return sum;
}

// The faceted torus is exactly N pieces, each the image of (tube polygon) × [−1, 1] under
// (ρ, t, z) ↦ (ρ cos α, ρ t sin α, z), α = π/N, Jacobian ρ sin α cos α. Hence V = N sin 2α ∫ρ,
// I_zz = N sin 2α (cos²α + sin²α / 3) ∫ρ³, I_xx = I_yy = I_zz / 2 + N sin 2α ∫ρz².
TEST(MassProperties, PolyhedralTorusExactly) {
  const int N = 32, tube = 16;
  const double R = 1.0, r = 0.25, alpha = pi / N, k = N * std::sin(2 * alpha);
  const double V = k * polygon_moment(tube, R, r, 1, 0);
  const double Izz = k * (std::cos(alpha) * std::cos(alpha) + std::sin(alpha) * std::sin(alpha) / 3) * polygon_moment(tube, R, r, 3, 0);
  const double Ixx = Izz / 2 + k * polygon_moment(tube, R, r, 1, 2);
  const Mat3 I = diagonal(Ixx, Ixx, Izz);
  const MassProperties p = polyhedral_mass_properties(torus_mesh(N, tube, R, r));
  EXPECT_LT(relative_error(p.volume, V), kExact);
  EXPECT_LT(relative_error(p.inertia, I), kExact);
  // The bundled torus is the same solid with float32 vertices: equal to ~1e-7.
  const MassProperties file = assets::load_mesh_body(mesh_path("torus.obj")).unit;
  EXPECT_LT(relative_error(file.volume, V), 1e-6);
  EXPECT_LT(relative_error(file.inertia, I), 1e-6);
}

// The smooth torus (V = 2π²Rr², I_zz = m (R² + ¾ r²), I_xx = m (½ R² + ⅝ r²)) is the limit; the
// faceted one is within the O(h²) of its facets (here 32 × 16: under 2.5 %).
TEST(MassProperties, PolyhedralTorusApproachesTheSmoothOne) {
  const double R = 1.0, r = 0.25, V = 2 * pi * pi * R * r * r;
  const Mat3 I = V * diagonal(R * R / 2 + 5 * r * r / 8, R * R / 2 + 5 * r * r / 8, R * R + 0.75 * r * r);
  double previous = 1.0;
  for (int n : {8, 16, 32, 64}) {
    const MassProperties p = polyhedral_mass_properties(torus_mesh(2 * n, n, R, r));
    const double error = relative_error(p.inertia, I);
    std::printf("[ mass     ] torus %3d x %2d: volume error %.3e, inertia error %.3e\n", 2 * n, n,
                relative_error(p.volume, V), error);
    EXPECT_LT(error, previous / 3.5);  // second order: 4× smaller each time the facets halve
    previous = error;
  }
  EXPECT_LT(previous, 0.01);
}

// Icospheres of subdivision level k (edge ∝ 2^−k) converge to the sphere (V = 4/3 π, I = 8/15 π for
// r = 1) at second order: the error falls 4× per level, log2(e_k / e_{k+1}) → 2.
TEST(MassProperties, IcospheresConvergeToTheSphereAtSecondOrder) {
  const double V = 4.0 / 3.0 * pi, I = 8.0 / 15.0 * pi;
  std::vector<double> errors;
  for (int level = 0; level <= 4; ++level) {
    const MassProperties p = assets::load_mesh_body(mesh_path("icosphere_" + std::to_string(level) + ".obj")).unit;
    EXPECT_LT(p.center_of_mass.norm(), 1e-6);
    EXPECT_LT((p.inertia - p.inertia(0, 0) * Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-6 * I);  // isotropic
    errors.push_back(relative_error(p.principal_moments.mean(), I));
    const double order = level ? std::log2(errors[level - 1] / errors[level]) : 0.0;
    std::printf("[ mass     ] icosphere %d: volume error %.3e, inertia error %.3e, observed order %.3f\n", level,
                relative_error(p.volume, V), errors.back(), order);
  }
  for (std::size_t k = 3; k < errors.size(); ++k) {  // levels 0–2 are not yet asymptotic
    const double order = std::log2(errors[k - 1] / errors[k]);
    EXPECT_GT(order, 1.9) << "level " << k;
    EXPECT_LT(order, 2.1) << "level " << k;
  }
}

// Mirtich's method and the signed-tetrahedron decomposition agree to rounding on non-convex and
// curved meshes, wherever they sit.
TEST(MassProperties, AgreesWithSignedTetrahedra) {
  for (const char* name : {"l_bracket.obj", "t_handle.obj", "torus.obj", "icosphere_3.obj", "cylinder.obj", "box.obj"}) {
    const assets::MeshBody body = assets::load_mesh_body(mesh_path(name));
    for (const Vec3& offset : {Vec3(0, 0, 0), Vec3(30, -40, 50)}) {
      const TriangleMesh mesh = transformed(*body.mesh, skew_rotation(), offset);
      const MassProperties p = polyhedral_mass_properties(mesh);
      const MassProperties q = tetrahedra_reference(mesh, offset + Vec3(0.01, 0.02, -0.01));
      EXPECT_LT(relative_error(p.volume, q.volume), kExact) << name;
      EXPECT_LT((p.center_of_mass - q.center_of_mass).norm() / (1.0 + offset.norm()), kExact) << name;
      EXPECT_LT(relative_error(p.inertia, q.inertia), 1e-10) << name;
    }
  }
}

// Density and mass: mass = ρ V, inertia ∝ ρ; with_mass rescales to a given total mass.
TEST(MassProperties, DensityAndGivenMass) {
  const TriangleMesh mesh = box_mesh(Vec3::Zero(), Vec3(1, 2, 3));
  const MassProperties p = polyhedral_mass_properties(mesh, 7800.0);
  EXPECT_NEAR(p.mass, 7800.0 * 6.0, 1e-9);
  const MassProperties q = assets::with_mass(p, 12.0);
  EXPECT_DOUBLE_EQ(q.mass, 12.0);
  EXPECT_DOUBLE_EQ(q.density, 2.0);
  EXPECT_LT(relative_error(q.inertia, 12.0 / 12.0 * diagonal(4 + 9, 1 + 9, 1 + 4)), kExact);
}

// Principal axes form a rotation and diagonalize the tensor; moments ascend. The T handle has three
// distinct moments (it tumbles about the middle one).
TEST(MassProperties, PrincipalAxesDiagonalizeTheTensor) {
  const MassProperties p = assets::load_mesh_body(mesh_path("t_handle.obj")).unit;
  const Mat3& A = p.principal_axes;
  EXPECT_LT((A.transpose() * A - Mat3::Identity()).norm(), 1e-12);
  EXPECT_NEAR(A.determinant(), 1.0, 1e-12);
  EXPECT_LT(relative_error(A * p.principal_moments.asDiagonal() * A.transpose(), p.inertia), 1e-12);
  EXPECT_LT(p.principal_moments[0], p.principal_moments[1]);
  EXPECT_LT(p.principal_moments[1], p.principal_moments[2]);
  EXPECT_GE(p.principal_moments[0] + p.principal_moments[1], p.principal_moments[2]);  // triangle inequality
}

}  // namespace
}  // namespace impetus::test
