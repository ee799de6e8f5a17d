#include "impetus/engine/metrics.hpp"

#include <algorithm>

namespace impetus {

WorldMetrics measure(const World& world) {
  WorldMetrics m = measure_bodies(world.bodies(), world.settings().gravity);
  for (const Contact& c : world.contacts()) m.max_penetration = std::max(m.max_penetration, c.depth);
  m.contacts = world.contacts().size();
  return m;
}

double total_kinetic_energy(std::span<const RigidBody> bodies) {
  double energy = 0.0;
  for (const RigidBody& b : bodies)
    if (!b.fixed)
      energy += 0.5 * b.mass * b.velocity.squaredNorm() + 0.5 * b.angular_velocity.dot(b.inertia_world() * b.angular_velocity);
  return energy;
}

double load_potential_energy(std::span<const RigidBody> bodies, const Vec3& g) {
  double energy = 0.0;
  for (const RigidBody& b : bodies)
    if (!b.fixed) energy -= (b.mass * g + b.force).dot(b.position);
  return energy;
}

WorldMetrics measure_bodies(std::span<const RigidBody> bodies, const Vec3& g) {
  WorldMetrics m;
  for (const RigidBody& b : bodies) {
    if (b.fixed) continue;
    const Vec3 spin = b.inertia_world() * b.angular_velocity;  // J_world ω
    m.kinetic_energy += 0.5 * b.mass * b.velocity.squaredNorm() + 0.5 * b.angular_velocity.dot(spin);
    m.potential_energy -= b.mass * g.dot(b.position);
    m.linear_momentum += b.mass * b.velocity;
    m.angular_momentum += b.position.cross(b.mass * b.velocity) + spin;
  }
  return m;
}

}  // namespace impetus
