#pragma once
/// \file
/// Internals shared by the island solver's source files (equality_solver.cpp, complementarity.cpp,
/// complementarity_fallback.cpp, primal_step.cpp): the active-set loop's state and small helpers. Not
/// installed, not for tests.

#include "bordered_update.hpp"
#include "complementarity_solver.hpp"
#include "impetus/resolution/ledas/island_solver.hpp"
#include "impetus/resolution/ledas/masked_ldlt.hpp"

#include <memory>
#include <span>
#include <vector>

namespace impetus::ledas {

// An impulse this far below zero, relative to the largest one, is rounding, not a pulling impulse.
inline constexpr double kImpulseRoundoff = 1e-12;

/// One active-set loop (solve_complementarity): its masked factorization of (A + εI)_BB and the
/// bordered update against it.
struct ComplementaritySolver::ActiveLoop {
  std::unique_ptr<MaskedLdlt> factor;
  bool factored = false;
  double floor = 0.0;         // A_kk at or below this: nothing movable behind row k
  bool singular = false;      // a factorization met a redundant row (pivot ≈ the shift)
  std::span<const std::array<std::int32_t, 2>> groups;  // the problem's, for the analysis (may be empty)
  std::vector<char> in_base;  // rows B of the last factorization (free and not dropped)
  BorderedUpdate* update = nullptr;  // solves for active sets near B without refactoring (the workspace's)
};

/// v restricted to `rows`, in their order.
inline Vector gather(const Vector& v, std::span<const RowIndex> rows) {
  Vector out(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) out(static_cast<Eigen::Index>(i)) = v(rows[i]);
  return out;
}

/// The indices k with flags[k] set, increasing, into `out` (its storage reused).
inline void members(const std::vector<char>& flags, std::vector<RowIndex>& out) {
  out.clear();
  for (std::size_t k = 0; k < flags.size(); ++k)
    if (flags[k]) out.push_back(static_cast<RowIndex>(k));
}
/// The same, returned.
inline std::vector<RowIndex> members(const std::vector<char>& flags) {
  std::vector<RowIndex> out;
  members(flags, out);
  return out;
}

}  // namespace impetus::ledas
