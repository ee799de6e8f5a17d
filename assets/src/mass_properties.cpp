// Mirtich's polyhedral mass properties, from the paper's three reductions (see mass_properties.hpp):
// volume integrals → face integrals (divergence theorem) → projection integrals (each face projected
// onto the coordinate plane its normal is most nearly perpendicular to) → line integrals along the
// projected edges (Green's theorem).

#include "impetus/assets/mass_properties.hpp"

#include <Eigen/Eigenvalues>

#include <array>
#include <cassert>
#include <cmath>

namespace impetus::assets {
namespace {

constexpr int kMaxDegree = 3;  // the ten integrals need monomials up to degree 3

constexpr std::array<double, 9> kFactorial = {1, 1, 2, 6, 24, 120, 720, 5040, 40320};

double binomial(int n, int k) { return kFactorial[n] / (kFactorial[k] * kFactorial[n - k]); }

// Powers x⁰ … x⁴ of one number (the highest any integral here needs).
using Powers = std::array<double, kMaxDegree + 2>;

Powers powers(double x) {
  Powers p{1.0};
  for (std::size_t k = 1; k < p.size(); ++k) p[k] = p[k - 1] * x;
  return p;
}

// ∫₀¹ a(t)^m b(t)^q dt on the segment a(t) = (1 − t) a0 + t a1, b(t) = (1 − t) b0 + t b1. Expanding both
// powers binomially leaves integrals of t^k (1 − t)^l, which are k! l! / (k + l + 1)! (Beta function).
double segment_moment(int m, int q, const Powers& a0, const Powers& a1, const Powers& b0, const Powers& b1) {
  double sum = 0.0;
  for (int i = 0; i <= m; ++i)
    for (int j = 0; j <= q; ++j) {
      const int k = i + j, l = m + q - i - j;
      sum += binomial(m, i) * binomial(q, j) * a1[i] * a0[m - i] * b1[j] * b0[q - j] * kFactorial[k] *
             kFactorial[l] / kFactorial[k + l + 1];
    }
  return sum;
}

// Projection integrals P[p][q] = ∫∫_Π α^p β^q dα dβ, p + q ≤ 3, over the projection Π of one triangle,
// signed by its traversal (positive counter-clockwise in the αβ plane). Green's theorem turns each
// into a line integral: ∫∫_Π α^p β^q dα dβ = 1/(p + 1) ∮ α^(p+1) β^q dβ, summed edge by edge.
using Projection = std::array<std::array<double, kMaxDegree + 1>, kMaxDegree + 1>;

Projection projection_integrals(const std::array<Vec3, 3>& p, int alpha, int beta) {
  Projection P{};
  for (int e = 0; e < 3; ++e) {
    const Vec3& from = p[e];
    const Vec3& to = p[(e + 1) % 3];
    const double d_beta = to[beta] - from[beta];
    if (d_beta == 0.0) continue;  // an edge parallel to α adds nothing to ∮ … dβ
    const Powers a0 = powers(from[alpha]), a1 = powers(to[alpha]), b0 = powers(from[beta]), b1 = powers(to[beta]);
    for (int i = 0; i <= kMaxDegree; ++i)
      for (int j = 0; i + j <= kMaxDegree; ++j)
        P[i][j] += d_beta * segment_moment(i + 1, j, a0, a1, b0, b1) / (i + 1);
  }
  return P;
}

// Face integrals ∫_F x^ex y^ey z^ez dA of one triangle from its projection integrals. On the face's
// plane n·p + w = 0, γ = −(n_α α + n_β β + w) / n_γ = −k h(α, β) with k = 1/n_γ, and dA = |k| dα dβ
// (the sign of k also undoes the projection's orientation), so
//   ∫_F α^p β^q γ^r dA = k (−k)^r ∫∫_Π α^p β^q h^r dα dβ,
// with h^r expanded by the multinomial theorem into projection integrals.
class Face {
 public:
  Face(const std::array<Vec3, 3>& p, const Vec3& unit_normal, int gamma)
      : axis_{(gamma + 1) % 3, (gamma + 2) % 3, gamma},
        n_alpha_(powers(unit_normal[axis_[0]])),
        n_beta_(powers(unit_normal[axis_[1]])),
        w_(powers(-unit_normal.dot(p[0]))),
        k_(1.0 / unit_normal[gamma]),
        P_(projection_integrals(p, axis_[0], axis_[1])) {}

  /// ∫_F x^e[0] y^e[1] z^e[2] dA.
  double integral(const std::array<int, 3>& e) const {
    const int p = e[axis_[0]], q = e[axis_[1]], r = e[axis_[2]];
    double sum = 0.0;  // ∫∫ α^p β^q (n_α α + n_β β + w)^r
    for (int i = 0; i <= r; ++i)
      for (int j = 0; i + j <= r; ++j) {
        const int l = r - i - j;
        const double coefficient = kFactorial[r] / (kFactorial[i] * kFactorial[j] * kFactorial[l]);
        sum += coefficient * n_alpha_[i] * n_beta_[j] * w_[l] * P_[p + i][q + j];
      }
    return k_ * powers(-k_)[r] * sum;
  }

 private:
  std::array<int, 3> axis_;  // α, β, γ: a cyclic permutation of x, y, z, so (α, β, γ) is right-handed
  Powers n_alpha_, n_beta_, w_;  // powers of n_α, n_β and w
  double k_;                     // 1 / n_γ
  Projection P_;
};

}  // namespace

VolumeIntegrals volume_integrals(const TriangleMesh& mesh, const Vec3& origin) {
  VolumeIntegrals T;
  T.origin = origin;
  for (const auto& t : mesh.triangles) {
    const std::array<Vec3, 3> p = {mesh.vertices[t[0]] - origin, mesh.vertices[t[1]] - origin,
                                   mesh.vertices[t[2]] - origin};
    const Vec3 normal = (p[1] - p[0]).cross(p[2] - p[0]);
    const double length = normal.norm();
    if (!(length > 0.0)) continue;  // a zero-area face bounds nothing
    const Vec3 n = normal / length;
    // Project onto the plane of the two other axes of the normal's largest component: the projection
    // is then never thin, which keeps the integrals well conditioned.
    int gamma = 0;
    n.cwiseAbs().maxCoeff(&gamma);
    const Face face(p, n, gamma);
    // Divergence theorem, one field per integral: ∫_V 1 = ∮ n_x x, ∫_V x_i = ½ ∮ n_i x_i²,
    // ∫_V x_i² = ⅓ ∮ n_i x_i³, ∫_V xy = ½ ∮ n_x x² y (and cyclically for yz, zx).
    T.volume += n.x() * face.integral({1, 0, 0});
    T.first += 0.5 * Vec3(n.x() * face.integral({2, 0, 0}), n.y() * face.integral({0, 2, 0}),
                          n.z() * face.integral({0, 0, 2}));
    T.squares += Vec3(n.x() * face.integral({3, 0, 0}), n.y() * face.integral({0, 3, 0}),
                      n.z() * face.integral({0, 0, 3})) / 3.0;
    T.products += 0.5 * Vec3(n.x() * face.integral({2, 1, 0}), n.y() * face.integral({0, 2, 1}),
                             n.z() * face.integral({1, 0, 2}));
  }
  return T;
}

MassProperties mass_properties_from_integrals(const VolumeIntegrals& T, double density) {
  MassProperties out;
  out.volume = T.volume;
  out.density = density;
  out.mass = density * T.volume;
  const Vec3 c = T.first / T.volume;  // center of mass relative to T.origin
  out.center_of_mass = T.origin + c;
  // Inertia about T.origin: J_xx = ∫ (y² + z²), J_xy = −∫ xy, …
  const Vec3& S = T.squares;
  Mat3 about_origin;
  about_origin << S.y() + S.z(), -T.products.x(), -T.products.z(),  //
      -T.products.x(), S.z() + S.x(), -T.products.y(),                //
      -T.products.z(), -T.products.y(), S.x() + S.y();
  // Parallel-axis theorem back to the center of mass: J_c = J_o − V (|c|² E − c cᵀ). With the origin
  // near the mesh, c is no larger than the mesh, so this subtraction loses nothing.
  const Mat3 shift = T.volume * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  out.inertia = density * (about_origin - shift);
  out.inertia = 0.5 * (out.inertia + out.inertia.transpose()).eval();
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(out.inertia);
  out.principal_moments = eigen.eigenvalues();
  out.principal_axes = eigen.eigenvectors();
  if (out.principal_axes.determinant() < 0.0) out.principal_axes.col(2) *= -1.0;  // a rotation
  return out;
}

MassProperties polyhedral_mass_properties(const TriangleMesh& mesh, double density) {
  assert(density > 0.0);
  if (mesh.vertices.empty()) return mass_properties_from_integrals(VolumeIntegrals{}, density);
  Vec3 lo = mesh.vertices.front(), hi = lo;
  for (const Vec3& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return mass_properties_from_integrals(volume_integrals(mesh, 0.5 * (lo + hi)), density);
}

MassProperties with_mass(const MassProperties& properties, double mass) {
  assert(mass > 0.0 && properties.mass > 0.0);
  const double factor = mass / properties.mass;
  MassProperties out = properties;
  out.mass = mass;
  out.density = properties.density * factor;
  out.inertia = properties.inertia * factor;
  out.principal_moments = properties.principal_moments * factor;
  return out;
}

}  // namespace impetus::assets
