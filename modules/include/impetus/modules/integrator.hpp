#pragma once
/// \file
/// The integrator module contract. The world calls the two phases around detection and resolution
/// (docs/conventions.md, "The step"): velocities first, positions last, so resolved velocities move bodies.

#include "impetus/core/body.hpp"
#include "impetus/modules/step.hpp"

#include <span>

namespace impetus {

/// Advances the bodies' state in time. Implementations skip fixed bodies (the world moves those with a
/// prescribed motion itself) and sleeping ones (RigidBody::asleep), and apply RigidBody::applied_force()
/// and applied_torque().
class Integrator {
 public:
  virtual ~Integrator() = default;

  /// Phase 1: gravity, applied forces and torques change velocities over ctx.dt.
  virtual void integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx,
                                    IntegratorCounters& counters) noexcept = 0;

  /// Phase 2: positions and rotations advance over ctx.dt with the current (resolved) velocities.
  virtual void integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx,
                                   IntegratorCounters& counters) noexcept = 0;
};

}  // namespace impetus
