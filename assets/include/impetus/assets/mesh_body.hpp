#pragma once
/// \file
/// A mesh made ready to be a rigid body: imported, validated, its frame moved to its center of mass
/// (the body frame of docs/conventions.md), its convex hull built and its mass properties computed.
/// The scene loader uses this for `shape: {mesh: …}`; `impetus mass` prints the same numbers.

#include "impetus/assets/mass_properties.hpp"
#include "impetus/assets/mesh_import.hpp"
#include "impetus/core/error.hpp"

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

namespace impetus::assets {

/// A validated mesh in its body frame, with what a body needs from it.
struct MeshBody {
  std::shared_ptr<const TriangleMesh> mesh;  ///< body frame: origin at the center of mass, file axes
  std::shared_ptr<const TriangleMesh> hull;  ///< its convex hull, same frame
  bool convex = false;    ///< the mesh is its own convex hull (to a relative 1e-9 in volume)
  MassProperties unit;    ///< for density 1 kg/m³, body frame (center_of_mass is zero)
  Vec3 center_of_mass_file = Vec3::Zero();  ///< the center of mass in the file's coordinates (m)
  std::string format;     ///< the importer that read the file
  std::vector<std::string> warnings;  ///< from import and validation, each naming the file
};

/// A scale, density or mass that makes a mesh's mass properties overflow a double (or that is not a
/// positive finite number). what() reads "<file>: <name> <value> <why>", e.g. "cube.obj: scale 1e+70 is
/// too large: the mesh's mass properties overflow a double (…)", the value in shortest round-trip form;
/// message_naming lets a caller name its own option ("--scale") instead.
class MassOverflow : public Error {
 public:
  enum class Cause { scale, density, mass };
  MassOverflow(std::string label, Cause cause, double value, std::string why);
  const std::string& label() const { return label_; }  ///< the mesh file (and part)
  Cause cause() const { return cause_; }
  double value() const { return value_; }
  const std::string& why() const { return why_; }  ///< "is too large: …" (empty for a non-finite value)
  /// The message with the value's `name` in place of "scale", "density" or "mass".
  std::string message_naming(const std::string& name) const;

 private:
  std::string label_;
  Cause cause_;
  double value_;
  std::string why_;
};

/// `value` in shortest round-trip form (std::to_chars), as messages print a number the user gave.
std::string shortest(double value);

/// Makes a body from a mesh in file coordinates that require_valid_mesh has accepted; `label` (the
/// file) starts each warning.
MeshBody make_mesh_body(const TriangleMesh& mesh, const std::string& label);

/// Imports `file` (parts merged, unless `part` names one node), validates it and makes a body.
/// Throws Error("<file>: <defect>"), e.g. "part.obj: 4 boundary edges: the mesh is not closed …";
/// MassOverflow when `options.scale` is not a positive finite number or makes a coordinate, the volume
/// or the inertia overflow a double.
MeshBody load_mesh_body(const std::filesystem::path& file, const ImportOptions& options = {},
                        const std::string& part = {});

/// `body`'s mass properties (body frame) at `density` kg/m³, or for a total `mass` kg (one of them; neither:
/// density 1). Throws MassOverflow when the value is not a positive finite number or when the mass or
/// inertia it gives is not finite (e.g. density 1e308 on a mesh of volume 2).
MassProperties mesh_mass_properties(const MeshBody& body, std::optional<double> density,
                                    std::optional<double> mass, const std::string& label);

/// Mesh bodies by (file, scale, part), so bodies naming the same mesh share one import and one
/// geometry. One cache serves one scene load (it never notices a file changing).
class MeshCache {
 public:
  /// A cached body and whether this call imported it (so its warnings are reported once).
  struct Entry {
    std::shared_ptr<const MeshBody> body;
    bool fresh = false;
  };
  /// The body for `file` at `scale` (and `part`), importing it on first use. Throws like
  /// load_mesh_body.
  Entry load(const std::filesystem::path& file, double scale, const std::string& part = {});
  /// The cached body whose body-frame mesh is `mesh`, or null.
  std::shared_ptr<const MeshBody> find(const TriangleMesh* mesh) const;

 private:
  std::map<std::tuple<std::filesystem::path, double, std::string>, std::shared_ptr<const MeshBody>> bodies_;
};

}  // namespace impetus::assets
