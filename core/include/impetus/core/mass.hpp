#pragma once
/// \file
/// Closed-form mass properties of primitive shapes (uniform density), about the center of mass, in the
/// body frame. Meshes get theirs from the asset pipeline (Mirtich's algorithm).

#include "impetus/core/shape.hpp"

#include <optional>

namespace impetus {

/// Volume (m³) and the inertia tensor per unit density (m⁵) of a shape, about its center of mass.
struct UnitMassProperties {
  double volume = 0.0;
  Mat3 inertia_per_density = Mat3::Zero();
};

/// Closed-form properties of a sphere, box, capsule or cylinder; nullopt for a plane (infinite) and for
/// a mesh (computed by the asset pipeline).
std::optional<UnitMassProperties> primitive_mass_properties(const Shape& shape);

struct RigidBody;

/// Gives a movable `body` with a primitive shape the mass `mass` (kg, > 0) and the inertia of a uniform
/// solid of that shape (and both inverses). Throws Error for a plane, a mesh (use the asset pipeline)
/// or a non-positive mass. For embedding code; scene files do the same through `mass:`/`density:`.
void set_primitive_mass(RigidBody& body, double mass);

}  // namespace impetus
