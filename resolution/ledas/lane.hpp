#pragma once
/// \file
/// One worker's share of a resolve() (private: not installed): the solvers with their caches of symbolic
/// analyses, the statistics and counters of the islands it solved, its scratch, and the warm starts it
/// keeps for the next step. The lanes of a step run in parallel; what one lane computes depends only on
/// the islands dealt to it (ledas.hpp, LedasResolver::kLanes), never on which thread runs it.

#include "island.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace impetus {

struct LedasResolver::Lane {
  explicit Lane(const ledas::SolverSettings& settings) : solver(settings), correction_solver(settings) {}

  // The velocity phase's solver and the position correction's, each with its own caches: the two may
  // solve one island at once (LedasResolver::solve_island), and a correction solved by its own solver is
  // the same whether it ran alongside the impact or after it.
  ledas::IslandSolver solver;
  ledas::IslandSolver correction_solver;
  ledas::FrictionalSolver friction;
  LedasStats stats;            // this step's, added into the resolver's in lane order
  ResolverCounters counters;   // likewise
  std::vector<std::int32_t> hops, queue;  // narrow_start_set's distances and search queue (reused)
  std::vector<std::pair<ContactKey, ContactImpulse>> remembered;  // next step's warm starts, island order
  // The islands' working data, the lane's j-th island of a step in islands[j]: kept from step to step, so
  // that a stable contact pattern is solved in buffers of the right sizes, without allocating.
  std::vector<ledas::Island> islands;
  std::size_t islands_used = 0;  // this step's
  std::vector<int> position;  // correct_positions' scratch (principal_submatrix)
  ledas::Island& next_island() {
    if (islands_used == islands.size()) islands.emplace_back();
    return islands[islands_used++];
  }
};

}  // namespace impetus
