// A complementarity problem with redundant rows, solved in body space by a primal–dual interior point
// (Mehrotra's predictor–corrector). README.md, "Redundant islands: an interior point in body space".
//
// The problem (island_solver.hpp) is the optimality condition of the QP min ½ pᵀA p − cᵀp, p ≥ 0, with
// A = G M⁻¹ Gᵀ. Its dual in the velocity change u = M⁻¹ Gᵀ p is
//     min ½ uᵀ M u   subject to   G u ≥ c,
// whose multipliers are p and whose slacks s = G u − c are w. In contact space A is singular wherever
// rows are redundant (a face's four corners carry three independent constraints); in body space the
// Newton system M + Gᵀ D G (D = P S⁻¹) is positive definite whatever the rows, and of the bodies' size.
#include "body_space.hpp"

#include <algorithm>
#include <cmath>

namespace impetus::ledas {

namespace {
constexpr int kMaxSteps = 40;            // Mehrotra's method takes 10–20 on the problems it is used for
constexpr double kStepFraction = 0.99;   // of the longest step that keeps s, p > 0
constexpr double kRegularization = 1e-10;  // δ = this · max A_kk (below)
// The stopping rule's bound on each row's p_k w_k, in units of tolerance · max p. Each factor 100 costs
// about one more step: on a wall of 80 cubes (tests/resolution/ledas/test_ledas_body_space.cpp) the
// velocities came within 2.6e-7 / 2.5e-9 / 2.5e-11 / 7.5e-13 m/s of the active-set search's at 1 /
// 1e-2 / 1e-4 / 1e-6, in 10 / 11 / 12 / 13 steps; at 1e-6 the knocked wall's hardest problems no
// longer get there before the regularization's floor and fall back to the search.
constexpr double kComplementarity = 1e-4;

// The longest step α ≤ 1 with x + α dx ≥ 0.
double longest_step(const Vector& x, const Vector& dx) {
  double alpha = 1.0;
  for (Eigen::Index k = 0; k < x.size(); ++k)
    if (dx(k) < 0.0) alpha = std::min(alpha, -x(k) / dx(k));
  return alpha;
}

// The interior point's stopping rule on p ≥ 0 and w = A p − c: no row approaches (w ≥ −tolerance) and
// every row's complementarity product is at most kComplementarity · tolerance · max p (a row that
// separates by w carries at most kComplementarity · tolerance / w of the largest impulse).
bool complementary(const Vector& p, const Vector& w, double tolerance) {
  const double bound = kComplementarity * tolerance * p.lpNorm<Eigen::Infinity>();
  for (Eigen::Index k = 0; k < p.size(); ++k)
    if (!(w(k) >= -tolerance) || !(p(k) >= 0.0) || p(k) * w(k) > bound) return false;
  return true;
}
}  // namespace

bool suits_body_space(const ComplementarityProblem& problem, const SolverSettings& settings) {
  const BodySpace* body = problem.body_space;
  if (body == nullptr || settings.interior_point_rows == 0) return false;
  const auto m = static_cast<std::size_t>(problem.rhs.size());
  if (m < settings.interior_point_rows || body->jacobian.rows() != problem.rhs.size() ||
      body->jacobian.cols() >= problem.rhs.size())
    return false;
  return std::none_of(problem.equality.begin(), problem.equality.end(), [](char e) { return e != 0; });
}

bool solve_in_body_space(const ComplementarityProblem& problem, BodySpaceWorkspace& work, SolverStats& stats,
                         Vector& p_out) {
  const SparseMatrix& g = problem.body_space->jacobian;
  const SparseMatrix& mass = problem.body_space->mass;
  const SparseMatrix& a = *problem.matrix;
  const Vector& c = problem.rhs;
  const Eigen::Index m = g.rows(), n = g.cols();
  const double tolerance = problem.tolerance;
  const double c_scale = c.lpNorm<Eigen::Infinity>();
  if (!(c_scale > tolerance) || !std::isfinite(c_scale)) return false;  // p = 0 (or nothing sane): the search's
  double a_scale = 0.0;
  for (Eigen::Index k = 0; k < m; ++k) a_scale = std::max(a_scale, a.coeff(k, k));
  if (!(a_scale > 0.0)) return false;

  work.jacobian_t = g.transpose();
  Vector &u = work.u, &p = work.p, &s = work.s;
  u.setZero(n);
  s = ((-c).cwiseMax(0.0).array() + c_scale).matrix();  // strictly interior, of the problem's scale
  p.setConstant(m, c_scale / a_scale);
  bool analysed = false;
  const double delta = kRegularization * a_scale;
  for (int step = 0; step < kMaxSteps; ++step) {
    // Residuals: dual M u − Gᵀ p, primal G u − c − s, and the mean complementarity μ.
    work.dual.noalias() = mass * u;
    work.dual.noalias() -= work.jacobian_t * p;
    work.primal.noalias() = g * u;
    work.primal -= c + s;
    const double mu = p.dot(s) / static_cast<double>(m);

    // Judged on the impulses themselves: w = A p − c, which carries the dual residual's error.
    work.w.noalias() = a * p;
    work.w -= c;
    if (complementary(p, work.w, tolerance)) {
      // The rows that separate by more than the tolerance let go of their (small) impulses if the rule
      // still holds without them.
      work.candidate = p;
      for (Eigen::Index k = 0; k < m; ++k)
        if (work.w(k) > tolerance) work.candidate(k) = 0.0;
      work.check.noalias() = a * work.candidate;
      work.check -= c;
      p_out = complementary(work.candidate, work.check, tolerance) ? work.candidate : p;
      ++stats.interior_point_solved;
      return true;
    }

    // The Newton system in body space, regularized (primal–dual regularization): the primal equation
    // G du − ds = −r_p gets + δ dp, which caps D = (S P⁻¹ + δ)⁻¹ at 1/δ. Without it D grows without bound
    // on the rows that end pushing, and the rounding of the solve shows up as a growing dual residual
    // (on the knocked wall, M u − Gᵀp grew from 1e-10 to 1e-6 while μ fell, and the iteration stalled).
    // The dual and complementarity equations hold exactly; the primal one is off by δ dp, which the
    // next step's residual takes up.
    //   (M + Gᵀ D G) du = −r_d − Gᵀ D (r_p − P⁻¹ r_c),  dp = −D (G du + r_p − P⁻¹ r_c),  ds = G du + r_p + δ dp.
    work.ratio = (s.cwiseQuotient(p).array() + delta).inverse().matrix();
    work.system = work.jacobian_t * work.ratio.asDiagonal() * g;
    work.system += mass;
    if (!analysed) work.factor.analyzePattern(work.system), analysed = true;
    work.factor.factorize(work.system);
    ++stats.interior_point_steps;
    if (work.factor.info() != Eigen::Success) return false;
    const auto direction = [&](const Vector& complement, Vector& du, Vector& ds, Vector& dp) {
      work.target = work.ratio.cwiseProduct(work.primal - complement.cwiseQuotient(p));
      work.rhs.noalias() = -(work.jacobian_t * work.target);
      work.rhs -= work.dual;
      du = work.factor.solve(work.rhs);
      ds.noalias() = g * du;
      ds += work.primal;
      dp = -work.ratio.cwiseProduct(ds - complement.cwiseQuotient(p));
      ds += delta * dp;
    };
    // Predictor (affine scaling), then the corrector with centring σ = (μ_aff / μ)³.
    work.complement = -p.cwiseProduct(s);
    direction(work.complement, work.du_aff, work.ds_aff, work.dp_aff);
    const double primal_aff = longest_step(s, work.ds_aff), dual_aff = longest_step(p, work.dp_aff);
    const double mu_aff =
        (s + primal_aff * work.ds_aff).dot(p + dual_aff * work.dp_aff) / static_cast<double>(m);
    const double sigma = std::pow(mu_aff / mu, 3);
    work.complement = (sigma * mu - p.cwiseProduct(s).array() - work.ds_aff.cwiseProduct(work.dp_aff).array()).matrix();
    direction(work.complement, work.du, work.ds, work.dp);
    const double alpha = kStepFraction * std::min(longest_step(s, work.ds), longest_step(p, work.dp));
    u += alpha * work.du;
    s += alpha * work.ds;
    p += alpha * work.dp;
    if (!u.allFinite() || !p.allFinite()) return false;
  }
  return false;
}

}  // namespace impetus::ledas
