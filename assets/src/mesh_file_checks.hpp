#pragma once
// Checks of a mesh file before assimp reads it (internal to the asset pipeline).

#include <cstdint>
#include <filesystem>

namespace impetus::assets::detail {

/// Checks that `file` is a non-empty regular file within the size limit (1 GiB) and, for STL, PLY, OFF
/// and COLLADA, free of the defects assimp 5.2 mishandles (truncated binary STL; a PLY header that does
/// not match its body; counts that do not fit the file; stray bytes in number lists). Returns the
/// file's size in bytes. Throws Error("<file>: <problem>").
std::uintmax_t check_mesh_file(const std::filesystem::path& file);

}  // namespace impetus::assets::detail
