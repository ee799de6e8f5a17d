#pragma once
/// \file
/// Hand-built bodies and contacts, and the small drivers and measures, that the conformance suites and
/// Impetus's own tests set up their closed-form problems with. Header-only and free of GoogleTest, so
/// any test can use it.

#include "impetus/core/body.hpp"
#include "impetus/core/shape.hpp"
#include "impetus/modules/contact.hpp"
#include "impetus/modules/integrator.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

namespace impetus::conformance {

/// A movable body of mass m (kg) with principal moments `moments` (kg·m²) along its body axes (no shape).
inline RigidBody principal_body(double mass, const Vec3& moments) {
  RigidBody b;
  b.mass = mass;
  b.inv_mass = 1.0 / mass;
  b.inertia_body = moments.asDiagonal();
  b.inv_inertia_body = moments.cwiseInverse().asDiagonal();
  return b;
}

/// A movable solid sphere: mass m (kg), radius r (m), inertia 2/5 m r², at `position` (m) moving with
/// `velocity` (m/s).
inline RigidBody sphere(double mass, double radius, const Vec3& position, const Vec3& velocity = Vec3::Zero(),
                        double restitution = 0.0) {
  RigidBody b;
  b.shape = Sphere{radius};
  b.mass = mass;
  b.inv_mass = 1.0 / mass;
  b.inertia_body = Mat3::Identity() * (0.4 * mass * radius * radius);
  b.inv_inertia_body = b.inertia_body.inverse();
  b.position = position;
  b.velocity = velocity;
  b.material.restitution = restitution;
  return b;
}

/// A movable solid box with full edges `size` (m): inertia m/12 (b² + c², …) about its axes.
inline RigidBody box(double mass, const Vec3& size, const Vec3& position, const Mat3& rotation = Mat3::Identity(),
                     const Vec3& velocity = Vec3::Zero(), double restitution = 0.0) {
  const Vec3 s2 = size.cwiseProduct(size);
  RigidBody b = principal_body(mass, mass / 12.0 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()));
  b.shape = Box{size};
  b.position = position;
  b.rotation = rotation;
  b.velocity = velocity;
  b.material.restitution = restitution;
  return b;
}

/// The fixed half-space z ≤ 0 named "ground", its body at the origin.
inline RigidBody ground(double restitution = 0.0) {
  RigidBody g;
  g.name = "ground";
  g.shape = Plane{Vec3::UnitZ(), 0.0};
  make_fixed(g);
  g.material.restitution = restitution;
  return g;
}

/// A contact following the convention (normal normalized here, out of a into b; depth > 0 overlaps).
inline Contact contact(BodyIndex a, BodyIndex b, const Vec3& point, const Vec3& normal, double depth = 0.0) {
  Contact c;
  c.a = a;
  c.b = b;
  c.point = point;
  c.normal = normal.normalized();
  c.depth = depth;
  return c;
}

/// ‖RᵀR − I‖ (Frobenius) of a rotation matrix.
inline double orthonormality_error(const Mat3& rotation) {
  return (rotation.transpose() * rotation - Mat3::Identity()).norm();
}

/// Runs `steps` whole integrator steps (velocities, then positions; no contacts) from step index 0 and
/// returns the summed counters.
inline IntegratorCounters run(Integrator& integrator, std::vector<RigidBody>& bodies, StepContext ctx, int steps) {
  IntegratorCounters total;
  for (int i = 0; i < steps; ++i) {
    ctx.step = static_cast<std::uint64_t>(i);
    ctx.time = i * ctx.dt;
    integrator.integrate_velocities(bodies, ctx, total);
    integrator.integrate_positions(bodies, ctx, total);
  }
  return total;
}

/// Rotation angle (rad) of R_aᵀ R_b, accurate near zero (through the quaternion, not acos of the trace).
inline double angle_between(const Mat3& r_a, const Mat3& r_b) {
  const Quat q(Mat3(r_a.transpose() * r_b));
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

}  // namespace impetus::conformance
