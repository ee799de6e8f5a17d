#pragma once
// The importer process's side of isolation (internal): what impetus-mesh-import does before it lets
// assimp read a file, and how it writes its reply. Shared with the misbehaving test helper
// (tests/assets/fake_mesh_importer.cpp), so the limits tested are the ones the real program sets.

#include "import_protocol.hpp"

#include <string_view>

namespace impetus::assets::detail {

/// Prepares this process to import under `limits`, and returns the file descriptor the reply goes to.
/// Standard output is kept for the reply (as a private descriptor) and then pointed at standard error,
/// so nothing a library prints can corrupt the reply. Sets RLIMIT_AS (memory) and RLIMIT_CPU (soft
/// limit: SIGXCPU; hard limit one second later: SIGKILL), no core files, and a new-handler that exits
/// with kExitOutOfMemory when an allocation fails; on Linux, asks to be killed if the library's
/// thread goes away. Returns −1 (with a message on standard error) if a limit cannot be set.
int enter_importer_process(const ImporterLimits& limits);

/// Writes all of `bytes` to `fd`, retrying after interruptions. False if the pipe is gone.
bool write_reply(int fd, std::string_view bytes);

}  // namespace impetus::assets::detail
