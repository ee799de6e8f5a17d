// A mesh made into a body: center of mass at the origin, convex hull, unit-density properties.

#include "impetus/assets/mesh_body.hpp"

#include "impetus/assets/convex_hull.hpp"
#include "impetus/assets/mesh_validation.hpp"
#include "impetus/core/error.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace impetus::assets {
namespace {

const char* cause_name(MassOverflow::Cause cause) {
  switch (cause) {
    case MassOverflow::Cause::scale: return "scale";
    case MassOverflow::Cause::density: return "density";
    case MassOverflow::Cause::mass: return "mass";
  }
  return "value";
}

std::string overflow_message(const std::string& label, const std::string& name, double value, const std::string& why) {
  const bool bad_value = !(std::isfinite(value) && value > 0.0);
  return label + ": " + name + " " + shortest(value) + " " + (bad_value ? std::string("is not a positive finite number") : why);
}

bool finite_properties(const MassProperties& p) {
  return std::isfinite(p.volume) && std::isfinite(p.mass) && std::isfinite(p.density) && p.inertia.allFinite() &&
         p.center_of_mass.allFinite() && p.principal_moments.allFinite() && p.principal_axes.allFinite();
}

}  // namespace

std::string shortest(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

MassOverflow::MassOverflow(std::string label, Cause cause, double value, std::string why)
    : Error(overflow_message(label, cause_name(cause), value, why)),
      label_(std::move(label)),
      cause_(cause),
      value_(value),
      why_(std::move(why)) {}

std::string MassOverflow::message_naming(const std::string& name) const {
  return overflow_message(label_, name, value_, why_);
}

namespace {

// make_mesh_body for a mesh imported at `scale`: an overflow at a scale other than 1 is the scale's.
MeshBody make_body(const TriangleMesh& mesh, const std::string& label, double scale) {
  MeshBody body;
  body.unit = polyhedral_mass_properties(mesh, 1.0);
  // Finite coordinates can still give integrals beyond a double (the inertia grows as the fifth power of
  // the size): that is no self-intersection, and no number of it may be used.
  if (!finite_properties(body.unit)) {
    const std::string why =
        std::isfinite(body.unit.volume)
            ? "the mesh's mass properties overflow a double (volume " + shortest(body.unit.volume) +
                  " m³; the moments of inertia, which grow as the fifth power of its size, do not fit)"
            : std::string("the mesh's mass properties overflow a double (its volume does not fit)");
    if (scale != 1.0) throw MassOverflow(label, MassOverflow::Cause::scale, scale, "is too large: " + why);
    throw Error(label + ": " + why + ": the mesh is too large");
  }
  // A closed, consistently oriented mesh that intersects itself passes validation, but its integrals
  // are not those of a solid: a principal moment can come out negative or break I1 + I2 >= I3 (found
  // by fuzz/mesh_off). Refuse it here rather than hand a body an impossible inertia.
  const Vec3& moments = body.unit.principal_moments;  // ascending
  if (!moments.allFinite() || !body.unit.center_of_mass.allFinite() || !(moments[0] > 0.0) ||
      moments[0] + moments[1] < moments[2] * (1.0 - 1e-9)) {
    char text[160];
    std::snprintf(text, sizeof text, "(%.6g, %.6g, %.6g)", moments[0], moments[1], moments[2]);
    throw Error(label + ": its principal moments of inertia " + text +
                " are not those of any solid: the mesh probably intersects itself");
  }
  body.center_of_mass_file = body.unit.center_of_mass;
  // The body frame of docs/conventions.md: origin at the center of mass, axes as in the file (so a body
  // with the identity orientation looks as modelled; the inertia is then a full tensor).
  auto centered = std::make_shared<TriangleMesh>(mesh);
  for (Vec3& v : centered->vertices) v -= body.center_of_mass_file;
  body.unit.center_of_mass.setZero();
  try {
    auto hull = std::make_shared<TriangleMesh>(convex_hull(centered->vertices));
    body.convex = is_convex(*centered, *hull);
    body.hull = std::move(hull);
  } catch (const Error& e) {
    body.warnings.push_back(label + ": no convex hull (" + e.what() + "); the mesh can only collide as triangles");
  }
  body.mesh = std::move(centered);
  return body;
}

}  // namespace

MeshBody make_mesh_body(const TriangleMesh& mesh, const std::string& label) { return make_body(mesh, label, 1.0); }

MeshBody load_mesh_body(const std::filesystem::path& file, const ImportOptions& options, const std::string& part) {
  ImportOptions import_options = options;
  if (!part.empty()) import_options.parts = PartMode::separate;
  std::string label = file.string();
  const double scale = options.scale;
  if (!(std::isfinite(scale) && scale > 0.0)) throw MassOverflow(label, MassOverflow::Cause::scale, scale, {});
  ImportedMesh imported = import_mesh(file, import_options);
  TriangleMesh mesh;
  if (part.empty()) {
    for (const ImportedPart& p : imported.parts) {
      const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
      mesh.vertices.insert(mesh.vertices.end(), p.mesh.vertices.begin(), p.mesh.vertices.end());
      for (auto t : p.mesh.triangles) mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    }
    if (imported.parts.size() > 1) weld_identical_vertices(mesh);
  } else {
    std::string names;
    for (const ImportedPart& p : imported.parts) {
      if (p.name == part && mesh.triangles.empty()) mesh = p.mesh;
      names += (names.empty() ? "'" : ", '") + p.name + "'";
    }
    if (mesh.triangles.empty()) throw Error(label + ": no part named '" + part + "'; its parts are " + names);
    label += " (part '" + part + "')";
  }
  std::vector<std::string> warnings = std::move(imported.warnings);
  if (scale != 1.0)
    for (const Vec3& v : mesh.vertices)
      if (v.array().isInf().any())
        throw MassOverflow(label, MassOverflow::Cause::scale, scale,
                           "is too large: a vertex coordinate overflows a double (or the file holds an infinite one)");
  require_valid_mesh(mesh, label, warnings);
  MeshBody body = make_body(mesh, label, scale);
  body.format = imported.format;
  body.warnings.insert(body.warnings.begin(), warnings.begin(), warnings.end());
  return body;
}

MassProperties mesh_mass_properties(const MeshBody& body, std::optional<double> density, std::optional<double> mass,
                                    const std::string& label) {
  MassProperties p = body.unit;
  const auto check = [&](MassOverflow::Cause cause, double value) {
    if (!(std::isfinite(value) && value > 0.0)) throw MassOverflow(label, cause, value, {});
  };
  if (density) {
    check(MassOverflow::Cause::density, *density);
    const double total = *density * p.volume;
    if (!(std::isfinite(total) && total > 0.0))
      throw MassOverflow(label, MassOverflow::Cause::density, *density,
                         total > 0.0 ? "is too large: times the volume " + shortest(p.volume) + " m³, the mass overflows a double"
                                     : "is too small: times the volume " + shortest(p.volume) + " m³, the mass is 0 kg");
    p = with_mass(p, total);
    if (!finite_properties(p))
      throw MassOverflow(label, MassOverflow::Cause::density, *density,
                         "is too large: the moments of inertia (largest at density 1: " +
                             shortest(body.unit.inertia.cwiseAbs().maxCoeff()) + " kg·m²) overflow a double");
  } else if (mass) {
    check(MassOverflow::Cause::mass, *mass);
    p = with_mass(p, *mass);
    if (!finite_properties(p) || !(p.density > 0.0))
      throw MassOverflow(label, MassOverflow::Cause::mass, *mass,
                         "is out of range: with the volume " + shortest(p.volume) +
                             " m³, the density or the moments of inertia it gives do not fit in a double");
  }
  return p;
}

MeshCache::Entry MeshCache::load(const std::filesystem::path& file, double scale, const std::string& part) {
  std::error_code ec;
  std::filesystem::path canonical = std::filesystem::weakly_canonical(file, ec);
  if (ec) canonical = file;
  auto& slot = bodies_[{canonical, scale, part}];
  if (slot) return {slot, false};
  ImportOptions options;
  options.scale = scale;
  slot = std::make_shared<const MeshBody>(load_mesh_body(file, options, part));
  return {slot, true};
}

std::shared_ptr<const MeshBody> MeshCache::find(const TriangleMesh* mesh) const {
  for (const auto& [key, body] : bodies_)
    if (body && body->mesh.get() == mesh) return body;
  return nullptr;
}

}  // namespace impetus::assets
