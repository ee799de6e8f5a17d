#pragma once
/// \file
/// Eq. 2 with angular momentum carried through the rotation step instead of angular velocity
/// (docs/conventions.md, "The paper's typos": the paper's eq. 2 ignores the gyroscopic term). See README.md for
/// what it assumes, guarantees and where it fails.

#include "impetus/integrators/common/rigid_motion.hpp"
#include "impetus/modules/integrator.hpp"
#include "impetus/modules/options.hpp"

namespace impetus {

/// Like EulerIntegrator, but the rotation step keeps the world-frame angular momentum L = J_world ω
/// and recomputes ω = J_world⁻¹ L with the new rotation. A torque-free body therefore conserves L to
/// rounding, and an asymmetric one tumbles as it should (intermediate-axis instability). Stateless:
/// L is rebuilt from ω at the start of each phase, so ω stays the body's state and the resolver may
/// change it between the phases. Skips fixed bodies.
///
/// Options: `orthonormalize` (bool, default true): re-orthonormalize R every step.
class MomentumIntegrator final : public Integrator {
 public:
  /// Reads the options; throws OptionError on a bad value.
  explicit MomentumIntegrator(const ModuleOptions& options);

  /// Phase 1, eq. 2 rows 1–2 in momentum form: v += dt (g + F/M); L = J_world ω + dt τ,
  /// ω = J_world⁻¹ L (at a fixed R this is the same update as EulerIntegrator's).
  void integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx,
                            IntegratorCounters& counters) noexcept override;

  /// Phase 2: L = J_world(R) ω; x += dt v; R' = Q(ω dt) R; ω = J_world(R')⁻¹ L. Counts the bodies.
  void integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx,
                           IntegratorCounters& counters) noexcept override;

  /// The settings read from the options.
  const integrators::RotationSettings& settings() const { return settings_; }

 private:
  integrators::RotationSettings settings_;
};

}  // namespace impetus
