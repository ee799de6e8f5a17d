#include "mass_report.hpp"

#include "impetus/core/error.hpp"

#include <cmath>

namespace impetus::cli {
namespace {

nlohmann::json vector_json(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

// A value that overflows, named as the option that gave it ("--scale 1e+70 is too large: …").
[[noreturn]] void rethrow_as_option(const assets::MassOverflow& e) {
  switch (e.cause()) {
    case assets::MassOverflow::Cause::scale: throw Error(e.message_naming("--scale"));
    case assets::MassOverflow::Cause::density: throw Error(e.message_naming("--density"));
    case assets::MassOverflow::Cause::mass: throw Error(e.message_naming("--mass"));
  }
  throw Error(e.what());
}

}  // namespace

MassResult compute_mass(const MassArgs& args) {
  assets::ImportOptions options;
  options.scale = args.scale;
  MassResult result;
  const std::string label = args.mesh + (args.part.empty() ? "" : " (part '" + args.part + "')");
  try {
    result.body = assets::load_mesh_body(args.mesh, options, args.part);
    result.properties = assets::mesh_mass_properties(result.body, args.density, args.mass, label);
  } catch (const assets::MassOverflow& e) {
    rethrow_as_option(e);
  }
  const assets::MassProperties& p = result.properties;
  const Vec3& com = result.body.center_of_mass_file;
  // Nothing that is not a number is ever reported (the library refuses it; this is the last guard).
  if (!(std::isfinite(p.volume) && std::isfinite(p.mass) && std::isfinite(p.density) && p.inertia.allFinite() &&
        p.principal_moments.allFinite() && p.principal_axes.allFinite() && com.allFinite()))
    throw Error(label + ": its mass properties are not finite numbers; nothing is printed");
  return result;
}

nlohmann::json mass_json(const MassArgs& args, const MassResult& result) {
  const assets::MeshBody& body = result.body;
  const assets::MassProperties& p = result.properties;
  nlohmann::json j;
  j["file"] = args.mesh;
  j["format"] = body.format;
  if (!args.part.empty()) j["part"] = args.part;
  j["scale"] = args.scale;
  j["vertices"] = body.mesh->vertices.size();
  j["triangles"] = body.mesh->triangles.size();
  j["convex"] = body.convex;
  j["volume"] = p.volume;
  j["density"] = p.density;
  j["mass"] = p.mass;
  j["center_of_mass"] = vector_json(body.center_of_mass_file);
  j["inertia"] = {vector_json(p.inertia.row(0)), vector_json(p.inertia.row(1)), vector_json(p.inertia.row(2))};
  j["principal_moments"] = vector_json(p.principal_moments);
  j["principal_axes"] = {vector_json(p.principal_axes.col(0)), vector_json(p.principal_axes.col(1)),
                         vector_json(p.principal_axes.col(2))};
  j["warnings"] = body.warnings;
  return j;
}

}  // namespace impetus::cli
