#pragma once
// `impetus mass MESH [--density D | --mass M] [--scale S] [--part NAME] [--json]`: the mass properties
// of a mesh file (README.md, "The `impetus` tool"), computed exactly as a scene would.

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace impetus::cli {

/// The options of `impetus mass`.
struct MassArgs {
  std::string mesh;               ///< the mesh file
  std::optional<double> density;  ///< kg/m³ (default 1)
  std::optional<double> mass;     ///< kg, instead of a density
  double scale = 1.0;             ///< multiplies the file's coordinates (after its unit, if it states one)
  std::string part;               ///< one named part (node) of the file instead of all of them merged
  bool json = false;
};

/// Adds the `mass` subcommand to `app`; `args` is filled when it is parsed.
CLI::App* add_mass_command(CLI::App& app, MassArgs& args);

/// Runs it: the report on stdout, warnings on stderr. Throws Error("<file>: <defect>") for a mesh
/// that cannot be read or is not a closed, consistently oriented solid.
int run_mass_command(const MassArgs& args);

}  // namespace impetus::cli
