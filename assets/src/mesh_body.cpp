// A mesh made into a body: center of mass at the origin, convex hull, unit-density properties.

#include "impetus/assets/mesh_body.hpp"

#include "impetus/assets/convex_hull.hpp"
#include "impetus/assets/mesh_validation.hpp"
#include "impetus/core/error.hpp"

#include <cstdio>

namespace impetus::assets {

MeshBody make_mesh_body(const TriangleMesh& mesh, const std::string& label) {
  MeshBody body;
  body.unit = polyhedral_mass_properties(mesh, 1.0);
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

MeshBody load_mesh_body(const std::filesystem::path& file, const ImportOptions& options, const std::string& part) {
  ImportOptions import_options = options;
  if (!part.empty()) import_options.parts = PartMode::separate;
  ImportedMesh imported = import_mesh(file, import_options);
  std::string label = file.string();
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
  require_valid_mesh(mesh, label, warnings);
  MeshBody body = make_mesh_body(mesh, label);
  body.format = imported.format;
  body.warnings.insert(body.warnings.begin(), warnings.begin(), warnings.end());
  return body;
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
