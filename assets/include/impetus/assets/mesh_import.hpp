#pragma once
/// \file
/// Mesh import: Wavefront OBJ, ASCII STL, ASCII PLY and OFF by the engine's own readers at double
/// precision; binary STL, binary PLY, glTF 2.0 (.gltf/.glb), COLLADA and the other formats assimp reads
/// through assimp 5.2, whose vertices are float32 (binary STL and glTF store float32 by definition;
/// assets/README.md, "Precision"). The result is the engine's own TriangleMesh: no assimp type crosses
/// this header.
///
/// Conventions. Coordinates are taken in the file's own axes (no up-axis conversion: rotate a body
/// with the scene's `orientation`). Lengths come out in metres: a file that states its unit (COLLADA
/// `<unit meter=…>`, FBX `UnitScaleFactor`) is converted, with a warning; a file that carries no unit
/// (OBJ, STL, PLY, OFF) is read as metres, and a warning suggests a scale when the mesh is more than
/// 10 m across (a part in millimetres or centimetres). glTF is metres by its specification.
/// Triangles are counter-clockwise seen from outside; polygons are triangulated (convex ones as fans,
/// others by ear clipping), points and lines
/// dropped (with a warning), and vertices at identical positions welded (assimp's
/// aiProcess_JoinIdenticalVertices is not used: it keeps STL's per-facet vertices apart because their
/// normals differ, and it merges within a tolerance rather than on equality).
///
/// Isolation. assimp (or the text reader) reads the file in a separate process, `impetus-mesh-import`, found next to
/// libimpetus_assets.so (`<libdir>/impetus/libexec/`, in the build tree and in an installed, relocated
/// prefix alike). assimp 5.2 can crash, abort or allocate without bound on a malformed file; in that
/// process this ends the import with an Error naming the file and what happened, never the program.
/// The process imports under limits, and the library checks everything it sends back. Environment
/// variables, read at each import:
/// - `IMPETUS_MESH_IMPORT`: `isolated` (default) or `in-process` (assimp in the calling process: no
///   process cost, no protection; for debugging);
/// - `IMPETUS_MESH_IMPORT_MEMORY_MB`: address-space limit (RLIMIT_AS) in MiB; default 1024 MiB plus
///   16 bytes per byte of the file;
/// - `IMPETUS_MESH_IMPORT_CPU_SECONDS`: CPU time limit (RLIMIT_CPU); default 60 s;
/// - `IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS`: wall-clock limit, after which the process is killed;
///   default 120 s;
/// - `IMPETUS_MESH_IMPORT_HELPER`: the importer program's path, instead of the default place.
/// The process costs a few milliseconds per import (assets/README.md). It is started with posix_spawn
/// (safe in a program with threads, and imports may run concurrently); it is always reaped, its pipes
/// always closed; the library never writes to it (no SIGPIPE) and resumes interrupted system calls.

#include "impetus/core/shape.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace impetus::assets {

/// What becomes of several meshes in one file.
enum class PartMode : std::uint8_t {
  merge,    ///< default: every mesh in the file, placed by its node transform, becomes one mesh
  separate  ///< one part per scene-graph node that carries meshes (an OBJ object, a glTF node, …)
};

/// What becomes of a length unit the file states.
enum class UnitMode : std::uint8_t {
  convert,    ///< default: convert to metres (a warning says so)
  as_written  ///< keep the numbers as written (a warning names the file's unit)
};

/// How to import a mesh file.
struct ImportOptions {
  /// Multiplies every coordinate after unit conversion (e.g. 0.001 for a unitless file in mm). > 0.
  double scale = 1.0;
  PartMode parts = PartMode::merge;
  UnitMode units = UnitMode::convert;
};

/// One imported part: metres (after unit conversion and scale), the file's axes, welded vertices.
struct ImportedPart {
  std::string name;  ///< the node's name (may be empty; in merge mode the file's stem)
  TriangleMesh mesh;
};

/// The result of importing one file.
struct ImportedMesh {
  std::filesystem::path file;
  std::string format;                ///< e.g. "Wavefront OBJ (double precision)", or assimp's importer name
  std::optional<double> file_unit;   ///< metres per file unit, when the file states one
  std::vector<ImportedPart> parts;   ///< one (merge) or one per node with meshes (separate)
  std::vector<std::string> warnings; ///< complete sentences, each naming the file
};

/// Imports `file`. Throws Error("<file>: <problem>") when it cannot be opened, is empty, is a
/// truncated binary STL, cannot be parsed (a text format: "<file>: malformed OBJ: line N: …"), or holds
/// no triangles; and, with isolation, when the
/// importer process crashed (the signal is named), ran out of its memory, CPU time or wall-clock limit,
/// sent a malformed reply, or cannot be found or started. The mesh is not validated here (see
/// mesh_validation.hpp). May be called from several threads at once.
ImportedMesh import_mesh(const std::filesystem::path& file, const ImportOptions& options = {});

/// Welds vertices at exactly equal positions (−0 equals +0; NaN never equals anything), renumbers
/// the triangles, and drops vertices no triangle uses.
void weld_identical_vertices(TriangleMesh& mesh);

}  // namespace impetus::assets
