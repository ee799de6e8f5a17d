#include "impetus/integrators/euler/euler.hpp"

namespace impetus {

EulerIntegrator::EulerIntegrator(const ModuleOptions& options)
    : settings_(integrators::RotationSettings::from_options(options)) {}

void EulerIntegrator::integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx,
                                           IntegratorCounters& /*counters*/) noexcept {
  IntegratorCounters unused;
  integrators::for_each_moving_body(bodies, unused, [&](RigidBody& body, IntegratorCounters&) {
    integrators::integrate_velocity(body, ctx);
  });
}

void EulerIntegrator::integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx,
                                          IntegratorCounters& counters) noexcept {
  integrators::for_each_moving_body(bodies, counters, [&](RigidBody& body, IntegratorCounters& count) {
    // The paper keeps ω through the rotation (eq. 2, row 4 uses ω^{n+1} and nothing updates it after).
    integrators::advance_pose(body, ctx.dt, settings_, count);
    ++count.bodies;
  });
}

}  // namespace impetus
