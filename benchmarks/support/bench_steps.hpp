#pragma once
/// \file
/// The timed loop of the step-level families (`step`, `model`): after one untimed warm-up step, every
/// iteration restores `initial` (untimed) and times one World::step(), so each row measures one
/// well-defined steady-state step. A step that
/// fails (non-finite state) ends the row with its message instead of being timed.

#include "support/bench_scenes.hpp"

#include "impetus/engine/world.hpp"

#include <benchmark/benchmark.h>

#include <cstdint>
#include <limits>
#include <span>

namespace impetus::bench {

/// What the timed steps did: the stage times summed over the iterations, and the last step's status.
struct TimedSteps {
  StepProfile sum;
  StepStatus last;
  double cold_ms = 0.0;  // the untimed first step (ms)
  double allocations = std::numeric_limits<double>::quiet_NaN();  // per timed step, if counted
};

/// `count_allocations` (optional): the program's allocation count (allocation_counter.hpp), read around
/// each timed step.
inline TimedSteps time_steps(benchmark::State& state, World& world, std::span<const RigidBody> initial,
                             std::uint64_t (*count_allocations)() noexcept = nullptr) {
  TimedSteps out;
  // One untimed step first: what a simulation sets up once and reuses (symbolic analyses, the
  // broadphase's structures, buffers), so every timed iteration is a steady-state step.
  restore_state(world.bodies(), initial);
  out.cold_ms = 1e3 * world.step().profile.total;
  std::uint64_t allocations = 0, steps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    restore_state(world.bodies(), initial);
    const std::uint64_t before = count_allocations ? count_allocations() : 0;
    state.ResumeTiming();
    const StepStatus& s = world.step();
    state.PauseTiming();
    allocations += count_allocations ? count_allocations() - before : 0;
    ++steps;
    if (!s.ok) {
      state.SkipWithError(s.message.c_str());
      break;
    }
    out.sum.velocities += s.profile.velocities;
    out.sum.detect += s.profile.detect;
    out.sum.resolve += s.profile.resolve;
    out.sum.positions += s.profile.positions;
    out.sum.total += s.profile.total;
    out.last = s;
    state.ResumeTiming();
  }
  if (count_allocations && steps > 0) out.allocations = static_cast<double>(allocations) / static_cast<double>(steps);
  return out;
}

}  // namespace impetus::bench
