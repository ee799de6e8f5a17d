#pragma once
// Hand-built bodies and contacts for the sequential resolver's tests, and the whole-system measures
// they assert (momentum, energy), computed here independently of the resolver's own algebra.
#include "impetus/core/body.hpp"
#include "impetus_test/bodies.hpp"
#include "impetus/core/mass.hpp"
#include "impetus/engine/metrics.hpp"
#include "impetus/modules/contact.hpp"
#include "impetus/resolution/mirtich/mirtich.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <vector>

namespace impetus::mirtich_test {

/// Hand-built spheres, boxes, the fixed ground (z ≤ 0) and contacts (impetus/conformance/fixtures.hpp).
using conformance::box;
using conformance::sphere;
inline RigidBody ground() { return test::ground_plane(); }
using test::contact;

/// Runs the resolver once with `settings` and returns its counters.
inline ResolverCounters resolve(std::vector<RigidBody>& bodies, std::vector<Contact>& contacts,
                                const MirtichSettings& settings = {}) {
  MirtichResolver resolver(settings);
  ResolverCounters counters;
  resolver.resolve(bodies, contacts, {}, StepContext{}, counters);
  return counters;
}

/// Momenta and kinetic energy of the movable bodies, as the core measures them.
inline Vec3 linear_momentum(std::span<const RigidBody> bodies) { return measure_bodies(bodies).linear_momentum; }
inline Vec3 angular_momentum(std::span<const RigidBody> bodies) { return measure_bodies(bodies).angular_momentum; }
inline double kinetic_energy(std::span<const RigidBody> bodies) { return measure_bodies(bodies).kinetic_energy; }

/// A row of `count` touching spheres (radius r, mass 1) on the x axis, ball 0 moving at +x `speed`,
/// with contacts (i, i+1) along +x: Newton's cradle without strings.
inline void cradle(int count, double restitution, double speed, std::vector<RigidBody>& bodies,
                   std::vector<Contact>& contacts, double r = 0.5) {
  bodies.clear();
  contacts.clear();
  for (int i = 0; i < count; ++i)
    bodies.push_back(sphere(1.0, r, Vec3(2 * r * i, 0, 0), Vec3::Zero(), restitution));
  bodies[0].velocity = Vec3(speed, 0, 0);
  for (int i = 0; i + 1 < count; ++i)
    contacts.push_back(contact(i, i + 1, Vec3(2 * r * i + r, 0, 0), Vec3::UnitX()));
}

}  // namespace impetus::mirtich_test
