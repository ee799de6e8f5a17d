// Mass properties of a movable body from mass or density (see scene_body_setup.hpp).

#include "scene_body_setup.hpp"

#include "impetus/core/error.hpp"
#include "impetus/core/format.hpp"

#include <cassert>
#include <cmath>
#include <string>

namespace impetus::scene_detail {

void set_mass_properties(RigidBody& body, const UnitMassProperties& unit, const MassSpec& spec) {
  assert(spec.mass.has_value() != spec.density.has_value());
  assert(unit.volume > 0.0);
  const double density = spec.density ? *spec.density : *spec.mass / unit.volume;
  body.fixed = false;
  body.mass = spec.mass ? *spec.mass : density * unit.volume;
  body.inv_mass = 1.0 / body.mass;
  body.inertia_body = spec.inertia_body ? *spec.inertia_body : Mat3(unit.inertia_per_density * density);
  // Symmetrize: the cofactor inverse of a symmetric matrix can differ from symmetric in the last bit.
  Mat3 inverse = body.inertia_body.inverse();
  // The cofactor inverse goes through the determinant, which overflows (or underflows) for moments
  // beyond about 1e±100 (a 1e122 kg sphere, found by fuzz/scene): invert the matrix scaled to unit size
  // then. Ordinary bodies keep the plain inverse, bit for bit.
  if (!inverse.allFinite() || !((body.inertia_body * inverse - Mat3::Identity()).norm() < 1e-9)) {
    const double scale = body.inertia_body.cwiseAbs().maxCoeff();
    inverse = (body.inertia_body / scale).inverse() / scale;
  }
  body.inv_inertia_body = 0.5 * (inverse + inverse.transpose());
}

}  // namespace impetus::scene_detail

namespace impetus {

void set_primitive_mass(RigidBody& body, double mass) {
  const std::string label = "body '" + body.name + "'";
  if (!(mass > 0.0) || !std::isfinite(mass))
    throw Error(label + ": mass must be positive and finite, got " + format_number(mass));
  const std::optional<UnitMassProperties> unit = primitive_mass_properties(body.shape);
  if (!unit)
    throw Error(label + ": a " + std::string(shape_kind_name(body.shape)) +
                " has no closed-form mass properties (planes are fixed; meshes go through the asset pipeline)");
  scene_detail::set_mass_properties(body, *unit, scene_detail::MassSpec{mass, std::nullopt, std::nullopt});
}

}  // namespace impetus
