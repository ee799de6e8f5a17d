// The complementary mode on an island with friction (resolution/ledas/README.md, "Friction"): the
// inelastic frictional impact solved exactly and simultaneously (frictional_solver.hpp), then a
// restitution phase that is itself a frictional impact, scaled back if it would raise the kinetic energy.
#include "island.hpp"
#include "lane.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <algorithm>
#include <cmath>

namespace impetus {

namespace {
// Relative accuracy of the frictional solve: its natural-map residual ≤ this × ‖q‖ ...
constexpr double kFrictionalRelativeTolerance = 1e-10;
// ... or ≤ this, absolute, when q is tiny.
constexpr double kFrictionalAbsoluteTolerance = 1e-12;
// Position-level joint re-targeting rounds of the inelastic phase at most (each halves the gap or stops).
constexpr std::uint64_t kJointRounds = 16;
}  // namespace

using ledas::Vector;

// Sets island.friction_start to the last step's impulses of the island's rows (0 where a contact is new);
// returns whether any is not 0.
bool LedasResolver::warm_start(ledas::Island& island) const {
  Vector& r = island.friction_start;
  r.resize(static_cast<Eigen::Index>(island.rows.size()));
  for (std::size_t i = 0; i < island.rows.size(); ++i) r(static_cast<Eigen::Index>(i)) = row_warm_[island.rows[i]];
  return r.any();
}

// Keeps the island's frictional contacts' inelastic impulses for the next step's warm start.
void LedasResolver::remember_impulses(Lane& lane, const ledas::Island& island, std::span<const Contact> contacts) const {
  for (std::size_t i = 0; i < island.rows.size(); ++i) {
    if (!island.normal_row(i) || !(island.mu[i] > 0.0)) continue;
    const auto ei = static_cast<Eigen::Index>(i);
    const Contact& c = contacts[static_cast<std::size_t>(info_[island.rows[i]].contact)];
    ContactImpulse p;
    p.normal = island.impulse_inelastic(ei);
    p.tangent = island.impulse_inelastic(ei + 1) * rows_[island.rows[i + 1]].normal +
                island.impulse_inelastic(ei + 2) * rows_[island.rows[i + 2]].normal;
    lane.remembered.emplace_back(ContactKey{c.a, c.b, c.feature}, p);
  }
}

// Solves the island's frictional problem u = A r + q (A = W over the island's rows, q = v − target),
// tried first from island.friction_start if `warm`, into island.friction_impulse (returned). The problem
// is rebuilt in the island's buffers: no allocation when the island's size did not change.
Vector& LedasResolver::solve_frictional(Lane& lane, ledas::Island& island, const Vector& v, const Vector& target,
                                        bool warm) {
  ledas::FrictionalProblem& problem = island.friction;
  problem.start = warm ? &island.friction_start : nullptr;
  problem.w = &island.a;
  problem.q = v - target;
  problem.role = island.role;
  problem.mu = island.mu;
  problem.dofs = 6 * island.bodies.size();
  problem.tolerance = std::max(kFrictionalRelativeTolerance * problem.q.norm(), kFrictionalAbsoluteTolerance);
  problem.workspace = &island.friction_work;
  lane.friction.solve(problem, lane.stats.friction, island.friction_impulse);
  return island.friction_impulse;
}

// Applies the impulses p on the island's rows (eq. 3 per row, tangent rows along t1, t2) and adds the
// tangent rows' work Σ p_t (v_t⁻ + v_t⁺)/2 to friction_work (exact for one simultaneous impulse: ΔE_kin =
// pᵀ(v⁻ + v⁺)/2 row by row).
void LedasResolver::apply_island_impulse(ledas::Island& island, const Vector& p, std::span<RigidBody> bodies,
                                         Lane& lane) {
  const Vector& before = island.velocity_before = current_velocities(island, bodies);
  for (std::size_t i = 0; i < island.rows.size(); ++i)
    if (const double pi = p(static_cast<Eigen::Index>(i)); pi != 0.0)
      resolution::apply_row_impulse(rows_[island.rows[i]], pi, bodies);
  island.velocity_current = false;
  const Vector& after = current_velocities(island, bodies);
  double work = 0.0;
  for (std::size_t i = 0; i < island.rows.size(); ++i)
    if (island.role[i] == ledas::RowRole::tangent) {
      const auto ei = static_cast<Eigen::Index>(i);
      work += 0.5 * p(ei) * (before(ei) + after(ei));
    }
  lane.counters.friction_work += work;
  island.impulse_total += p;
}

// Phase 1: the inelastic frictional impact (every contact's mode found together), re-solved while
// position-level joints re-target. Phase 2, with restitution: a frictional impact whose normal targets
// are e |v_n⁻| (Newton's rule, simultaneously), which with friction can raise the kinetic energy (Kane's
// rod); its impulse is then scaled by the largest α ≤ 1 that keeps the energy at or below its pre-impact
// value (ΔE is quadratic in α), so no impact creates energy for any e ≤ 1.
void LedasResolver::velocity_frictional(ledas::Island& island, std::span<RigidBody> bodies, Lane& lane) {
  const std::size_t m = island.rows.size();
  // W's factored form, for the interior point of an island with more rows than body coordinates (a
  // pyramid, a stack: cone_qp.hpp), assembled when that first asks. Positions do not change within the
  // step, so it holds for every round and both phases; the problem forgets it on return.
  struct Source final : ledas::BodySpaceSource {
    std::span<const resolution::ImpulseRow> rows;
    ledas::Island* island = nullptr;
    std::span<const RigidBody> bodies;
    bool assembled = false;
    const ledas::BodySpace& body_space() override {
      if (!assembled) ledas::assemble_body_space(rows, *island, {}, bodies, island->body_space);
      assembled = true;
      return island->body_space;
    }
  } source;
  source.rows = rows_;
  source.island = &island;
  source.bodies = bodies;
  struct Forget {
    ledas::FrictionalProblem& problem;
    ~Forget() { problem.body_space = nullptr; }
  } forget{island.friction};
  island.friction.body_space = ledas::wants_body_space(island, m, solver_settings_) ? &source : nullptr;
  const Vector& v0 = island.velocity_start = current_velocities(island, bodies);
  const double energy0 = ledas::kinetic_energy(bodies, island.bodies);
  bool needed = false;
  for (std::size_t i = 0; i < m; ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (island.role[i] == ledas::RowRole::equality) needed = needed || std::abs(v0(ei) - island.target(ei)) > settings_.tolerance;
    if (!island.normal_row(i)) continue;
    const bool touching = v0(ei) <= island.target(ei) + settings_.tolerance;
    if (touching) island.entered[i] = 1;
    needed = needed || v0(ei) < island.target(ei) - settings_.tolerance;
  }
  for (std::uint64_t round = 0; round < kJointRounds; ++round) {
    const Vector& v = current_velocities(island, bodies);
    const bool refine = ledas::retarget_joints(island, rows_, info_, v, bodies);
    if (round > 0 && !refine) break;
    if (round == 0 && !needed && !refine) return;
    const std::uint64_t failures = lane.stats.friction.non_converged;
    const bool warm = round == 0 && settings_.warm_start && warm_start(island);
    Vector& r = solve_frictional(lane, island, v, island.target, warm);
    // A problem left unsolved (counted) still must not create energy: its best iterate is scaled back
    // so that ΔE = rᵀv + ½ rᵀA r ≤ 0 (rows' velocities v before it).
    if (lane.stats.friction.non_converged != failures) {
      island.product.noalias() = island.a * r;
      const double linear = r.dot(v), quadratic = 0.5 * r.dot(island.product);
      if (linear + quadratic > 0.0) r *= linear < 0.0 && quadratic > 0.0 ? std::min(1.0, -linear / quadratic) : 0.0;
    }
    for (std::size_t i = 0; i < m; ++i)
      if (r(static_cast<Eigen::Index>(i)) != 0.0 && island.normal_row(i)) island.entered[i] = 1;
    island.impulse_inelastic += r;
    apply_island_impulse(island, r, bodies, lane);
    ++island.rounds;
  }
  const Vector& v1 = island.velocity_inelastic = current_velocities(island, bodies);
  island.measure_complementarity(v1, island.target);
  if (!island.bouncing()) return;

  // Phase 2: normal targets e |v_n⁻| where the contact bounces, the step's targets elsewhere.
  Vector& target = island.bounce_target = island.target;
  bool bounce = false;
  for (std::size_t i = 0; i < m; ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (!island.normal_row(i) || island.restitution(ei) == 0.0 || island.impulse_inelastic(ei) <= 0.0) continue;
    target(ei) = std::max(target(ei), island.restitution(ei) * std::max(0.0, -v0(ei)));
    bounce = bounce || v1(ei) < target(ei) - settings_.tolerance;
  }
  if (!bounce) return;
  Vector& r = solve_frictional(lane, island, v1, target, false);
  // ΔE(α) = α rᵀv₁ + ½ α² rᵀ A r; the budget is what phase 1 dissipated.
  island.product.noalias() = island.a * r;
  const double linear = r.dot(v1), quadratic = 0.5 * r.dot(island.product);
  const double budget = std::max(0.0, energy0 - ledas::kinetic_energy(bodies, island.bodies));
  if (linear + quadratic > budget + 0.5 * ledas::kRoundoff * energy0) {  // beyond rounding
    const double alpha = quadratic > 0.0
                             ? (-linear + std::sqrt(std::max(0.0, linear * linear + 4.0 * quadratic * budget))) /
                                   (2.0 * quadratic)
                             : (linear < 0.0 ? 1.0 : 0.0);
    r *= std::clamp(alpha, 0.0, 1.0);
    ++lane.stats.restitution_capped;
  }
  apply_island_impulse(island, r, bodies, lane);
  ++island.rounds;
}

}  // namespace impetus
