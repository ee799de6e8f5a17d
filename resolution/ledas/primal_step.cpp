// The primal active-set step (primal_step.hpp): one definition for the proximal search and the fallback.
#include "primal_step.hpp"
#include "solver_internal.hpp"

#include <algorithm>

namespace impetus::ledas {

RatioTest ratio_test(const Vector& p, const Vector& direction, const std::vector<char>& free_rows,
                     const std::vector<char>& equality, double max_step) {
  const std::size_t m = free_rows.size();
  RatioTest out{max_step, m};
  for (std::size_t k = 0; k < m; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    if (!free_rows[k] || equality[k] || !(direction(i) < 0.0)) continue;
    const double ratio = std::max(0.0, p(i)) / -direction(i);
    if (ratio < out.step) out.step = ratio, out.blocking = k;
  }
  return out;
}

void step_and_release(Vector& p, const Vector& direction, const RatioTest& test, const Vector& falling, double margin,
                      std::vector<char>& free_rows, const std::vector<char>& equality, SolverStats& stats) {
  p += test.step * direction;
  const double floor = kImpulseRoundoff * p.lpNorm<Eigen::Infinity>();
  for (std::size_t k = 0; k < free_rows.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    if (free_rows[k] && !equality[k] && (k == test.blocking || (falling(i) < -margin && p(i) <= floor))) {
      free_rows[k] = 0;
      p(i) = 0.0;
      ++stats.released;
    }
  }
}

void clamp_to_free_set(Vector& p, const std::vector<char>& free_rows, const std::vector<char>& equality) {
  for (std::size_t k = 0; k < free_rows.size(); ++k)
    if (!equality[k]) p(static_cast<Eigen::Index>(k)) = free_rows[k] ? std::max(p(static_cast<Eigen::Index>(k)), 0.0) : 0.0;
}

}  // namespace impetus::ledas
