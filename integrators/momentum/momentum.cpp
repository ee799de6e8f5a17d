#include "impetus/integrators/momentum/momentum.hpp"

namespace impetus {

MomentumIntegrator::MomentumIntegrator(const ModuleOptions& options)
    : settings_(integrators::RotationSettings::from_options(options)) {}

void MomentumIntegrator::integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx,
                                              IntegratorCounters& /*counters*/) noexcept {
  // L += dt τ at the current R is ω += dt J_world⁻¹ τ: the shared update, without the round trip
  // through L (which would only add rounding).
  IntegratorCounters unused;
  integrators::for_each_moving_body(bodies, unused, [&](RigidBody& body, IntegratorCounters&) {
    integrators::integrate_velocity(body, ctx);
  });
}

void MomentumIntegrator::integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx,
                                             IntegratorCounters& counters) noexcept {
  integrators::for_each_moving_body(bodies, counters, [&](RigidBody& body, IntegratorCounters& count) {
    // Torque-free between the phases, L is constant in the world frame while J_world turns with the
    // body: this is where the gyroscopic term that eq. 2 drops comes back.
    // Products applied right to left (R (J (Rᵀ ω))) round less than forming J_world = R J Rᵀ.
    const Vec3 angular_momentum =
        body.rotation * (body.inertia_body * (body.rotation.transpose() * body.angular_velocity));
    integrators::advance_pose(body, ctx.dt, settings_, count);
    body.angular_velocity =
        body.rotation * (body.inv_inertia_body * (body.rotation.transpose() * angular_momentum));
    ++count.bodies;
  });
}

}  // namespace impetus
