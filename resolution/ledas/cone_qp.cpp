// The convex relaxation by a primal–dual interior-point method (cone_qp.hpp).
//
// Variables are scaled to standard cones: x = D r with D = μ on a frictional contact's normal row and 1
// elsewhere, so ‖r_t‖ ≤ μ r_n becomes the second-order cone Q = {x₀ ≥ ‖(x₁, x₂)‖}, which is self-dual;
// the problem becomes min ½ xᵀP x + cᵀx, x ∈ Q × … × ℝ₊ × … × ℝ (free joint rows), P = D⁻¹WD⁻¹,
// c = D⁻¹q, with the multiplier z = P x + c (= D⁻¹u) in the same cones and x ∘ z = 0 (Jordan product:
// x ∘ z = (xᵀz, x₀ z₁ + z₀ x₁)). Each step scales both by Nesterov–Todd's T (T x = T⁻¹ z = λ) and solves
// (P + T²) Δx = rhs, symmetric positive definite (T² is, on every row but the joint rows), by sparse LDLᵀ.
#include "cone_qp.hpp"

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace impetus::ledas {

namespace {

// The fraction of the way to the cones' boundary a step goes at most.
constexpr double kStepToBoundary = 0.99;
// The shift of the joint rows' diagonal (× max P_ii): they have no barrier term, and redundant joints
// would leave P + T² singular there.
constexpr double kFreeShift = 1e-12;

// One cone: rows first .. first + size − 1 of x.
struct Cone {
  Eigen::Index first = 0;
  int size = 1;       // 1: ℝ₊ (or ℝ when free), 3: Q
  bool free = false;  // a joint row: no cone, z = 0
};

// Per cone and step: Nesterov–Todd's scaling T (symmetric), T², T⁻¹ and λ = T x.
struct Scaling {
  Eigen::Matrix3d t, t2, inverse;
  Eigen::Vector3d lambda;
};

using Vec3d = Eigen::Vector3d;

Vec3d block(const Vector& v, const Cone& k) {
  Vec3d b = Vec3d::Zero();
  for (int j = 0; j < k.size; ++j) b(j) = v(k.first + j);
  return b;
}

// a ∘ b on the cone (the Jordan product; on ℝ₊ the plain product).
Vec3d jordan(const Vec3d& a, const Vec3d& b, int size) {
  if (size == 1) return Vec3d(a(0) * b(0), 0.0, 0.0);
  return Vec3d(a.dot(b), a(0) * b(1) + b(0) * a(1), a(0) * b(2) + b(0) * a(2));
}

// v with λ ∘ v = ξ.
Vec3d jordan_divide(const Vec3d& lambda, const Vec3d& xi, int size) {
  if (size == 1) return Vec3d(xi(0) / lambda(0), 0.0, 0.0);
  const double det = lambda(0) * lambda(0) - lambda(1) * lambda(1) - lambda(2) * lambda(2);
  const double v0 = (lambda(0) * xi(0) - lambda(1) * xi(1) - lambda(2) * xi(2)) / det;
  return Vec3d(v0, (xi(1) - v0 * lambda(1)) / lambda(0), (xi(2) - v0 * lambda(2)) / lambda(0));
}

// √(v₀² − ‖v₁‖²), as (v₀ − ‖v₁‖)(v₀ + ‖v₁‖) to keep its precision near the cone's boundary.
double hyperbolic_norm(const Vec3d& v) {
  const double t = std::hypot(v(1), v(2));
  return std::sqrt(std::max(0.0, (v(0) - t) * (v(0) + t)));
}

// Nesterov–Todd's scaling of x, z in the interior of Q (or ℝ₊): w = (z̄ + J x̄)/(2γ) with x̄ = x/√det x,
// z̄ = z/√det z, γ = √((1 + x̄ᵀz̄)/2), J = diag(1, −1, −1); its square root v = (w + e)/√(2(w₀ + 1)); then
// T = θ (2 v vᵀ − J), θ = (det z / det x)^¼, and T⁻¹ = (2 J v vᵀ J − J)/θ.
Scaling nesterov_todd(const Vec3d& x, const Vec3d& z, int size) {
  Scaling s;
  if (size == 1) {
    const double t = std::sqrt(z(0) / x(0));
    s.t = Eigen::Matrix3d::Zero();
    s.t(0, 0) = t;
    s.t2 = s.t * s.t;
    s.inverse = Eigen::Matrix3d::Zero();
    s.inverse(0, 0) = 1.0 / t;
    s.lambda = Vec3d(std::sqrt(x(0) * z(0)), 0.0, 0.0);
    return s;
  }
  const Eigen::Matrix3d j = Vec3d(1.0, -1.0, -1.0).asDiagonal();
  const double dx = hyperbolic_norm(x), dz = hyperbolic_norm(z);
  const Vec3d xb = x / dx, zb = z / dz;
  const double gamma = std::sqrt(0.5 * (1.0 + xb.dot(zb)));
  Vec3d v = (zb + j * xb) / (2.0 * gamma);
  v(0) += 1.0;
  v /= std::sqrt(2.0 * v(0));
  const double theta = std::sqrt(dz / dx);
  s.t = theta * (2.0 * v * v.transpose() - j);
  const Vec3d jv = j * v;
  s.inverse = (2.0 * jv * jv.transpose() - j) / theta;
  s.t2 = s.t * s.t;
  s.lambda = s.t * x;
  return s;
}

// The largest α with x + α d in the cone (∞ if every α is), x in its interior.
double step_to_boundary(const Vec3d& x, const Vec3d& d, int size) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  if (size == 1) return d(0) < 0.0 ? -x(0) / d(0) : kInfinity;
  // (x₀ + α d₀)² − ‖x₁ + α d₁‖² = a α² + b α + c, c > 0: the first positive root, if any.
  const double a = d(0) * d(0) - d(1) * d(1) - d(2) * d(2);
  const double b = 2.0 * (x(0) * d(0) - x(1) * d(1) - x(2) * d(2));
  const double c = x(0) * x(0) - x(1) * x(1) - x(2) * x(2);
  if (a == 0.0) return b < 0.0 ? -c / b : kInfinity;
  const double discriminant = b * b - 4.0 * a * c;
  if (discriminant < 0.0) return kInfinity;  // a > 0 here: the quadratic stays positive
  const double h = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
  double best = kInfinity;
  for (const double root : {h / a, h != 0.0 ? c / h : kInfinity})
    if (root > 0.0) best = std::min(best, root);
  // A root behind the apex of −Q (x₀ + α d₀ < 0 there) is not reached through Q; the first is.
  return best;
}

double max_step(const std::vector<Cone>& cones, const Vector& x, const Vector& dx, const Vector& z,
                const Vector& dz) {
  double alpha = std::numeric_limits<double>::infinity();
  for (const Cone& k : cones) {
    if (k.free) continue;
    alpha = std::min({alpha, step_to_boundary(block(x, k), block(dx, k), k.size),
                      step_to_boundary(block(z, k), block(dz, k), k.size)});
  }
  return alpha;
}

}  // namespace

Vector solve_cone_qp(const FrictionalProblem& problem, double target, std::uint64_t max_iterations,
                     ConeQpReport& report) {
  const SparseMatrix& w = *problem.w;
  const Eigen::Index m = problem.q.size();
  report = {};
  if (m == 0) return Vector();

  // The cones and the scaling D.
  std::vector<Cone> cones;
  Vector d = Vector::Ones(m);
  std::size_t degree = 0;  // ν: the number of cones (the barrier's degree)
  for (Eigen::Index i = 0; i < m;) {
    const auto row = static_cast<std::size_t>(i);
    Cone k;
    k.first = i;
    k.free = problem.role[row] == RowRole::equality;
    if (problem.role[row] == RowRole::normal && problem.mu[row] > 0.0) {
      k.size = 3;
      d(i) = problem.mu[row];
    }
    if (!k.free) ++degree;
    cones.push_back(k);
    i += k.size;
  }
  SparseMatrix p = w;
  for (Eigen::Index col = 0; col < p.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(p, col); it; ++it) it.valueRef() /= d(it.row()) * d(col);
  const Vector c = problem.q.cwiseQuotient(d);
  const double p_scale = std::max(p.diagonal().maxCoeff(), std::numeric_limits<double>::min());
  const double c_scale = std::max(c.lpNorm<Eigen::Infinity>(), std::numeric_limits<double>::min());

  // Start at the cones' centres e = (1, 0, 0), sized to the problem: x ~ impulses, z ~ velocities.
  Vector x = Vector::Zero(m), z = Vector::Zero(m);
  for (const Cone& k : cones)
    if (!k.free) {
      x(k.first) = c_scale / p_scale;
      z(k.first) = c_scale;
    }

  // The pattern of P + T² (P's and each cone's diagonal block, explicit zeros kept) is the same at every
  // step: one symbolic analysis.
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> ldlt;
  bool analyzed = false;
  std::vector<Scaling> scaling(cones.size());
  Vector r = Vector::Zero(m);
  Vector best = r;
  double best_residual = std::numeric_limits<double>::infinity();
  FrictionalProblem relaxed = problem;
  relaxed.convex = true;

  for (; report.iterations < max_iterations; ++report.iterations) {
    r = x.cwiseQuotient(d);
    const double residual = natural_map_residual(relaxed, r);
    if (residual < best_residual) {
      best_residual = residual;
      best = r;
    }
    if (residual <= target) {
      report.converged = true;
      break;
    }
    const Vector rd = p * x + c - z;  // the dual residual (z = 0 on joint rows)
    double gap = 0.0;
    for (const Cone& k : cones)
      if (!k.free) gap += block(x, k).dot(block(z, k));
    const double mu = degree > 0 ? gap / static_cast<double>(degree) : 0.0;

    entries.clear();
    bool numerical_end = false;
    for (Eigen::Index col = 0; col < p.outerSize(); ++col)
      for (SparseMatrix::InnerIterator it(p, col); it; ++it)
        if (it.row() >= col) entries.emplace_back(it.row(), col, it.value());
    for (std::size_t n = 0; n < cones.size(); ++n) {
      const Cone& k = cones[n];
      if (k.free) {
        entries.emplace_back(k.first, k.first, kFreeShift * p_scale);
        continue;
      }
      scaling[n] = nesterov_todd(block(x, k), block(z, k), k.size);
      if (!scaling[n].t2.allFinite()) {  // an iterate on a boundary to rounding: as far as it goes
        numerical_end = true;
        break;
      }
      for (int a = 0; a < k.size; ++a)
        for (int b = 0; b <= a; ++b) entries.emplace_back(k.first + a, k.first + b, scaling[n].t2(a, b));
    }
    if (numerical_end) break;
    SparseMatrix h(m, m);
    h.setFromTriplets(entries.begin(), entries.end());
    if (!analyzed) {
      ldlt.analyzePattern(h);
      analyzed = true;
    }
    ldlt.factorize(h);
    if (ldlt.info() != Eigen::Success) break;

    // (P + T²) Δx = −r_d + T η,  Δz = T η − T² Δx,  with λ ∘ η = ξ per cone.
    const auto direction = [&](const std::vector<Vec3d>& eta, Vector& dx, Vector& dz) {
      Vector rhs = -rd;
      for (std::size_t n = 0; n < cones.size(); ++n) {
        const Cone& k = cones[n];
        if (k.free) continue;
        const Vec3d te = scaling[n].t * eta[n];
        for (int a = 0; a < k.size; ++a) rhs(k.first + a) += te(a);
      }
      dx = ldlt.solve(rhs);
      dz = Vector::Zero(m);
      for (std::size_t n = 0; n < cones.size(); ++n) {
        const Cone& k = cones[n];
        if (k.free) continue;
        const Vec3d v = scaling[n].t * eta[n] - scaling[n].t2 * block(dx, k);
        for (int a = 0; a < k.size; ++a) dz(k.first + a) = v(a);
      }
    };
    // Predictor (affine scaling): ξ = −λ ∘ λ, so η = −λ.
    std::vector<Vec3d> eta(cones.size(), Vec3d::Zero());
    for (std::size_t n = 0; n < cones.size(); ++n)
      if (!cones[n].free) eta[n] = -scaling[n].lambda;
    Vector dx_aff, dz_aff;
    direction(eta, dx_aff, dz_aff);
    if (!dx_aff.allFinite()) break;
    const double alpha_aff = std::min(1.0, max_step(cones, x, dx_aff, z, dz_aff));
    double gap_aff = 0.0;
    for (const Cone& k : cones)
      if (!k.free) gap_aff += (block(x, k) + alpha_aff * block(dx_aff, k)).dot(block(z, k) + alpha_aff * block(dz_aff, k));
    const double sigma = mu > 0.0 ? std::pow(std::clamp(gap_aff / gap, 0.0, 1.0), 3) : 0.0;

    // Corrector (Mehrotra): ξ = σ μ e − λ ∘ λ − (T Δx_aff) ∘ (T⁻¹ Δz_aff).
    for (std::size_t n = 0; n < cones.size(); ++n) {
      const Cone& k = cones[n];
      if (k.free) continue;
      const Scaling& s = scaling[n];
      Vec3d xi = -jordan(s.lambda, s.lambda, k.size) -
                 jordan(s.t * block(dx_aff, k), s.inverse * block(dz_aff, k), k.size);
      xi(0) += sigma * mu;
      eta[n] = jordan_divide(s.lambda, xi, k.size);
    }
    Vector dx, dz;
    direction(eta, dx, dz);
    if (!dx.allFinite() || !dz.allFinite()) break;
    const double alpha = std::min(1.0, kStepToBoundary * max_step(cones, x, dx, z, dz));
    x += alpha * dx;
    z += alpha * dz;
  }
  if (!report.converged) {
    r = x.cwiseQuotient(d);
    if (natural_map_residual(relaxed, r) < best_residual) best = r;
  }
  return best;
}

}  // namespace impetus::ledas
