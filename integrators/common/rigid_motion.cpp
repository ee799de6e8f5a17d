#include "impetus/integrators/common/rigid_motion.hpp"

namespace impetus::integrators {

void integrate_velocity(RigidBody& body, const StepContext& ctx) {
  // eq. (2), row 1: the force acts through the center of mass. Body-frame loads are turned into the
  // world frame at the pose the step starts from.
  body.velocity += ctx.dt * (ctx.gravity + body.inv_mass * body.applied_force());
  // eq. (2), row 2.
  body.angular_velocity += ctx.dt * (body.inv_inertia_world() * body.applied_torque());
}

void advance_pose(RigidBody& body, double dt, const RotationSettings& settings,
                  IntegratorCounters& counters) {
  // eq. (2), row 3, with the velocity already updated (and resolved): symplectic Euler.
  body.position += dt * body.velocity;
  // eq. (2), row 4: rotate by |ω| dt about ω, in the world frame, hence the left product.
  body.rotation = rotation_from_vector(dt * body.angular_velocity) * body.rotation;
  if (settings.orthonormalize) {
    body.rotation = orthonormalized(body.rotation);
    ++counters.orthonormalized;
  }
}

}  // namespace impetus::integrators
