#pragma once
// The assimp stage of mesh import (internal): compiled into both the core library (in-process import)
// and the importer program impetus-mesh-import (isolated import, the default).

#include "impetus/assets/mesh_import.hpp"

#include <cstddef>
#include <filesystem>
#include <string>

namespace impetus::assets::detail {

/// Reads `file` with assimp and turns its scene graph into parts: node transforms applied, units
/// converted, `options.scale` applied, points and lines dropped, vertices welded; warnings for a stated
/// unit and for a huge unitless mesh. Expects a file that passed check_mesh_file. Throws
/// Error("<file>: …") for a file assimp cannot read or that holds no triangles. May crash, abort or
/// exhaust memory inside assimp on a malformed file: that is why it runs in its own process by default.
ImportedMesh read_with_assimp(const std::filesystem::path& file, const ImportOptions& options);

/// The common end of every reader: refuses a file whose parts hold no triangles (naming the `dropped`
/// points and lines), warns about dropped ones, welds each part, and warns when a unitless mesh read at
/// scale 1 is more than 10 m across. `out.file` and `out.format` must be set.
void finish_import(ImportedMesh& out, std::size_t dropped, const ImportOptions& options);

/// The assimp in use, as "assimp 5.2" (named in the importer's failure messages).
std::string assimp_version();

}  // namespace impetus::assets::detail
