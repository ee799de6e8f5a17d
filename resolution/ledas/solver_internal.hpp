#pragma once
/// \file
/// Internals shared by the island solver's source files (island_solver.cpp: set-up and caches;
/// equality_solve.cpp: the paper mode's equalities; complementarity.cpp: the proximal active set;
/// complementarity_fallback.cpp: the minimum-norm fallback and polish). Not installed, not for tests.

#include "ledas/island_solver.hpp"

#include <Eigen/SparseCholesky>

#include <span>
#include <vector>

namespace impetus::ledas {

// An impulse this far below zero, relative to the largest one, is rounding, not a pulling impulse.
inline constexpr double kImpulseRoundoff = 1e-12;

/// A sparse LDLᵀ (Eigen SimplicialLDLT, AMD ordering) with the pattern its symbolic analysis is for.
struct IslandSolver::Factor {
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
  std::vector<int> outer, inner;  // the sparsity pattern the symbolic analysis belongs to
};

/// v restricted to `rows`, in their order.
inline Vector gather(const Vector& v, std::span<const RowIndex> rows) {
  Vector out(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) out(static_cast<Eigen::Index>(i)) = v(rows[i]);
  return out;
}

/// The indices k with flags[k] set, increasing.
inline std::vector<RowIndex> members(const std::vector<char>& flags) {
  std::vector<RowIndex> out;
  for (std::size_t k = 0; k < flags.size(); ++k)
    if (flags[k]) out.push_back(static_cast<RowIndex>(k));
  return out;
}

}  // namespace impetus::ledas
