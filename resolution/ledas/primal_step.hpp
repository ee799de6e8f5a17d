#pragma once
/// \file
/// The primal active-set step of a complementarity problem (island_solver.hpp), shared by the proximal
/// search (complementarity.cpp) and the minimum-norm fallback (complementarity_fallback.cpp): the ratio
/// test along a direction, the move, the release of the rows that reached zero, and the final clamp of
/// the impulses to the free set.

#include "impetus/resolution/ledas/island_solver.hpp"

#include <cstddef>
#include <vector>

namespace impetus::ledas {

/// Ratio test: the largest step t ≤ max_step (1 for a step towards a minimizer, ∞ along a null
/// direction) that keeps p + t·direction ≥ 0 on every free inequality row (free_rows[k] and not
/// equality[k]); `blocking` is the row that stops it first (the lowest index among ties), or the row
/// count when no row does.
struct RatioTest {
  double step = 0.0;
  std::size_t blocking = 0;
};
RatioTest ratio_test(const Vector& p, const Vector& direction, const std::vector<char>& free_rows,
                     const std::vector<char>& equality, double max_step);

/// Moves p by `test.step · direction` and releases from the free set (p_k = 0, counted in
/// stats.released) the blocking row and every free inequality row that is falling (falling(k) < −margin)
/// and has reached zero (p_k ≤ 1e-12 · max |p|, rounding).
void step_and_release(Vector& p, const Vector& direction, const RatioTest& test, const Vector& falling, double margin,
                      std::vector<char>& free_rows, const std::vector<char>& equality, SolverStats& stats);

/// Clamps the impulses to the free set: on inequality rows, max(p_k, 0) for a free row, 0 for a row at
/// zero; equality rows keep theirs.
void clamp_to_free_set(Vector& p, const std::vector<char>& free_rows, const std::vector<char>& equality);

}  // namespace impetus::ledas
