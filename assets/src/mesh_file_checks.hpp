#pragma once
// Checks of a mesh file before assimp reads it (internal to the asset pipeline).

#include <cstdint>
#include <filesystem>

namespace impetus::assets::detail {

/// The largest mesh file read (1 GiB), and the largest file a mesh may refer to (a glTF buffer, an OBJ
/// material library, …; assimp_reader.cpp): assimp holds the whole file and its scene graph in memory.
inline constexpr std::uintmax_t kMaxMeshBytes = std::uintmax_t{1} << 30;

/// The most text all of one file's `data:` URIs may hold together (64 MiB, so 48 MiB of base64-decoded
/// data): assimp decodes them into memory from the glTF text, where no file size bounds them separately.
/// A larger buffer belongs in a file beside the mesh or in a .glb.
inline constexpr std::uintmax_t kMaxDataUriBytes = std::uintmax_t{64} << 20;

/// Checks that `file` is a non-empty regular file within the size limit (kMaxMeshBytes), that a glTF
/// (JSON text, or a .glb's JSON chunk) holds no more than kMaxDataUriBytes of `data:` URIs, and, for
/// STL, PLY, OFF and COLLADA, free of the defects assimp 5.2 mishandles (truncated binary STL; a PLY header that does
/// not match its body; counts that do not fit the file; stray bytes in number lists). Returns the
/// file's size in bytes. Throws Error("<file>: <problem>").
std::uintmax_t check_mesh_file(const std::filesystem::path& file);

}  // namespace impetus::assets::detail
