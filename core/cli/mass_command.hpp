#pragma once
// `impetus mass MESH [--density D | --mass M] [--scale S] [--part NAME] [--json]`: the mass properties
// of a mesh file (README.md, "The `impetus` tool"), computed exactly as a scene would.

#include "mass_report.hpp"

#include <CLI/CLI.hpp>

namespace impetus::cli {

/// Adds the `mass` subcommand to `app`; `args` is filled when it is parsed.
CLI::App* add_mass_command(CLI::App& app, MassArgs& args);

/// Runs it: the report on stdout, warnings on stderr. Throws Error("<file>: <defect>") for a mesh
/// that cannot be read or is not a closed, consistently oriented solid.
int run_mass_command(const MassArgs& args);

}  // namespace impetus::cli
