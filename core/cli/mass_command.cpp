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

int run_mass_command(const MassArgs& args) {
  const MassResult result = compute_mass(args);
  const assets::MeshBody& body = result.body;
  const assets::MassProperties& p = result.properties;
  const Vec3& com = body.center_of_mass_file;  // the body frame's origin, in file coordinates
  for (const std::string& w : body.warnings) std::cerr << "impetus: warning: " << w << "\n";

  if (args.json) {
    const nlohmann::json j = mass_json(args, result);
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
