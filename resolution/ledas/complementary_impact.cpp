// The complementary mode: each round solves the exact inelastic impact (a linear complementarity
// problem over the approaching and touching rows, island_solver.hpp), then applies (1 + e) p.
#include "island.hpp"
#include "lane.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <cmath>

namespace impetus {

using ledas::Vector;
// The exact impact (a linear complementarity problem), then (1 + e) p. Restitution can make a contact
// approach again (a separating contact pushed shut gets −e v_n⁻), so the round repeats while any does.
void LedasResolver::velocity_complementary(ledas::Island& island, std::span<RigidBody> bodies, Lane& lane) {
  const std::size_t m = island.rows.size();
  ledas::ComplementarityProblem& problem = island.impact;
  problem.workspace = &island.impact_work;
  problem.matrix = &island.a;
  problem.equality.assign(island.equality.begin(), island.equality.end());
  problem.start.assign(m, 0);
  problem.groups.assign(island.incidence.slots.begin(), island.incidence.slots.end());
  problem.tolerance = settings_.tolerance;
  problem.body_space = nullptr;
  if (ledas::wants_body_space(island, m, solver_settings_)) {
    ledas::assemble_body_space(rows_, island, {}, bodies, island.body_space);
    problem.body_space = &island.body_space;
  }
  const std::uint64_t failed_before = lane.stats.velocity.infeasible, unconverged_before = lane.stats.velocity.non_converged;
  for (std::uint64_t round = 0;; ++round) {
    const Vector& v = current_velocities(island, bodies);  // (finish_round changes it: not used after)
    bool needed = ledas::retarget_joints(island, rows_, info_, v, bodies) && round > 0;
    Vector& target = island.impact_target;
    target = island.target;
    for (std::size_t i = 0; i < m; ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      if (island.equality[i]) {
        problem.start[i] = 1;
        needed = needed || (round == 0 && std::abs(v(ei) - island.target(ei)) > settings_.tolerance);
        continue;
      }
      const bool touching = v(ei) <= island.target(ei) + settings_.tolerance;  // approaching or touching
      problem.start[i] = touching;
      needed = needed || v(ei) < island.target(ei) - settings_.tolerance;
      target(ei) = ledas::solve_target(island.target(ei), touching, island.restitution(ei));
      if (touching) island.entered[i] = 1;
    }
    if (!needed) break;
    // Rounds are bounded by work too: a round repeats only because restitution made a contact approach
    // again; one whose solve failed (no solution, or stopped unconverged) would fail the same way again.
    if (round == settings_.max_rounds || round == ledas::work_budget(m, solver_settings_)) {
      ++lane.counters.non_converged;
      break;
    }
    if (round > 0 &&
        (lane.stats.velocity.infeasible > failed_before || lane.stats.velocity.non_converged > unconverged_before))
      break;  // counted by the solver already
    if (settings_.start_set == LedasStartSet::impact) {
      add_closable_gaps(island, v, problem.start);
      narrow_start_set(lane, island, v, problem.start);
    }
    problem.rhs = target - v;
    const auto solves = [&] { return lane.stats.velocity.iterations + lane.stats.velocity.interior_point_steps; };
    const std::uint64_t before = solves();
    Vector& p = island.impact_solution;
    lane.solver.solve_complementarity(problem, lane.stats.velocity, p);
    lane.stats.systems += solves() - before;
    for (std::size_t i = 0; i < m; ++i)
      if (p(static_cast<Eigen::Index>(i)) != 0.0) island.entered[i] = 1;
    finish_round(island, p, target, bodies);
    ++island.rounds;
  }
}

// The complementary mode's start set, first half (README.md, "The start set"): a separating contact the
// impact can close joins the touching ones: one whose slack v_n − target is at most the largest approach
// deficit target − v_n of the island's contacts, the speed the impact takes out of the approaching
// bodies and can pass on. Under gravity every body gains the same −g dt, so only the contacts with the
// ground approach; a pile whose layers drift apart slowly (a frictionless pyramid spreading) would
// otherwise join one layer per active-set iteration as each lands on the one below, where now the first
// solve takes them all.
void LedasResolver::add_closable_gaps(const ledas::Island& island, const Vector& v, std::vector<char>& start) const {
  const std::size_t m = island.rows.size();
  double reach = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (!island.equality[i]) reach = std::max(reach, island.target(ei) - v(ei));
  }
  if (reach <= settings_.tolerance) return;
  for (std::size_t i = 0; i < m; ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (!start[i] && !island.equality[i] && v(ei) - island.target(ei) <= reach)
      start[i] = 1;
  }
}

// The start set, second half: of the touching contacts, only those
// that can pass the impact on. The impact's sources are the movable bodies of the approaching contacts
// and of the joint rows off their target; every movable body's distance from them is counted in hops
// over the rows of the start set (breadth-first). A touching contact between two movable bodies at the
// same distance runs across the front along which the impact travels: the bodies behind a front are
// pushed apart along it, not together (a pyramid's horizontal contacts, boxes side by side on a floor),
// so such a contact almost always separates. Started in, it is a redundant row the first solve must
// factorize (a pyramid's horizontal contacts carry most of the factorization's fill) and the search
// must then release; left out, it joins at the next iteration if it would approach. Contacts with a
// fixed body and contacts between bodies the impact does not reach keep their places (in; out: nothing
// pushes them).
void LedasResolver::narrow_start_set(Lane& lane, const ledas::Island& island, const Vector& v, std::vector<char>& start) {
  const std::size_t m = island.rows.size();
  const auto& slots = island.incidence.slots;
  const auto driving = [&](std::size_t i) {
    const auto ei = static_cast<Eigen::Index>(i);
    return island.equality[i] ? std::abs(v(ei) - island.target(ei)) > settings_.tolerance
                              : v(ei) < island.target(ei) - settings_.tolerance;
  };
  lane.hops.assign(island.bodies.size(), -1);
  lane.queue.clear();
  for (std::size_t i = 0; i < m; ++i)
    if (driving(i))
      for (const std::int32_t s : slots[i])
        if (s >= 0 && lane.hops[static_cast<std::size_t>(s)] < 0) {
          lane.hops[static_cast<std::size_t>(s)] = 0;
          lane.queue.push_back(s);
        }
  for (std::size_t head = 0; head < lane.queue.size(); ++head) {
    const std::int32_t s = lane.queue[head];
    for (const std::uint32_t i : island.incidence.rows_of(s)) {
      if (!start[i]) continue;
      const std::int32_t other = slots[i][0] == s ? slots[i][1] : slots[i][0];
      if (other >= 0 && lane.hops[static_cast<std::size_t>(other)] < 0) {
        lane.hops[static_cast<std::size_t>(other)] = lane.hops[static_cast<std::size_t>(s)] + 1;
        lane.queue.push_back(other);
      }
    }
  }
  for (std::size_t i = 0; i < m; ++i) {
    const std::int32_t a = slots[i][0], b = slots[i][1];
    if (start[i] && !island.equality[i] && a >= 0 && b >= 0 &&
        lane.hops[static_cast<std::size_t>(a)] == lane.hops[static_cast<std::size_t>(b)] && !driving(i))
      start[i] = 0;
  }
}

}  // namespace impetus
