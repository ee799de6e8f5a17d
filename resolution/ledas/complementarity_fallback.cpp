// Complementarity problems: the two minimum-norm pieces around the proximal active set of
// complementarity.cpp — the fallback for problems without an exact solution, and the minimum-norm
// impulse split of a small final system.
#include "complementarity_solver.hpp"
#include "primal_step.hpp"
#include "solver_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus::ledas {

namespace {

// z = the minimum-norm least-squares solution of A_FF z_F = c_F on the free rows F, zero off F.
Vector min_norm_on_free_set(EqualitySolver& equalities, const SparseMatrix& a, const Vector& c,
                            const std::vector<char>& free_rows, SolverStats& stats) {
  const std::vector<RowIndex> rows = members(free_rows);
  Vector z = Vector::Zero(a.rows());
  const Vector part = equalities.solve_system(principal_submatrix(a, rows), gather(c, rows), stats);
  for (std::size_t i = 0; i < rows.size(); ++i) z(rows[i]) = part(static_cast<Eigen::Index>(i));
  return z;
}

// A singular system with an inconsistent right-hand side has no minimizer on F: the objective falls
// without bound along the residual d = c − A z (a null direction). Sets d to its clear components on F
// and returns whether it is such a direction for some inequality row (else z is the answer on F).
bool null_direction(const ComplementarityProblem& problem, const Vector& z, const std::vector<char>& free_rows,
                    bool singular, Vector& d) {
  const Vector& c = problem.rhs;
  d = c - *problem.matrix * z;
  double inconsistency = 0.0;
  for (std::size_t k = 0; k < free_rows.size(); ++k)
    if (free_rows[k]) inconsistency = std::max(inconsistency, std::abs(d(static_cast<Eigen::Index>(k))));
    else d(static_cast<Eigen::Index>(k)) = 0.0;
  if (!(singular && inconsistency > 0.5 * problem.tolerance)) return false;
  bool along_null = false;
  for (std::size_t k = 0; k < free_rows.size(); ++k) {
    double& dk = d(static_cast<Eigen::Index>(k));
    if (std::abs(dk) < 1e-6 * inconsistency) dk = 0.0;
    along_null = along_null || (!problem.equality[k] && dk != 0.0);
  }
  return along_null;
}

// Whether z is ≥ 0 (to rounding) on every free inequality row.
bool feasible(const Vector& z, const std::vector<char>& free_rows, const std::vector<char>& equality, double roundoff) {
  bool out = true;
  for (std::size_t k = 0; k < free_rows.size(); ++k)
    if (free_rows[k] && !equality[k] && z(static_cast<Eigen::Index>(k)) < -roundoff) out = false;
  return out;
}

// At a feasible p: clamps rounding below zero on the free rows and adds every row at zero that would
// approach (w < −tolerance). Returns whether any row was added.
bool add_approaching(const ComplementarityProblem& problem, Vector& p, std::vector<char>& free_rows,
                     SolverStats& stats) {
  const Vector w = *problem.matrix * p - problem.rhs;
  bool added = false;
  for (std::size_t k = 0; k < free_rows.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    if (!problem.equality[k] && free_rows[k]) p(i) = std::max(p(i), 0.0);  // rounding below zero
    if (!free_rows[k] && w(i) < -problem.tolerance) {
      free_rows[k] = 1;
      added = true;
      ++stats.added;
    }
  }
  return added;
}

}  // namespace

// The earlier method, kept as the fallback for problems the proximal iteration cannot finish (an
// inconsistent singular system: conflicting targets, where the regularized iterates drift): each free
// set solved by minimum-norm least squares, whose residual is then a null direction followed to the
// first bound; the primal active-set step (primal_step.hpp) otherwise.
Vector ComplementaritySolver::solve_min_norm(const ComplementarityProblem& problem, SolverStats& stats) {
  const SparseMatrix& a = *problem.matrix;
  const auto m = static_cast<std::size_t>(a.rows());
  std::vector<char> free_rows(m);
  for (std::size_t k = 0; k < m; ++k) free_rows[k] = problem.equality[k] || problem.start[k];
  Vector p = Vector::Zero(a.rows());
  bool converged = false, not_finite = false, infeasible = false;
  const std::uint64_t budget = work_budget(m, settings_);
  for (std::uint64_t iteration = 0; iteration < budget; ++iteration) {
    ++stats.iterations;
    const std::uint64_t singular_before = stats.singular;
    const Vector z = min_norm_on_free_set(equalities_, a, problem.rhs, free_rows, stats);
    if (!z.allFinite()) {
      ++stats.nan_caught;
      p.setZero();
      not_finite = true;
      break;
    }
    Vector d;
    const bool along_null = null_direction(problem, z, free_rows, stats.singular != singular_before, d);
    Vector direction;  // p moves along `direction` by the ratio test, or p = z
    const double roundoff = kImpulseRoundoff * z.lpNorm<Eigen::Infinity>();
    if (along_null) direction = d;
    else if (!feasible(z, free_rows, problem.equality, roundoff)) direction = z - p;
    if (direction.size() > 0) {
      // The largest step keeping every free inequality row ≥ 0 (at most 1 towards z, unbounded along
      // the null direction); the blocking row is released even when the step is cut to 1.
      RatioTest test = ratio_test(p, direction, free_rows, problem.equality, std::numeric_limits<double>::infinity());
      if (test.blocking == m) {  // the objective falls without bound: the problem has no solution
        infeasible = true;
        ++stats.infeasible;
        break;
      }
      if (!along_null) test.step = std::min(test.step, 1.0);
      // Falling: along the null direction, the rows it lowers; towards z, the rows z puts below zero.
      step_and_release(p, direction, test, along_null ? direction : z, along_null ? 0.0 : roundoff, free_rows,
                       problem.equality, stats);
      continue;
    }
    p = z;
    if (!add_approaching(problem, p, free_rows, stats)) {
      converged = true;
      break;
    }
  }
  if (!converged && !not_finite && !infeasible) {
    ++stats.non_converged;
    if (budget < settings_.max_iterations) ++stats.work_limited;
  }
  clamp_to_free_set(p, free_rows, problem.equality);
  return p;
}

// The redundant rows' share of the impulse is not unique; where the system is small enough to afford
// it, take the minimum-norm one (the paper's choice for its Figure 2: the impulse shared equally among
// collinear contacts) if it keeps every impulse ≥ 0. It changes no velocity: p − p_min is a
// self-equilibrated impulse set (A (p − p_min) = 0).
void ComplementaritySolver::polish_minimum_norm(const SparseMatrix& a, const Vector& c, std::vector<char>& rows,
                                       const ComplementarityProblem& problem, Vector& p, SolverStats& stats) {
  for (std::size_t k = 0; k < rows.size(); ++k)  // rows at zero with w = 0 may share the impulse too
    if (!rows[k] && !problem.equality[k]) {
      double w = -c(static_cast<Eigen::Index>(k));
      for (SparseMatrix::InnerIterator it(a, static_cast<Eigen::Index>(k)); it; ++it) w += it.value() * p(it.row());
      rows[k] = std::abs(w) <= 0.5 * problem.tolerance;
    }
  std::vector<RowIndex>& members_f = work_->members;
  members(rows, members_f);
  if (members_f.size() < 2 || members_f.size() > settings_.polish_limit) return;
  SolverStats ignored;
  // A over the rows (dense: the polish is for small sets) and c over them, in the workspace.
  const auto n = static_cast<Eigen::Index>(members_f.size());
  std::vector<int>& position = work_->position;
  position.assign(static_cast<std::size_t>(a.rows()), -1);
  for (std::size_t i = 0; i < members_f.size(); ++i) position[members_f[i]] = static_cast<int>(i);
  Eigen::MatrixXd& sub = work_->dense;
  sub.setZero(n, n);
  Vector& rhs = work_->gathered;
  rhs.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    rhs(j) = c(members_f[static_cast<std::size_t>(j)]);
    for (SparseMatrix::InnerIterator it(a, members_f[static_cast<std::size_t>(j)]); it; ++it)
      if (const int i = position[static_cast<std::size_t>(it.row())]; i >= 0) sub(i, j) = it.value();
  }
  Vector& q = work_->solution;
  equalities_.solve_dense_matrix(sub, rhs, ignored, work_->ldlt, q);
  const double roundoff = kImpulseRoundoff * q.lpNorm<Eigen::Infinity>();
  for (std::size_t i = 0; i < members_f.size(); ++i)
    if (!problem.equality[members_f[i]] && q(static_cast<Eigen::Index>(i)) < -roundoff) return;
  if (!q.allFinite()) return;
  Vector& candidate = work_->candidate;
  candidate = p;
  for (std::size_t i = 0; i < members_f.size(); ++i)
    candidate(members_f[i]) = problem.equality[members_f[i]] ? q(static_cast<Eigen::Index>(i))
                                                            : std::max(0.0, q(static_cast<Eigen::Index>(i)));
  // Same velocities to rounding, or keep the basic solution.
  Vector& difference = work_->difference;
  difference = candidate - p;
  Vector& change = work_->change;
  change.noalias() = a * difference;
  if (change.lpNorm<Eigen::Infinity>() > 0.5 * problem.tolerance) return;
  p.swap(candidate);
  ++stats.polished;
}

}  // namespace impetus::ledas
