#pragma once
/// \file
/// The paper's integrator: the explicit first-order scheme of eq. 2, split into the two phases of the
/// step (docs/conventions.md, "The step"). See README.md for what it assumes, guarantees and where it fails.

#include "impetus/integrators/common/rigid_motion.hpp"
#include "impetus/modules/integrator.hpp"
#include "impetus/modules/options.hpp"

namespace impetus {

/// Eq. 2 with Rodrigues' Q: ω is updated directly from the torque and carried unchanged through the
/// rotation step, so a torque-free body keeps its world-frame ω (and its angular momentum drifts unless
/// ω is along a principal axis). Stateless; skips fixed bodies.
///
/// Options: `orthonormalize` (bool, default true): re-orthonormalize R every step.
class EulerIntegrator final : public Integrator {
 public:
  /// Reads the options; throws OptionError on a bad value.
  explicit EulerIntegrator(const ModuleOptions& options);

  /// Phase 1, eq. 2 rows 1–2: v += dt (g + F/M), ω += dt J_world⁻¹ τ.
  void integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx,
                            IntegratorCounters& counters) noexcept override;

  /// Phase 2, eq. 2 rows 3–4: x += dt v, R = Q(ω dt) R; ω unchanged. Counts the bodies advanced.
  void integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx,
                           IntegratorCounters& counters) noexcept override;

  /// The settings read from the options.
  const integrators::RotationSettings& settings() const { return settings_; }

 private:
  integrators::RotationSettings settings_;
};

}  // namespace impetus
