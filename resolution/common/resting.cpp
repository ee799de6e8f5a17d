#include "impetus/resolution/common/resting.hpp"

namespace impetus::resolution {

RestingSettings RestingSettings::from_options(const ModuleOptions& options) {
  RestingSettings s;
  s.slop = options.number("slop", s.slop, 0.0, 1.0);
  s.correction = options.number("correction", s.correction, 0.0, 1.0);
  s.bounce_threshold = options.number("bounce_threshold", s.bounce_threshold, 0.0, 1e3);
  return s;
}

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
