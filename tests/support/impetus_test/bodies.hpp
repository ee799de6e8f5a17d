#pragma once
// Small builders shared by the tests: the fixed ground and a contact written out by hand.

#include "impetus/core/body.hpp"
#include "impetus/modules/contact.hpp"

namespace impetus::test {

/// The fixed ground "ground": the half-space z ≤ 0, with restitution `restitution`.
inline RigidBody ground_plane(double restitution = 0.0) {
  RigidBody g;
  g.name = "ground";
  g.shape = Plane{Vec3::UnitZ(), 0.0};
  make_fixed(g);
  g.material.restitution = restitution;
  return g;
}

/// A contact following the convention (normal, normalized here, out of a into b; depth > 0 overlaps).
inline Contact contact(BodyIndex a, BodyIndex b, const Vec3& point, const Vec3& normal, double depth = 0.0) {
  Contact c;
  c.a = a;
  c.b = b;
  c.point = point;
  c.normal = normal.normalized();
  c.depth = depth;
  return c;
}

}  // namespace impetus::test
