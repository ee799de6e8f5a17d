#include "impetus/integrators/euler/euler.hpp"

namespace impetus {

EulerIntegrator::EulerIntegrator(const ModuleOptions& options)
    : settings_(integrators::RotationSettings::from_options(options)) {}

void EulerIntegrator::integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx,
                                           IntegratorCounters& /*counters*/) noexcept {
  for (RigidBody& body : bodies)
    if (!body.fixed && !body.asleep) integrators::integrate_velocity(body, ctx);
}

void EulerIntegrator::integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx,
                                          IntegratorCounters& counters) noexcept {
  for (RigidBody& body : bodies) {
    if (body.fixed || body.asleep) continue;
    // The paper keeps ω through the rotation (eq. 2, row 4 uses ω^{n+1} and nothing updates it after).
    integrators::advance_pose(body, ctx.dt, settings_, counters);
    ++counters.bodies;
  }
}

}  // namespace impetus
