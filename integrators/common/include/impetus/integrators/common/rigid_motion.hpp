#pragma once
/// \file
/// The parts of the paper's explicit scheme, eq. 2, that every Impetus integrator shares, one body at a
/// time. Split as the step needs it (docs/conventions.md, "The step"): velocities first, then, after the
/// resolver has corrected them, positions and rotations.
///
/// Eq. 2 as used here (world frame, R maps body to world, J_world = R J_body Rᵀ):
///   v⁺ = v + dt (g + F / M)                 (row 1)
///   ω⁺ = ω + dt J_world⁻¹ τ                 (row 2; no gyroscopic term, as in the paper)
///   x⁺ = x + dt v⁺                          (row 3)
///   R⁺ = Q(ω⁺ dt) R                         (row 4; Q by Rodrigues' formula, its diagonal typo fixed)

#include "impetus/core/body.hpp"
#include "impetus/modules/options.hpp"
#include "impetus/modules/step.hpp"
#include "impetus/settings/integrators.hpp"  // RotationSettings

#include <functional>
#include <span>

namespace impetus::integrators {

/// Eq. 2, rows 1–2: gravity `ctx.gravity` (m/s²), the applied force `body.applied_force()` (N) and
/// torque `body.applied_torque()` (N·m, world frame; body-frame loads turned at the current pose) change
/// the velocities over `ctx.dt`. Angular momentum changes by dt τ; at the current R that is exactly ω += dt J_world⁻¹ τ, so this one update serves integrators
/// that carry ω and those that carry L. The body must not be fixed.
void integrate_velocity(RigidBody& body, const StepContext& ctx);

/// Eq. 2, rows 3–4: x += dt v and R = Q(ω dt) R, re-orthonormalized if `settings` say so (counted in
/// `counters.orthonormalized`). Leaves v and ω unchanged. The body must not be fixed.
void advance_pose(RigidBody& body, double dt, const RotationSettings& settings,
                  IntegratorCounters& counters);

/// Calls `advance(body, counters)` for every body that is neither fixed nor asleep: in parallel, on fixed
/// chunks of bodies, when there is more than one chunk (the chunks do not depend on the thread count,
/// and each body is advanced on its own, so the bodies come out the same for every thread count). Each
/// chunk counts into its own counters; they are added to `counters`.
void for_each_moving_body(std::span<RigidBody> bodies, IntegratorCounters& counters,
                          const std::function<void(RigidBody&, IntegratorCounters&)>& advance);

}  // namespace impetus::integrators
