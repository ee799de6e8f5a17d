#pragma once
/// \file
/// The timed loop of the step-level families (`step`, `model`): after one untimed warm-up step, every
/// iteration restores `initial` (untimed) and times one World::step(), so each row measures one
/// well-defined steady-state step. A step that
/// fails (non-finite state) ends the row with its message instead of being timed.

#include "support/bench_scenes.hpp"

#include "impetus/engine/world.hpp"

#include <benchmark/benchmark.h>

#include <span>

namespace impetus::bench {

/// What the timed steps did: the stage times summed over the iterations, and the last step's status.
struct TimedSteps {
  StepProfile sum;
  StepStatus last;
  double cold_ms = 0.0;  // the untimed first step (ms)
};

inline TimedSteps time_steps(benchmark::State& state, World& world, std::span<const RigidBody> initial) {
  TimedSteps out;
  // One untimed step first: what a simulation sets up once and reuses (symbolic analyses, the
  // broadphase's structures, buffers), so every timed iteration is a steady-state step.
  restore_state(world.bodies(), initial);
  out.cold_ms = 1e3 * world.step().profile.total;
  for (auto _ : state) {
    state.PauseTiming();
    restore_state(world.bodies(), initial);
    state.ResumeTiming();
    const StepStatus& s = world.step();
    state.PauseTiming();
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
  return out;
}

}  // namespace impetus::bench
