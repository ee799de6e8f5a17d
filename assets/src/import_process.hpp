#pragma once
// The library's side of isolated mesh import (internal): settings from the environment, starting the
// importer process, reading its reply, and turning every way it can fail into an Error naming the file.

#include "import_protocol.hpp"

#include <cstdint>
#include <filesystem>
#include <string>

namespace impetus::assets::detail {

/// How import_mesh runs assimp; read from the environment at each import (mesh_import.hpp lists the
/// variables).
struct IsolationSettings {
  bool isolated = true;
  std::filesystem::path importer;  ///< the impetus-mesh-import program
  std::string importer_origin;     ///< where that path came from, for the "not found" message
  ImporterLimits limits;
  double wall_seconds = 0.0;       ///< wall-clock limit, after which the process is killed
};

/// The settings for importing `file` of `file_size` bytes. Throws Error naming the file and the
/// variable when a variable holds something else than it should.
IsolationSettings isolation_settings(const std::filesystem::path& file, std::uintmax_t file_size);

/// Imports `file` in a new importer process under `settings`. Throws Error("<file>: …") for whatever
/// went wrong: the importer's own error message as it is, or what became of the process (crashed with a
/// signal, out of memory, out of CPU time, timed out, a malformed reply, not found, not startable).
/// Never leaves a zombie or an open descriptor behind; never writes to the process, so it cannot raise
/// SIGPIPE; interrupted system calls are resumed.
ImportedMesh import_isolated(const std::filesystem::path& file, const ImportOptions& options,
                             const IsolationSettings& settings);

}  // namespace impetus::assets::detail
