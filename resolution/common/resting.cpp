#include "impetus/resolution/common/resting.hpp"

namespace impetus::resolution {

void apply_row_displacement(const ImpulseRow& row, double q, std::span<RigidBody> bodies) {
  RigidBody& a = bodies[row.a];
  RigidBody& b = bodies[row.b];
  // Rotations stay orthonormal to rounding: Rodrigues' matrix is exact, the angles are tiny.
  if (!a.fixed) {
    a.position -= (q * row.inv_mass_a) * row.normal;
    a.rotation = rotation_from_vector(-q * row.turn_a) * a.rotation;
  }
  if (!b.fixed) {
    b.position += (q * row.inv_mass_b) * row.normal;
    b.rotation = rotation_from_vector(q * row.turn_b) * b.rotation;
  }
}

}  // namespace impetus::resolution
