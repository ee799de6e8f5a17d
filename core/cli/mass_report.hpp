#pragma once
// The mass properties of a mesh file as `impetus mass` reports them (README.md, "The `impetus` tool"),
// computed exactly as a scene would; shared by the tool and the Python package (impetus.mass).

#include "impetus/assets/mesh_body.hpp"

#include <nlohmann/json.hpp>

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

/// A mesh, imported and validated, with its mass properties.
struct MassResult {
  assets::MeshBody body;
  assets::MassProperties properties;
};

/// Imports and measures the mesh. Throws Error("<file>: <defect>") for a mesh that cannot be read or is
/// not a closed, consistently oriented solid, and names the option (--scale, --density, --mass) whose
/// value overflows.
MassResult compute_mass(const MassArgs& args);

/// The `mass --json` document.
nlohmann::json mass_json(const MassArgs& args, const MassResult& result);

}  // namespace impetus::cli
