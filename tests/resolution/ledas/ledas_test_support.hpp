#pragma once
// Hand-built bodies, contacts and tiny analytic detectors for the LEDAS resolver tests (no FCL).
#include "impetus_test/bodies.hpp"
#include "impetus_test/box_stack_detector.hpp"
#include "impetus/core/mass.hpp"
#include "impetus/engine/metrics.hpp"
#include "impetus/modules/contact.hpp"
#include "impetus/modules/detector.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <cmath>
#include <span>
#include <vector>

namespace impetus::ledas_test {

inline RigidBody solid(const Shape& shape, double mass, const Vec3& position, const Vec3& velocity = Vec3::Zero(),
                       double restitution = 0.0, const Mat3& rotation = Mat3::Identity()) {
  RigidBody b;
  b.shape = shape;
  set_primitive_mass(b, mass);
  b.position = position;
  b.rotation = rotation;
  b.velocity = velocity;
  b.material.restitution = restitution;
  return b;
}

inline RigidBody sphere(double radius, double mass, const Vec3& position, const Vec3& velocity = Vec3::Zero(),
                        double restitution = 0.0) {
  return solid(Sphere{radius}, mass, position, velocity, restitution);
}

using test::contact;
using test::ground_plane;

/// One resolution with `resolver`; returns the counters.
inline ResolverCounters resolve(LedasResolver& resolver, std::vector<RigidBody>& bodies, std::vector<Contact>& contacts,
                                std::span<const Constraint> constraints = {}, double dt = 1e-3) {
  ResolverCounters counters;
  StepContext ctx;
  ctx.dt = dt;
  resolver.resolve(bodies, contacts, constraints, ctx, counters);
  return counters;
}

inline LedasSettings settings_for(LedasMode mode) {
  LedasSettings s;
  s.mode = mode;
  return s;
}

// Momenta and kinetic energy of the movable bodies, as the core measures them.
inline Vec3 momentum(std::span<const RigidBody> bodies) { return measure_bodies(bodies).linear_momentum; }
inline Vec3 angular_momentum(std::span<const RigidBody> bodies) { return measure_bodies(bodies).angular_momentum; }
inline double kinetic_energy(std::span<const RigidBody> bodies) { return measure_bodies(bodies).kinetic_energy; }

/// Sphere–sphere contacts (centres closer than 2r(1 + 1e-6)) and sphere–plane contacts for every plane
/// body (the solid half-space n·x ≤ offset), following the Contact convention (a < b, n out of a).
inline std::vector<Contact> sphere_contacts(std::span<const RigidBody> bodies) {
  std::vector<Contact> out;
  for (BodyIndex i = 0; i < bodies.size(); ++i) {
    for (BodyIndex j = i + 1; j < bodies.size(); ++j) {
      const auto* si = std::get_if<Sphere>(&bodies[i].shape);
      const auto* sj = std::get_if<Sphere>(&bodies[j].shape);
      const auto* pj = std::get_if<Plane>(&bodies[j].shape);
      if (si && sj) {
        const Vec3 d = bodies[j].position - bodies[i].position;
        const double reach = si->radius + sj->radius;
        if (d.norm() < reach * (1.0 + 1e-6))
          out.push_back(contact(i, j, bodies[i].position + d.normalized() * (si->radius - 0.5 * (reach - d.norm())),
                                d.normalized(), reach - d.norm()));
      } else if (si && pj) {  // plane normal points out of the plane's solid, into the sphere: n_contact = −normal
        const double height = pj->normal.dot(bodies[i].position) - pj->offset;
        if (height < si->radius * (1.0 + 1e-6))
          out.push_back(contact(i, j, bodies[i].position - si->radius * pj->normal, -pj->normal, si->radius - height));
      }
    }
  }
  return out;
}

using test::BoxStackDetector;

}  // namespace impetus::ledas_test
