#pragma once
// Internal: the one place that turns "mass or density (and maybe an inertia tensor)" plus a shape's unit
// properties into a body's mass properties. Used by scene bodies and by the generators.

#include "impetus/core/body.hpp"
#include "impetus/core/mass.hpp"

#include <optional>

namespace impetus::scene_detail {

/// How a movable body's mass is given: exactly one of `mass` (kg) and `density` (kg/m³), both
/// positive, and optionally an inertia tensor about the center of mass (body frame, kg·m²) that
/// replaces the one implied by the shape.
struct MassSpec {
  std::optional<double> mass;
  std::optional<double> density;
  std::optional<Mat3> inertia_body;
};

/// Sets `body`'s mass, inverse mass, inertia and inverse inertia from `unit` (the shape's volume and
/// inertia per unit density): mass = density·volume or density = mass/volume, inertia = density ×
/// inertia_per_density unless given. Callers check the preconditions with their own locations
/// (positive values, positive volume, positive definite inertia).
void set_mass_properties(RigidBody& body, const UnitMassProperties& unit, const MassSpec& spec);

}  // namespace impetus::scene_detail
