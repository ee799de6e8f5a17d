#include "impetus/integrators/common/rigid_motion.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

namespace impetus::integrators {
namespace {
// Bodies per chunk of for_each_moving_body (the world's own passes use the same size).
constexpr std::size_t kChunk = 1024;
}  // namespace

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

void for_each_moving_body(std::span<RigidBody> bodies, IntegratorCounters& counters,
                          const std::function<void(RigidBody&, IntegratorCounters&)>& advance) {
  const auto run = [&](std::size_t begin, std::size_t end, IntegratorCounters& into) {
    for (std::size_t i = begin; i < end; ++i)
      if (!bodies[i].fixed && !bodies[i].asleep) advance(bodies[i], into);
  };
  const std::size_t chunks = (bodies.size() + kChunk - 1) / kChunk;
  if (chunks <= 1) return run(0, bodies.size(), counters);
  // Integer counts: their sum does not depend on the order the chunks finish in.
  std::atomic<std::uint64_t> advanced{0}, orthonormalized{0};
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    IntegratorCounters own;
    run(c * kChunk, std::min(bodies.size(), (c + 1) * kChunk), own);
    advanced += own.bodies;
    orthonormalized += own.orthonormalized;
  });
  counters.bodies += advanced;
  counters.orthonormalized += orthonormalized;
}

}  // namespace impetus::integrators
