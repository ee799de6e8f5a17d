// The position correction after the velocity phase (impetus/resolution/common/resting.hpp): pseudo-impulses
// q ≥ 0 with A q ≥ target and complementarity move positions only.
#include "impetus/resolution/common/resting.hpp"
#include "island.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

namespace impetus {

namespace {
// Position-correction problems are in metres; a violation below this is rounding.
constexpr double kPositionTolerance = 1e-12;
}  // namespace

// The same complementarity problem as the complementary mode's impact, with the correction targets as
// right-hand side; joint rows hold (target 0) so the correction does not drag them.
void LedasResolver::correct_positions(ledas::Island& island, std::span<RigidBody> bodies) {
  const std::size_t m = island.rows.size();
  ledas::ComplementarityProblem problem;
  problem.matrix = &island.a;
  problem.equality = island.equality;
  problem.start.resize(m);
  problem.rhs = ledas::Vector::Zero(static_cast<Eigen::Index>(m));
  problem.tolerance = kPositionTolerance;
  bool needed = false;
  for (std::size_t i = 0; i < m; ++i) {
    if (island.equality[i]) continue;
    const double t = resolution::correction_target(info_[island.rows[i]].depth, settings_.resting);
    problem.rhs(static_cast<Eigen::Index>(i)) = t;
    // q = 0 already meets a target within the problem's tolerance (w = −t ≥ −tolerance): a contact
    // overlapping by the slop plus rounding (a generated pyramid at rest) asks for no solve.
    problem.start[i] = t > kPositionTolerance;
    needed = needed || t > kPositionTolerance;
  }
  if (!needed) return;
  const ledas::Vector q = solver_.solve_complementarity(problem, stats_.position);
  for (std::size_t i = 0; i < m; ++i)
    if (const double qi = q(static_cast<Eigen::Index>(i)); qi != 0.0)
      resolution::apply_row_displacement(rows_[island.rows[i]], qi, bodies);
}

}  // namespace impetus
