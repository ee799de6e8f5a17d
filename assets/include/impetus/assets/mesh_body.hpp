#pragma once
/// \file
/// A mesh made ready to be a rigid body: imported, validated, its frame moved to its center of mass
/// (the body frame of docs/conventions.md), its convex hull built and its mass properties computed.
/// The scene loader uses this for `shape: {mesh: …}`; `impetus mass` prints the same numbers.

#include "impetus/assets/mass_properties.hpp"
#include "impetus/assets/mesh_import.hpp"

#include <filesystem>
#include <map>
#include <memory>
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

/// Makes a body from a mesh in file coordinates that require_valid_mesh has accepted; `label` (the
/// file) starts each warning.
MeshBody make_mesh_body(const TriangleMesh& mesh, const std::string& label);

/// Imports `file` (parts merged, unless `part` names one node), validates it and makes a body.
/// Throws Error("<file>: <defect>"), e.g. "part.obj: 4 boundary edges: the mesh is not closed …".
MeshBody load_mesh_body(const std::filesystem::path& file, const ImportOptions& options = {},
                        const std::string& part = {});

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
