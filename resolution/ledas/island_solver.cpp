// The island solver: the two solvers it joins (equality_solver.hpp, complementarity_solver.hpp) and
// principal submatrices.
#include "impetus/resolution/ledas/island_solver.hpp"
#include "complementarity_solver.hpp"
#include "equality_solver.hpp"
#include "solver_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus::ledas {

IslandSolver::IslandSolver(SolverSettings settings)
    : settings_(settings), equalities_(std::make_unique<EqualitySolver>(settings_)),
      complementarity_(std::make_unique<ComplementaritySolver>(settings_, *equalities_)) {}
IslandSolver::~IslandSolver() = default;

namespace {
// Active-set solves allowed per row of a complementarity problem (work_budget), and the floor for
// small problems.
constexpr std::uint64_t kSolvesPerRow = 100;
constexpr std::uint64_t kMinSolves = 100;
// Rows whose A_kk differ by more than this factor (a 10¹²:1 mass ratio) are scaled before the solve.
constexpr double kScaleSpread = 1e8;
// A complementarity answer whose velocity changes exceed the asked ones by this factor is refused.
constexpr double kAbsurdGain = 1e6;
}  // namespace

std::uint64_t work_budget(std::size_t rows, const SolverSettings& settings) {
  const std::uint64_t size_bound = kMinSolves + kSolvesPerRow * static_cast<std::uint64_t>(rows);
  return std::min(settings.max_iterations, size_bound);
}

SparseMatrix principal_submatrix(const SparseMatrix& a, std::span<const RowIndex> subset) {
  SparseMatrix out;
  std::vector<int> position;
  principal_submatrix(a, subset, out, position);
  return out;
}

// Written in compressed form directly: column j is column subset[j] of `a` without the rows outside the
// subset, in increasing order because the subset is.
void principal_submatrix(const SparseMatrix& a, std::span<const RowIndex> subset, SparseMatrix& out,
                         std::vector<int>& position) {
  position.assign(static_cast<std::size_t>(a.rows()), -1);
  for (std::size_t i = 0; i < subset.size(); ++i) position[subset[i]] = static_cast<int>(i);
  const auto n = static_cast<Eigen::Index>(subset.size());
  out.resize(n, n);
  std::size_t nonzeros = 0;
  for (const RowIndex k : subset) nonzeros += static_cast<std::size_t>(a.outerIndexPtr()[k + 1] - a.outerIndexPtr()[k]);
  out.resizeNonZeros(static_cast<Eigen::Index>(nonzeros));
  int q = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    out.outerIndexPtr()[j] = q;
    for (SparseMatrix::InnerIterator it(a, subset[static_cast<std::size_t>(j)]); it; ++it)
      if (const int i = position[static_cast<std::size_t>(it.row())]; i >= 0) {
        out.innerIndexPtr()[q] = i;
        out.valuePtr()[q] = it.value();
        ++q;
      }
  }
  out.outerIndexPtr()[n] = q;
  out.resizeNonZeros(q);
}

Vector IslandSolver::solve_subset(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset,
                                  SolverStats& stats) {
  Vector p = Vector::Zero(a.rows());
  equalities_->solve_subset(a, c, subset, p, stats);
  return p;
}

void IslandSolver::solve_subset(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset, Vector& p,
                                SolverStats& stats) {
  equalities_->solve_subset(a, c, subset, p, stats);
}

// A 10¹²:1 mass ratio puts rows of A_kk ~ 1e-12 next to rows of A_kk ~ 1: below the rank tolerance
// (relative to max A_kk) the light rows' partners look like "nothing movable", and the active set cycles
// on rounding. The problem is invariant under the diagonal scaling p = S p̂, S = diag(A_kk)^-½ (p ≥ 0
// ⇔ p̂ ≥ 0, ŵ = S w): solved as Â = S A S, ĉ = S c, whose diagonal is 1 wherever a body can move. The
// tolerance becomes tolerance · min S (so w ≥ −tolerance still holds on every row). Only for spreads
// beyond kScaleSpread: ordinary problems are solved exactly as before, bit for bit.
Vector IslandSolver::solve_complementarity(const ComplementarityProblem& problem, SolverStats& stats) {
  Vector p;
  solve_complementarity(problem, stats, p);
  return p;
}

void IslandSolver::solve_complementarity(const ComplementarityProblem& problem, SolverStats& stats, Vector& p) {
  solve_balanced(problem, stats, p);
  // An answer whose velocity changes A p dwarf every change the problem asks for (‖c‖) is rounding
  // blown up along a null direction of conflicting targets (a body pinned by a joint deep inside the
  // ground: the joint's and the contact's rows are parallel), not physics: refused, nothing applied.
  const double asked = problem.rhs.lpNorm<Eigen::Infinity>() + problem.tolerance;
  Vector& change = problem.workspace ? problem.workspace->check : check_;
  if (p.size() > 0) change.noalias() = *problem.matrix * p;
  if (p.size() > 0 && !(change.lpNorm<Eigen::Infinity>() <= kAbsurdGain * asked)) {
    ++stats.refused;
    ++stats.non_converged;
    p.setZero();
  }
}

void IslandSolver::solve_balanced(const ComplementarityProblem& problem, SolverStats& stats, Vector& p) {
  const SparseMatrix& a = *problem.matrix;
  double hi = 0.0, lo = std::numeric_limits<double>::infinity();
  for (Eigen::Index k = 0; k < a.rows(); ++k)
    if (const double d = a.coeff(k, k); d > 0.0 && std::isfinite(d)) hi = std::max(hi, d), lo = std::min(lo, d);
  if (!(hi > kScaleSpread * lo)) {
    complementarity_->solve(problem, stats, p);
    return;
  }
  Vector scale = Vector::Ones(a.rows());
  for (Eigen::Index k = 0; k < a.rows(); ++k)
    if (const double d = a.coeff(k, k); d > 0.0 && std::isfinite(d)) scale(k) = 1.0 / std::sqrt(d);
  const SparseMatrix scaled = scale.asDiagonal() * a * scale.asDiagonal();
  ComplementarityProblem balanced = problem;
  balanced.matrix = &scaled;
  balanced.body_space = nullptr;  // G would need the same scaling; the search solves these
  balanced.rhs = scale.cwiseProduct(problem.rhs);
  balanced.tolerance = problem.tolerance / std::sqrt(hi);
  complementarity_->solve(balanced, stats, p);
  p = scale.cwiseProduct(p);
}

void add(SolverStats& into, const SolverStats& part) {
  into.closed_form += part.closed_form;
  into.dense += part.dense;
  into.sparse += part.sparse;
  into.updated += part.updated;
  into.singular += part.singular;
  into.inconsistent += part.inconsistent;
  into.symbolic_analyses += part.symbolic_analyses;
  into.symbolic_reused += part.symbolic_reused;
  into.iterations += part.iterations;
  into.released += part.released;
  into.added += part.added;
  into.non_converged += part.non_converged;
  into.work_limited += part.work_limited;
  into.refused += part.refused;
  into.infeasible += part.infeasible;
  into.nan_caught += part.nan_caught;
  into.polished += part.polished;
  into.proximal += part.proximal;
  into.refinements += part.refinements;
  into.sharpened += part.sharpened;
  into.interior_point_steps += part.interior_point_steps;
  into.interior_point_solved += part.interior_point_solved;
  into.interior_point_loose += part.interior_point_loose;
}

}  // namespace impetus::ledas
