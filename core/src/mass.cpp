#include "impetus/core/mass.hpp"

#include <numbers>
#include <type_traits>

namespace impetus {
namespace {

using std::numbers::pi;

// Inertia per unit density of a solid of revolution about body z: moment `axial` about z, `transverse`
// about x and y (both through the center of mass).
Mat3 axisymmetric(double transverse, double axial) {
  return Vec3(transverse, transverse, axial).asDiagonal();
}

UnitMassProperties sphere(const Sphere& s) {
  const double r = s.radius;
  const double volume = 4.0 / 3.0 * pi * r * r * r;
  const double moment = 0.4 * volume * r * r;  // 2/5 m r²
  return {volume, axisymmetric(moment, moment)};
}

UnitMassProperties box(const Box& b) {
  const double x = b.size.x(), y = b.size.y(), z = b.size.z();
  const double volume = x * y * z;
  // m (b² + c²) / 12 about each axis, with b, c the two other full edge lengths.
  const Vec3 moments(y * y + z * z, x * x + z * z, x * x + y * y);
  return {volume, Mat3((volume / 12.0 * moments).asDiagonal())};
}

UnitMassProperties cylinder(const Cylinder& c) {
  const double r = c.radius, h = c.length;
  const double volume = pi * r * r * h;
  return {volume, axisymmetric(volume * (3.0 * r * r + h * h) / 12.0, 0.5 * volume * r * r)};
}

// A cylinder of length h plus two hemispherical caps of radius r, one on each end.
UnitMassProperties capsule(const Capsule& c) {
  const double r = c.radius, h = c.length;
  const double volume_cylinder = pi * r * r * h;
  const double volume_caps = 4.0 / 3.0 * pi * r * r * r;  // the two caps make one sphere
  // About z the caps are a whole sphere: 2/5 m r².
  const double axial = 0.5 * volume_cylinder * r * r + 0.4 * volume_caps * r * r;
  // About x (or y) through the capsule's center. One cap of mass m: 2/5 m r² about a diameter of its
  // flat face; its centroid is 3r/8 from that face, so about its centroid 2/5 m r² − m (3r/8)², and
  // about the capsule's center (centroid at h/2 + 3r/8) m (2/5 r² − (3r/8)² + (h/2 + 3r/8)²)
  // = m (2/5 r² + h²/4 + 3hr/8). Two caps have mass volume_caps.
  const double caps_transverse = volume_caps * (0.4 * r * r + 0.25 * h * h + 0.375 * h * r);
  const double transverse = volume_cylinder * (3.0 * r * r + h * h) / 12.0 + caps_transverse;
  return {volume_caps + volume_cylinder, axisymmetric(transverse, axial)};
}

}  // namespace

std::optional<UnitMassProperties> primitive_mass_properties(const Shape& shape) {
  return std::visit(
      [](const auto& s) -> std::optional<UnitMassProperties> {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, Sphere>) return sphere(s);
        else if constexpr (std::is_same_v<T, Box>) return box(s);
        else if constexpr (std::is_same_v<T, Cylinder>) return cylinder(s);
        else if constexpr (std::is_same_v<T, Capsule>) return capsule(s);
        else return std::nullopt;  // plane: infinite; mesh: the asset pipeline's job
      },
      shape);
}

}  // namespace impetus
