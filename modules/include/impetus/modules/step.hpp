#pragma once
/// \file
/// What every module is told about the current step, and the counters each module reports back.
/// Counters are reset by the world before each step; a module only adds to its own.

#include "impetus/core/math.hpp"

#include <algorithm>
#include <cstdint>

namespace impetus {

/// The step being taken (read-only for modules).
struct StepContext {
  double dt = 1e-3;                      ///< time step (s)
  Vec3 gravity{0.0, 0.0, -9.81};         ///< m/s²
  std::uint64_t step = 0;                ///< index of this step (0 for the first)
  double time = 0.0;                     ///< simulated time at the start of the step (s)
};

/// Integrator counters for one step.
struct IntegratorCounters {
  std::uint64_t bodies = 0;          ///< movable bodies advanced
  std::uint64_t orthonormalized = 0; ///< rotation matrices re-orthonormalized
};

/// Detector counters for one step.
struct DetectorCounters {
  std::uint64_t pairs_tested = 0;      ///< candidate pairs from the broadphase
  std::uint64_t narrowphase_calls = 0; ///< exact shape-pair tests
  std::uint64_t contacts = 0;          ///< contacts produced
  std::uint64_t contacts_dropped = 0;  ///< contacts rejected (NaN or zero normal, duplicates, manifold reduction)
  /// Non-zero when the broadphase found more candidate pairs than the detector's pair limit allows (a
  /// pathological scene: many bodies generated at one point): the limit, and the detection is refused
  /// (no contacts; the world fails the step, naming `crowded_body`). Never an allocation of every pair.
  std::uint64_t pair_limit = 0;
  std::uint64_t crowded_body = 0;   ///< with pair_limit: the body in the most candidate pairs found
  std::uint64_t crowded_pairs = 0;  ///< with pair_limit: how many candidate pairs it was in when it stopped
  /// Pairs whose contact search looked ahead by their closing motion over the step (speculative
  /// contacts: a fast body met before it can pass through a thin one; 0 when nothing is fast).
  std::uint64_t speculative_pairs = 0;
};

/// Resolver counters for one step.
struct ResolverCounters {
  std::uint64_t islands = 0;           ///< independent groups solved
  std::uint64_t contacts = 0;          ///< contacts that entered a system
  std::uint64_t rounds = 0;            ///< solve rounds (simultaneous) or single impulses (sequential)
  std::uint64_t pulling_impulses = 0;  ///< impulses that came out negative (would pull bodies together)
  std::uint64_t non_converged = 0;     ///< systems that hit the iteration cap
  /// Systems the resolver could not solve: rank-deficient with conflicting targets (the minimum-norm
  /// solution leaves a residual), or no movable body behind any row. A real failure.
  std::uint64_t singular_systems = 0;
  /// Redundant contact sets solved exactly by the minimum-norm impulses: more rows than the bodies have
  /// degrees of freedom (a box resting on four corners), so the split among the rows is not unique and
  /// the smallest one is taken. Normal, not a failure (README.md, "The run summary").
  std::uint64_t redundant_systems = 0;
  std::uint64_t nan_caught = 0;        ///< non-finite results rejected
  double residual = 0.0;               ///< largest approach velocity left after resolving (m/s, ≥ 0)
  double complementarity_error = 0.0;  ///< largest |p · v_n⁺| over the contacts (N·m/s)
  std::uint64_t energy_gain_events = 0;  ///< islands whose kinetic energy rose in an impact (mixed restitution)
  std::uint64_t sticking = 0;          ///< contacts that stuck (an impulse, no slip after it)
  std::uint64_t sliding = 0;           ///< contacts that slid (an impulse, slip after it)
  /// Largest natural-map residual ‖r − P_K(r − (u + μ‖u_t‖ n))‖ of a frictional contact problem solved
  /// this step (fclib's measure without its scaling; 0 when no contact has friction).
  double natural_map_residual = 0.0;
  double friction_work = 0.0;          ///< work of the tangential impulses (J, ≤ 0: friction dissipates)
  /// Problems stopped by the resolver's work budget before they converged (also in non_converged): the
  /// best iterate is applied and the step goes on, bounded in time.
  std::uint64_t work_limited = 0;
  /// Position corrections scaled down because they would have moved a body further than the bound
  /// (resolution/common/resting.hpp, "Displacement bound"): conflicting targets, e.g. a body pinned by a
  /// joint deep inside the ground.
  std::uint64_t corrections_clamped = 0;
  double largest_correction = 0.0;     ///< largest displacement a position correction gave a body (m)
};

/// Adds the counters of a part of a step (one thread's islands, say) to `into`: counts and work add up,
/// the largest values stay the largest. Adding parts in a fixed order gives the same sums every time.
inline void add(ResolverCounters& into, const ResolverCounters& part) {
  into.islands += part.islands;
  into.contacts += part.contacts;
  into.rounds += part.rounds;
  into.pulling_impulses += part.pulling_impulses;
  into.non_converged += part.non_converged;
  into.singular_systems += part.singular_systems;
  into.redundant_systems += part.redundant_systems;
  into.nan_caught += part.nan_caught;
  into.residual = std::max(into.residual, part.residual);
  into.complementarity_error = std::max(into.complementarity_error, part.complementarity_error);
  into.energy_gain_events += part.energy_gain_events;
  into.sticking += part.sticking;
  into.sliding += part.sliding;
  into.natural_map_residual = std::max(into.natural_map_residual, part.natural_map_residual);
  into.friction_work += part.friction_work;
  into.work_limited += part.work_limited;
  into.corrections_clamped += part.corrections_clamped;
  into.largest_correction = std::max(into.largest_correction, part.largest_correction);
}

}  // namespace impetus
