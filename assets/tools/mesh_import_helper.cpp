// impetus-mesh-import: the importer process. The library (assets/src/import_process.cpp) starts it for
// each mesh file it imports, so that a crash, abort, runaway allocation or endless loop inside assimp
// ends this process and not the program that embeds the engine. It is not meant to be run by hand:
// its command line and reply are described in assets/src/import_protocol.hpp.
//
// Exit status: 0 after writing a reply (a mesh, or an error message naming the file); 2 for a command
// line it does not understand (a library from another build); 3 when an allocation failed under the
// memory limit; 4 when its limits could not be set; a signal when assimp crashed or the CPU time limit
// ran out.

#include "import_protocol.hpp"
#include "importer_process.hpp"
#include "text_mesh_reader.hpp"

#include "impetus/core/error.hpp"

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  namespace detail = impetus::assets::detail;
  detail::ImportRequest request;
  try {
    request = detail::parse_importer_arguments(argc, argv);
  } catch (const detail::ProtocolError& e) {
    std::fprintf(stderr, "impetus-mesh-import: %s (this program is started by the Impetus library)\n", e.what());
    return detail::kExitUsage;
  }
  const int reply = detail::enter_importer_process(request.limits);
  if (reply < 0) return detail::kExitSetupFailed;
  std::string bytes;
  try {
    impetus::assets::ImportedMesh mesh = detail::read_mesh_file(request.file, request.options);
    bytes = detail::encode_mesh_reply(mesh);
  } catch (const impetus::Error& e) {
    bytes = detail::encode_error_reply(e.what());
  } catch (const std::exception& e) {
    bytes = detail::encode_error_reply(request.file.string() + ": the importer failed: " + e.what());
  }
  return detail::write_reply(reply, bytes) ? 0 : 1;
}
