// The position correction after the velocity phase (impetus/resolution/common/resting.hpp): pseudo-impulses
// q ≥ 0 with A q ≥ target and complementarity move positions only.
#include "impetus/resolution/common/resting.hpp"
#include "island.hpp"
#include "lane.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace impetus {

namespace {
// Position-correction problems are in metres; a violation below this is rounding.
constexpr double kPositionTolerance = 1e-12;
}  // namespace

// The same complementarity problem as the complementary mode's impact, with the correction targets as
// right-hand side; joint rows hold (target 0) so the correction does not drag them. Only along normals:
// an island with friction leaves its tangent rows out (A restricted to the other rows), so the
// correction never pushes a body along a slope.
//
// solve_correction only reads the bodies (their masses and inertias, for the body-space form) and writes
// the island's correction buffers, the lane's correction solver and its position statistics, so it may run
// while the velocity phase works on the same island (solve_island); apply_correction moves the bodies
// after both.
bool LedasResolver::solve_correction(ledas::Island& island, std::span<const RigidBody> bodies, Lane& lane) {
  std::vector<ledas::RowIndex>& kept = island.kept;  // local rows of the correction problem (all but tangent rows)
  kept.clear();
  ledas::SparseMatrix& restricted = island.restricted;
  if (island.frictional) {
    for (std::size_t i = 0; i < island.rows.size(); ++i)
      if (island.role[i] != ledas::RowRole::tangent) kept.push_back(static_cast<ledas::RowIndex>(i));
    ledas::principal_submatrix(island.a, kept, restricted, lane.position);
  }
  const auto local = [&](std::size_t j) { return island.frictional ? kept[j] : j; };
  const std::size_t m = island.frictional ? kept.size() : island.rows.size();
  ledas::ComplementarityProblem& problem = island.correction;
  problem.workspace = &island.correction_work;
  problem.matrix = island.frictional ? &restricted : &island.a;
  problem.equality.assign(m, 0);
  problem.start.assign(m, 0);
  problem.groups.resize(m);
  for (std::size_t j = 0; j < m; ++j) problem.groups[j] = island.incidence.slots[local(j)];
  problem.rhs.setZero(static_cast<Eigen::Index>(m));
  problem.tolerance = kPositionTolerance;
  // Its start set (the rows overlapping beyond the slop) is a poor guess of its free set, which grows to
  // most rows as each push closes others (the 10,000-sphere heap's island: ~2,630 of ~2,870), and its
  // solver no longer shares the impact's analysis (solve_island): every row is analysed at once.
  problem.analyse_every_row = true;
  bool needed = false;
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t i = local(j);
    problem.equality[j] = island.equality[i];
    if (island.equality[i]) continue;
    const double t = resolution::correction_target(info_[island.rows[i]].depth, settings_.resting);
    problem.rhs(static_cast<Eigen::Index>(j)) = t;
    // q = 0 already meets a target within the problem's tolerance (w = −t ≥ −tolerance): a contact
    // overlapping by the slop plus rounding (a generated pyramid at rest) asks for no solve.
    problem.start[j] = t > kPositionTolerance;
    needed = needed || t > kPositionTolerance;
  }
  if (!needed) return false;
  problem.body_space = nullptr;
  if (ledas::wants_body_space(island, m, solver_settings_)) {
    ledas::assemble_body_space(rows_, island, island.frictional ? std::span<const ledas::RowIndex>(kept)
                                                                : std::span<const ledas::RowIndex>(), bodies,
                               island.correction_body_space);
    problem.body_space = &island.correction_body_space;
  }
  const std::uint64_t refused_before = lane.stats.position.refused;
  lane.correction_solver.solve_complementarity(problem, lane.stats.position, island.correction_solution);
  island.correction_refused = lane.stats.position.refused > refused_before;
  return true;
}

// The correction solve_correction found, bounded (below), applied to the bodies' positions.
void LedasResolver::apply_correction(ledas::Island& island, std::span<RigidBody> bodies, Lane& lane) {
  const ledas::ComplementarityProblem& problem = island.correction;
  const std::size_t m = static_cast<std::size_t>(problem.rhs.size());
  const auto local = [&](std::size_t j) { return island.frictional ? island.kept[j] : j; };
  double total_target = 0.0;  // Σ targets: the displacement bound's scale (resting.hpp)
  for (std::size_t j = 0; j < m; ++j)
    if (!problem.equality[j]) total_target += problem.rhs(static_cast<Eigen::Index>(j));
  ledas::Vector& q = island.correction_solution;
  // No correction moves a body absurdly far (conflicting targets: a body pinned deep in the ground).
  std::vector<const resolution::ImpulseRow*>& rows = island.correction_rows;
  rows.resize(m);
  for (std::size_t j = 0; j < m; ++j) rows[j] = &rows_[island.rows[local(j)]];
  const resolution::CorrectionBound bound = resolution::bound_correction(
      rows, std::span<double>(q.data(), m), resolution::kCorrectionBoundFactor * total_target, bodies);
  bool clamped = bound.scale < 1.0 || island.correction_refused;  // refused: clamped to 0
  // Nor may it open a joint: the joint rows hold with target 0, so a consistent correction leaves them
  // shut to rounding; conflicting targets (a body pinned deep in the ground) would drag the joint apart
  // and hand the next velocity phase an impossible target. The correction is scaled down until no joint
  // row opens by more than the slop.
  double opening = 0.0;
  if (std::find(problem.equality.begin(), problem.equality.end(), 1) != problem.equality.end()) {
    const ledas::Vector separation = *problem.matrix * q;
    for (std::size_t j = 0; j < m; ++j)
      if (problem.equality[j]) opening = std::max(opening, std::abs(separation(static_cast<Eigen::Index>(j))));
  }
  const double allowed = std::max(settings_.resting.slop, kPositionTolerance);
  double largest = bound.largest;
  if (opening > allowed) {
    const double scale = allowed / opening;
    q *= scale;
    largest *= scale;
    clamped = true;
  }
  if (clamped) ++lane.stats.corrections_clamped;
  lane.stats.largest_correction = std::max(lane.stats.largest_correction, largest);
  for (std::size_t j = 0; j < m; ++j)
    if (const double qj = q(static_cast<Eigen::Index>(j)); qj != 0.0)
      resolution::apply_row_displacement(*rows[j], qj, bodies);
}

}  // namespace impetus
