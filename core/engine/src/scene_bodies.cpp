// `bodies:` entries: name, shape, mass properties, pose, velocities, material, collision filter, applied
// loads (movable bodies) and prescribed motion (fixed bodies).

#include "impetus/assets/mesh_body.hpp"
#include "impetus/core/format.hpp"
#include "impetus/core/mass.hpp"
#include "scene_body_setup.hpp"
#include "scene_internal.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus::scene_detail {
namespace {

Shape read_shape(const SceneReader& r, const YAML::Node& node) {
  const Fields shape(r, node, "shape", {"sphere", "box", "capsule", "cylinder", "plane", "mesh"});
  if (shape.entries().empty())
    r.fail(node, "shape needs one of: sphere, box, capsule, cylinder, plane, mesh");
  if (shape.entries().size() > 1)
    r.fail(shape.entries()[1].key_node, "shape has both '" + shape.entries()[0].key + "' and '" +
                                            shape.entries()[1].key + "'; give exactly one");
  const Fields::Entry& kind = shape.entries().front();
  if (kind.key == "sphere") {
    const Fields f(r, kind.value, "sphere", {"radius"});
    return Sphere{r.positive(f.require("radius"), "radius")};
  }
  if (kind.key == "box") {
    const Fields f(r, kind.value, "box", {"size"});
    const YAML::Node& size_node = f.require("size");
    const Vec3 size = r.vec3(size_node, "size");
    if (!(size.minCoeff() > 0.0)) r.fail(size_node, "'size' must have three positive edge lengths");
    return Box{size};
  }
  if (kind.key == "capsule") {
    const Fields f(r, kind.value, "capsule", {"radius", "length"});
    // A capsule of length 0 is a sphere: allowed. A cylinder needs a length.
    return Capsule{r.positive(f.require("radius"), "radius"), r.non_negative(f.require("length"), "length")};
  }
  if (kind.key == "cylinder") {
    const Fields f(r, kind.value, "cylinder", {"radius", "length"});
    return Cylinder{r.positive(f.require("radius"), "radius"), r.positive(f.require("length"), "length")};
  }
  if (kind.key == "plane") {
    const Fields f(r, kind.value, "plane", {"normal", "offset"});
    const YAML::Node* offset = f.find("offset");
    return Plane{r.direction(f.require("normal"), "normal"), offset ? r.number(*offset, "offset") : 0.0};
  }
  // A mesh: imported (once per file, scale and part in this scene), validated, moved so the body
  // frame's origin is its center of mass (the body's `position` places that point), with its convex
  // hull. Without `collision`, a convex mesh collides as its hull and any other as triangles.
  const Fields f(r, kind.value, "mesh", {"file", "scale", "collision", "part"});
  MeshShape mesh;
  const YAML::Node& file = f.require("file");
  mesh.file = r.resolve_path(r.string(file, "file"));
  if (const YAML::Node* scale = f.find("scale")) mesh.scale = r.positive(*scale, "scale");
  const YAML::Node* part = f.find("part");
  const YAML::Node* collision = f.find("collision");
  if (collision)
    mesh.collision = r.choice(*collision, "collision", {"convex", "triangles"}) == "convex"
                         ? MeshCollision::convex
                         : MeshCollision::triangles;
  assets::MeshCache::Entry entry;
  try {
    entry = r.meshes().load(mesh.file, mesh.scale, part ? r.string(*part, "part") : std::string());
  } catch (const Error& e) {
    r.fail(file, e.what());  // "<scene>:<line>:<col>: <mesh file>: <defect>"
  }
  if (entry.fresh)
    for (const std::string& warning : entry.body->warnings) r.warn(file, warning);
  mesh.mesh = entry.body->mesh;
  mesh.hull = entry.body->hull;
  if (!collision) mesh.collision = entry.body->convex ? MeshCollision::convex : MeshCollision::triangles;
  if (mesh.collision == MeshCollision::convex && !mesh.hull)
    r.fail(*collision, "'collision: convex' needs a convex hull, and this mesh has none; use 'triangles'");
  return mesh;
}

// Volume and inertia per unit density: closed form for a primitive, Mirtich's for a mesh (computed
// when the mesh was read; looked up by its geometry).
std::optional<UnitMassProperties> unit_mass_properties(const SceneReader& r, const Shape& shape) {
  const auto* mesh = std::get_if<MeshShape>(&shape);
  if (!mesh) return primitive_mass_properties(shape);
  const std::shared_ptr<const assets::MeshBody> body = r.meshes().find(mesh->mesh.get());
  if (!body) return std::nullopt;
  return UnitMassProperties{body->unit.volume, body->unit.inertia};
}

// `inertia: [Ixx, Iyy, Izz]` (principal moments, body axes) or a symmetric 3×3 list of rows.
Mat3 read_inertia(const SceneReader& r, const YAML::Node& node) {
  Mat3 inertia = Mat3::Zero();
  if (node.IsSequence() && node.size() == 3 && node[0].IsSequence()) {
    for (int row = 0; row < 3; ++row) {
      const std::vector<double> values = r.numbers(node[row], "inertia", 3);
      for (int col = 0; col < 3; ++col) inertia(row, col) = values[col];
    }
    const double scale = inertia.cwiseAbs().maxCoeff();
    if ((inertia - inertia.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
      r.fail(node, "'inertia' must be a symmetric matrix");
    inertia = 0.5 * (inertia + inertia.transpose());
  } else {
    const std::vector<double> moments = r.numbers(node, "inertia", 3);
    inertia = Vec3(moments[0], moments[1], moments[2]).asDiagonal();
  }
  const Vec3 principal = Eigen::SelfAdjointEigenSolver<Mat3>(inertia, Eigen::EigenvaluesOnly).eigenvalues();
  if (!(principal.minCoeff() > 0.0))
    r.fail(node, "'inertia' must be positive definite; its principal moments are " +
                     format_number(principal[0]) + ", " + format_number(principal[1]) + ", " +
                     format_number(principal[2]));
  // A real mass distribution has I1 + I2 ≥ I3 for its principal moments (ascending here).
  if (principal[0] + principal[1] < principal[2] * (1.0 - 1e-9))
    r.fail(node, "'inertia' is not that of any rigid body: its principal moments break I1 + I2 >= I3");
  return inertia;
}

// `orientation: [w, x, y, z]`, normalized; the zero quaternion has no direction.
Mat3 read_orientation(const SceneReader& r, const YAML::Node& node) {
  const std::vector<double> q = r.numbers(node, "orientation", 4);
  // Divide by the largest component first: the squared norm of [1e300, …] overflows to inf and that of
  // [1e-200, …] underflows to 0, though both have a direction.
  double largest = 0.0;
  for (double x : q) largest = std::max(largest, std::abs(x));
  if (largest == 0.0) r.fail(node, "'orientation' is the zero quaternion; give [w, x, y, z] with w, x, y, z not all 0");
  const Quat quat(q[0] / largest, q[1] / largest, q[2] / largest, q[3] / largest);
  return quat.normalized().toRotationMatrix();
}

// The body's name if it has a readable one, to name it in messages about its other keys.
std::string context_name(const YAML::Node& node, std::size_t index) {
  if (node.IsMap())
    for (const auto& entry : node)
      if (entry.first.IsScalar() && entry.first.Scalar() == "name" && entry.second.IsScalar())
        return "body '" + entry.second.Scalar() + "'";
  return "body #" + std::to_string(index + 1);
}

}  // namespace

ReadBody read_body(const SceneReader& r, const YAML::Node& node, std::size_t index) {
  const Fields f(r, node, context_name(node, index),
                 {"name", "fixed", "shape", "mass", "density", "inertia", "position", "orientation", "velocity",
                  "angular_velocity", "restitution", "friction", "collision_group", "collision_mask", "force",
                  "torque", "force_body", "torque_body", "motion"});
  ReadBody out;
  RigidBody& body = out.body;
  out.where = f.require("name");
  body.name = r.string(out.where, "name");
  if (body.name.empty()) r.fail(out.where, "'name' must not be empty");
  if (has_control_character(body.name))
    r.fail(out.where, "'name' holds a control character (a line break, tab or NUL); names go into CSV files "
                      "and messages, so write them on one line");
  const bool fixed = f.find("fixed") ? r.boolean(*f.find("fixed"), "fixed") : false;
  const YAML::Node& shape_node = f.require("shape");
  body.shape = read_shape(r, shape_node);

  if (const YAML::Node* n = f.find("position")) body.position = r.vec3(*n, "position");
  if (const YAML::Node* n = f.find("orientation")) body.rotation = read_orientation(r, *n);
  if (const YAML::Node* n = f.find("velocity")) body.velocity = r.vec3(*n, "velocity");
  if (const YAML::Node* n = f.find("angular_velocity")) body.angular_velocity = r.vec3(*n, "angular_velocity");
  if (const YAML::Node* n = f.find("restitution")) body.material.restitution = r.in_range(*n, "restitution", 0.0, 1.0);
  if (const YAML::Node* n = f.find("friction")) body.material.friction = r.non_negative(*n, "friction");
  constexpr long long kMaxBits = std::numeric_limits<std::uint32_t>::max();
  if (const YAML::Node* n = f.find("collision_group"))
    body.collision_group = static_cast<std::uint32_t>(r.integer(*n, "collision_group", 0, kMaxBits));
  if (const YAML::Node* n = f.find("collision_mask"))
    body.collision_mask = static_cast<std::uint32_t>(r.integer(*n, "collision_mask", 0, kMaxBits));

  if (const YAML::Node* n = f.find("force")) body.force = r.vec3(*n, "force");
  if (const YAML::Node* n = f.find("torque")) body.torque = r.vec3(*n, "torque");
  if (const YAML::Node* n = f.find("force_body")) body.force_body = r.vec3(*n, "force_body");
  if (const YAML::Node* n = f.find("torque_body")) body.torque_body = r.vec3(*n, "torque_body");

  const YAML::Node* mass = f.find("mass");
  const YAML::Node* density = f.find("density");
  const YAML::Node* inertia = f.find("inertia");
  const YAML::Node* motion = f.find("motion");
  if (fixed) {
    // A fixed body's mass is infinite: these keys would be silently ignored.
    for (const char* key : {"mass", "density", "inertia"})
      if (const YAML::Node* n = f.find(key))
        r.fail(*n, "'" + std::string(key) + "' does not apply to a fixed body (infinite mass)");
    for (const char* key : {"force", "torque", "force_body", "torque_body"})
      if (const YAML::Node* n = f.find(key))
        r.fail(*n, "'" + std::string(key) + "' does not apply to a fixed body (infinite mass: a load would do "
                   "nothing); give it 'velocity' or 'angular_velocity' to move it");
    // Velocities on a fixed body are its prescribed motion: it moves with them, or with `motion:
    // surface` stays in place while its surface moves (a conveyor belt).
    const bool has_velocity = f.find("velocity") || f.find("angular_velocity");
    if (motion && !has_velocity)
      r.fail(*motion, "'motion' needs the fixed body's 'velocity' or 'angular_velocity'");
    if (has_velocity)
      body.motion = !motion || r.choice(*motion, "motion", {"moving", "surface"}) == "moving" ? PrescribedMotion::moving
                                                                                             : PrescribedMotion::surface;
    make_fixed(body);
    return out;
  }
  if (motion)
    r.fail(*motion, "'motion' (a prescribed motion) applies to fixed bodies only; this body moves under forces "
                    "and contacts");
  if (std::holds_alternative<Plane>(body.shape))
    r.fail(shape_node, "a plane is only allowed on a fixed body; add 'fixed: true' to " + f.context());
  if (mass && density) r.fail(*density, "give either 'mass' or 'density', not both");
  if (!mass && !density) r.fail(node, f.context() + " needs 'mass' or 'density' (it is not fixed)");
  MassSpec spec;
  if (mass) spec.mass = r.positive(*mass, "mass");
  if (density) spec.density = r.positive(*density, "density");
  if (inertia) spec.inertia_body = read_inertia(r, *inertia);
  // Planes were refused above: the shape is a primitive with a closed form, or a validated mesh.
  const std::optional<UnitMassProperties> unit = unit_mass_properties(r, body.shape);
  if (!unit || !(unit->volume > 0.0) || !std::isfinite(unit->volume))
    r.fail(shape_node, "the shape has no finite, positive volume, so it cannot carry a mass");
  set_mass_properties(body, *unit, spec);
  // Extreme but finite inputs can still overflow or underflow (1e300 kg, 1e-200 m).
  if (!std::isfinite(body.mass) || !(body.inv_mass > 0.0) || !std::isfinite(body.inv_mass) ||
      !body.inertia_body.allFinite() || !body.inv_inertia_body.allFinite())
    r.fail(mass ? *mass : *density, "the mass properties of " + f.context() + " are not finite numbers");
  // Finite values whose products are not: the energies and momenta every step measures.
  const Vec3 spin = body.rotation * body.inertia_body * body.rotation.transpose() * body.angular_velocity;
  if (const YAML::Node* n = f.find("velocity"); n && !std::isfinite(body.mass * body.velocity.squaredNorm()))
    r.fail(*n, "'velocity' with mass " + format_number(body.mass) + " overflows the kinetic energy (m |v|² must be finite)");
  if (const YAML::Node* n = f.find("angular_velocity"); n && !std::isfinite(spin.dot(body.angular_velocity)))
    r.fail(*n, "'angular_velocity' overflows the kinetic energy (ω·Iω must be finite)");
  if (const YAML::Node* n = f.find("position"); n && !std::isfinite(body.mass * body.position.norm()))
    r.fail(*n, "'position' with mass " + format_number(body.mass) + " overflows the moments measured about "
               "the origin (m |x| must be finite)");
  return out;
}

}  // namespace impetus::scene_detail
