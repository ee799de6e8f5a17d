// `impetus mass`: import, validate, and print volume, mass, center of mass, inertia about it, and the
// principal moments and axes of a mesh.

#include "mass_command.hpp"

#include "impetus/assets/mesh_body.hpp"
#include "impetus/core/error.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>

namespace impetus::cli {
namespace {

nlohmann::json vector_json(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

std::string text(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", x + 0.0);  // + 0.0: no "-0"
  return buffer;
}

std::string text(const Vec3& v) { return text(v.x()) + "  " + text(v.y()) + "  " + text(v.z()); }

}  // namespace

CLI::App* add_mass_command(CLI::App& app, MassArgs& args) {
  auto* cmd = app.add_subcommand("mass", "volume, mass, center of mass and inertia of a closed mesh");
  cmd->add_option("mesh", args.mesh, "mesh file (OBJ, STL, PLY, OFF, glTF/GLB, COLLADA, … read by assimp)")
      ->required();
  auto* density = cmd->add_option("--density", args.density, "density in kg/m³ (default 1)")
                      ->check(CLI::PositiveNumber);
  cmd->add_option("--mass", args.mass, "total mass in kg, instead of a density")
      ->check(CLI::PositiveNumber)
      ->excludes(density);
  cmd->add_option("--scale", args.scale, "multiply coordinates by S (after the file's unit, if it states one)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--part", args.part, "only the named part (node) of a file that holds several");
  cmd->add_flag("--json", args.json, "print the result as JSON");
  return cmd;
}

namespace {

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

int run_mass_command(const MassArgs& args) {
  assets::ImportOptions options;
  options.scale = args.scale;
  assets::MeshBody body;
  assets::MassProperties p;
  const std::string label = args.mesh + (args.part.empty() ? "" : " (part '" + args.part + "')");
  try {
    body = assets::load_mesh_body(args.mesh, options, args.part);
    p = assets::mesh_mass_properties(body, args.density, args.mass, label);
  } catch (const assets::MassOverflow& e) {
    rethrow_as_option(e);
  }
  const Vec3& com = body.center_of_mass_file;  // the body frame's origin, in file coordinates
  // Nothing that is not a number is ever printed (the library refuses it; this is the last guard).
  if (!(std::isfinite(p.volume) && std::isfinite(p.mass) && std::isfinite(p.density) && p.inertia.allFinite() &&
        p.principal_moments.allFinite() && p.principal_axes.allFinite() && com.allFinite()))
    throw Error(label + ": its mass properties are not finite numbers; nothing is printed");
  for (const std::string& w : body.warnings) std::cerr << "impetus: warning: " << w << "\n";

  if (args.json) {
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
    j["center_of_mass"] = vector_json(com);
    j["inertia"] = {vector_json(p.inertia.row(0)), vector_json(p.inertia.row(1)), vector_json(p.inertia.row(2))};
    j["principal_moments"] = vector_json(p.principal_moments);
    j["principal_axes"] = {vector_json(p.principal_axes.col(0)), vector_json(p.principal_axes.col(1)),
                           vector_json(p.principal_axes.col(2))};
    j["warnings"] = body.warnings;
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "mesh                 " << args.mesh << (args.part.empty() ? "" : " (part '" + args.part + "')")
            << "\n"
            << "                     " << body.format << ", " << body.mesh->vertices.size() << " vertices, "
            << body.mesh->triangles.size() << " triangles, "
            << (body.convex ? "convex" : "not convex") << "\n"
            << "volume               " << text(p.volume) << " m³\n"
            << "density              " << text(p.density) << " kg/m³"
            << (args.density || args.mass ? "" : " (default; set --density or --mass)") << "\n"
            << "mass                 " << text(p.mass) << " kg\n"
            << "center of mass       " << text(com) << " m (file coordinates)\n"
            << "inertia about the center of mass (kg·m², file axes):\n";
  for (int row = 0; row < 3; ++row) std::cout << "                     " << text(Vec3(p.inertia.row(row))) << "\n";
  std::cout << "principal moments    " << text(p.principal_moments) << " kg·m²\n"
            << "principal axes       ";
  for (int k = 0; k < 3; ++k) std::cout << (k ? "\n                     " : "") << text(Vec3(p.principal_axes.col(k)));
  std::cout << "\n";
  return 0;
}

}  // namespace impetus::cli
