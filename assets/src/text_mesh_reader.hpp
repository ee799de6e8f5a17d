#pragma once
// The text mesh formats at double precision (internal): Wavefront OBJ, ASCII STL, ASCII PLY and OFF.
// Compiled into both the library (in-process import) and the importer program, like assimp_reader.

#include "impetus/assets/mesh_import.hpp"

#include <filesystem>
#include <optional>

namespace impetus::assets::detail {

/// Reads `file` with the engine's own double-precision reader when it is a text format that reader
/// takes (by extension: .obj; .stl holding ASCII; .ply with `format ascii`; .off with a plain `OFF`
/// header), else returns nothing. Same result and conventions as read_with_assimp (scale applied,
/// points and lines dropped with a warning, vertices welded, the large-mesh warning); polygons are
/// triangulated (convex ones as fans, others by ear clipping). Throws
/// Error("<file>: malformed <format>: line N: …") for a file it cannot read; never allocates more than
/// the file's contents can justify.
std::optional<ImportedMesh> read_text_mesh(const std::filesystem::path& file, const ImportOptions& options);

/// read_text_mesh when it takes the file, else read_with_assimp: what both import paths call.
ImportedMesh read_mesh_file(const std::filesystem::path& file, const ImportOptions& options);

}  // namespace impetus::assets::detail
