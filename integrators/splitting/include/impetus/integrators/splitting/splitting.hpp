#pragma once
/// \file
/// Eq. 2's translation with the free rotation advanced by a symmetric splitting of the torque-free
/// rigid body into three exact rotations about the principal axes. See README.md for what it assumes,
/// guarantees and where it fails.

#include "impetus/integrators/common/rigid_motion.hpp"
#include "impetus/modules/integrator.hpp"
#include "impetus/modules/options.hpp"

namespace impetus {

/// Like MomentumIntegrator, the rotation step keeps the world-frame angular momentum L; unlike it, the
/// torque-free rotation over dt is not one explicit turn about ω but the symmetric composition
///   Φ₁(dt/2) Φ₂(dt/2) Φ₃(dt) Φ₂(dt/2) Φ₁(dt/2),
/// where Φᵢ(h) is the exact flow of the kinetic energy's i-th term lᵢ²/(2 Jᵢ): a rotation of the body
/// about its i-th principal axis by h lᵢ/Jᵢ (l = L in the principal frame, constant in the world).
/// Each Φᵢ is exact, so L is conserved to rounding; the composition is symplectic, time-reversible and
/// second order, so the kinetic energy oscillates within O(dt²) of its start instead of drifting.
/// Stateless: L is rebuilt from ω at the start of the positions phase, so the resolver may change ω
/// between the phases. Skips fixed bodies.
///
/// Options: `orthonormalize` (bool, default true): re-orthonormalize R every step.
class SplittingIntegrator final : public Integrator {
 public:
  /// Reads the options; throws OptionError on a bad value.
  explicit SplittingIntegrator(const ModuleOptions& options);

  /// Phase 1, eq. 2 rows 1–2 (shared with EulerIntegrator): v += dt (g + F/M); ω += dt J_world⁻¹ τ,
  /// which at a fixed R is L += dt τ.
  void integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx,
                            IntegratorCounters& counters) noexcept override;

  /// Phase 2: x += dt v (eq. 2 row 3); R and ω by the splitting above. Counts the bodies.
  void integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx,
                           IntegratorCounters& counters) noexcept override;

  /// The settings read from the options.
  const integrators::RotationSettings& settings() const { return settings_; }

 private:
  integrators::RotationSettings settings_;
};

}  // namespace impetus
