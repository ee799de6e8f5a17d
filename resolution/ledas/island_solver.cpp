// The island solver: the two solvers it joins (equality_solver.hpp, complementarity_solver.hpp) and
// principal submatrices.
#include "impetus/resolution/ledas/island_solver.hpp"
#include "complementarity_solver.hpp"
#include "equality_solver.hpp"
#include "solver_internal.hpp"

#include <algorithm>

namespace impetus::ledas {

IslandSolver::IslandSolver(SolverSettings settings)
    : settings_(settings), equalities_(std::make_unique<EqualitySolver>(settings_)),
      complementarity_(std::make_unique<ComplementaritySolver>(settings_, *equalities_)) {}
IslandSolver::~IslandSolver() = default;

SparseMatrix principal_submatrix(const SparseMatrix& a, std::span<const RowIndex> subset) {
  std::vector<int> position(static_cast<std::size_t>(a.rows()), -1);
  for (std::size_t i = 0; i < subset.size(); ++i) position[subset[i]] = static_cast<int>(i);
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t j = 0; j < subset.size(); ++j)
    for (SparseMatrix::InnerIterator it(a, subset[j]); it; ++it)
      if (const int i = position[static_cast<std::size_t>(it.row())]; i >= 0)
        entries.emplace_back(i, static_cast<int>(j), it.value());
  const auto n = static_cast<Eigen::Index>(subset.size());
  SparseMatrix out(n, n);
  out.setFromTriplets(entries.begin(), entries.end());
  out.makeCompressed();
  return out;
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

Vector IslandSolver::solve_complementarity(const ComplementarityProblem& problem, SolverStats& stats) {
  return complementarity_->solve(problem, stats);
}

}  // namespace impetus::ledas
