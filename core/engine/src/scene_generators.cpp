// The benchmark scenes of docs/conventions.md ("Benchmark scenes"): pyramid and line of spheres.

#include "impetus/engine/generators.hpp"

#include "impetus/core/format.hpp"
#include "impetus/core/mass.hpp"
#include "scene_body_setup.hpp"

#include <cmath>
#include <string>

namespace impetus {
namespace {

// Sizes beyond these would exhaust memory long before a benchmark finished; refuse them plainly.
constexpr int kMaxRows = 1000;        // 500 500 spheres
constexpr int kMaxCount = 1000000;

// Range checks shared by both generators; `kind` prefixes the message ("pyramid", "line").
void check_common(const char* kind, double radius, double mass, const Vec3& velocity, double restitution,
                  double friction, double overlap) {
  const std::string k = kind;
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw GeneratorError("radius", k + " 'radius' must be a positive number, got " + format_number(radius));
  if (!(mass > 0.0) || !std::isfinite(mass))
    throw GeneratorError("mass", k + " 'mass' must be a positive number, got " + format_number(mass));
  // The inertia 2/5 m r² and the spacing of thousands of bodies must stay finite (a radius of 1e200
  // passes the check above and overflows both).
  if (!std::isfinite(0.4 * mass * radius * radius) || !std::isfinite(radius * 4.0e6))
    throw GeneratorError("radius", k + " 'radius' " + format_number(radius) + " with 'mass' " + format_number(mass) +
                                       " overflows the inertia or the positions (m r² and 2r × count must be finite)");
  if (!velocity.allFinite()) throw GeneratorError("velocity", k + " 'velocity' must be finite");
  if (!std::isfinite(mass * velocity.squaredNorm()))
    throw GeneratorError("velocity", k + " 'velocity' overflows the kinetic energy (m |v|² must be finite)");
  if (!(restitution >= 0.0 && restitution <= 1.0))
    throw GeneratorError("restitution",
                         k + " 'restitution' must be between 0 and 1, got " + format_number(restitution));
  if (!(friction >= 0.0) || !std::isfinite(friction))
    throw GeneratorError("friction", k + " 'friction' must be a finite number >= 0, got " + format_number(friction));
  if (!(overlap >= 0.0 && overlap < 1.0))
    throw GeneratorError("overlap", k + " 'overlap' must be at least 0 and below 1, got " + format_number(overlap));
}

RigidBody sphere_body(std::string name, double radius, double mass, const Vec3& position, double restitution,
                      double friction) {
  RigidBody body;
  body.name = std::move(name);
  body.shape = Sphere{radius};
  body.position = position;
  body.material.restitution = restitution;
  body.material.friction = friction;
  scene_detail::MassSpec spec;
  spec.mass = mass;
  scene_detail::set_mass_properties(body, *primitive_mass_properties(body.shape), spec);
  return body;
}

// A fixed plane body at the identity pose: the solid half-space normal·p ≤ offset.
RigidBody plane_body(std::string name, const Vec3& normal, double offset, double friction) {
  RigidBody body;
  body.name = std::move(name);
  body.material.friction = friction;
  body.shape = Plane{normal, offset};
  make_fixed(body);
  return body;
}

}  // namespace

std::size_t body_count(const PyramidParams& p) {
  if (p.rows < 1 || p.rows > kMaxRows)
    throw GeneratorError("rows", "pyramid 'rows' must be between 1 and " + std::to_string(kMaxRows) + ", got " +
                                     std::to_string(p.rows));
  return static_cast<std::size_t>(p.rows) * (p.rows + 1) / 2 + (p.ground ? 1 : 0);
}

std::size_t body_count(const LineParams& p) {
  if (p.count < 1 || p.count > kMaxCount)
    throw GeneratorError("count", "line 'count' must be between 1 and " + std::to_string(kMaxCount) + ", got " +
                                      std::to_string(p.count));
  return static_cast<std::size_t>(p.count) + (p.wall ? 1 : 0);
}

std::vector<RigidBody> make_pyramid(const PyramidParams& p) {
  const std::size_t count = body_count(p);
  check_common("pyramid", p.radius, p.mass, p.velocity, p.restitution, p.friction, p.overlap);
  const double r = p.radius;
  const double spacing = 2.0 * r * (1.0 - p.overlap);  // neighbours overlap by 2r·overlap
  const double rise = std::sqrt(3.0) / 2.0 * spacing;  // row height: equilateral triangles of side `spacing`
  std::vector<RigidBody> bodies;
  bodies.reserve(count);
  for (int row = 0; row < p.rows; ++row) {
    for (int i = 0; i < p.rows - row; ++i) {
      const Vec3 position((0.5 * row + i) * spacing, 0.0, r * (1.0 - p.overlap) + row * rise);
      bodies.push_back(sphere_body("pyramid_r" + std::to_string(row) + "_" + std::to_string(i), r, p.mass,
                                   position, p.restitution, p.friction));
      bodies.back().velocity = p.velocity;
    }
  }
  if (p.ground) bodies.push_back(plane_body("ground", Vec3::UnitZ(), 0.0, p.friction));
  return bodies;
}

std::vector<RigidBody> make_line(const LineParams& p) {
  const std::size_t count = body_count(p);
  check_common("line", p.radius, p.mass, p.velocity, p.restitution, p.friction, p.overlap);
  const double r = p.radius;
  const double spacing = 2.0 * r * (1.0 - p.overlap);
  std::vector<RigidBody> bodies;
  bodies.reserve(count);
  for (int i = 0; i < p.count; ++i)
    bodies.push_back(sphere_body("line_" + std::to_string(i), r, p.mass, Vec3(i * spacing, 0.0, 0.0), p.restitution,
                                   p.friction));
  bodies.front().velocity = p.velocity;
  if (p.wall) {
    // The wall is the solid x ≥ x_wall; its outward normal points back along −x, so −x ≤ −x_wall.
    const double x_wall = (p.count - 1) * spacing + r * (1.0 - p.overlap);
    bodies.push_back(plane_body("wall", -Vec3::UnitX(), -x_wall, p.friction));
  }
  return bodies;
}

}  // namespace impetus
