// A mesh importer that misbehaves on purpose, for test_mesh_import_isolation.cpp: the library is pointed
// at it with IMPETUS_MESH_IMPORT_HELPER, and IMPETUS_FAKE_IMPORTER says what to do. It reads the real
// command line and sets the real limits (importer_process.cpp) first, so what it provokes is what the
// real importer would meet.
//
//   ok, slow-ok        a valid reply (a tetrahedron), at once or after 300 ms
//   error              an error reply whose message does not name the file
//   segv, abort        crash with SIGSEGV, or print a line and abort
//   oom                allocate until the memory limit stops it
//   hang, spin         sleep or burn CPU forever (wall-clock and CPU time limits)
//   linger             a valid reply, then stay alive without exiting
//   exit-7             exit with status 7 and no reply
//   garbage            bytes that are not a reply
//   truncated          the first half of a valid reply
//   bad-index          a well-formed reply whose triangle points past the vertices
//   huge-count         a reply announcing 4 000 000 000 vertices
//   flood              reply bytes without end

#include "import_protocol.hpp"
#include "importer_process.hpp"

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace {

using namespace impetus;
using namespace impetus::assets::detail;

std::string tetrahedron_reply(std::uint32_t last_index) {
  assets::ImportedMesh mesh;
  mesh.format = "fake";
  assets::ImportedPart part;
  part.mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  part.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, last_index}};
  mesh.parts.push_back(part);
  return encode_mesh_reply(mesh);
}

}  // namespace

int main(int argc, char** argv) {
  ImportRequest request;
  try {
    request = parse_importer_arguments(argc, argv);
  } catch (const ProtocolError& e) {
    std::fprintf(stderr, "fake importer: %s\n", e.what());
    return kExitUsage;
  }
  const int reply = enter_importer_process(request.limits);
  if (reply < 0) return kExitSetupFailed;
  const char* env = std::getenv("IMPETUS_FAKE_IMPORTER");
  const std::string mode = env ? env : "ok";

  if (mode == "ok") return write_reply(reply, tetrahedron_reply(3)) ? 0 : 1;
  if (mode == "slow-ok") {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    return write_reply(reply, tetrahedron_reply(3)) ? 0 : 1;
  }
  if (mode == "error") return write_reply(reply, encode_error_reply("something is wrong with it")) ? 0 : 1;
  if (mode == "segv") std::raise(SIGSEGV);
  if (mode == "abort") {
    std::fprintf(stderr, "fake importer: an assertion failed\n");
    std::abort();
  }
  if (mode == "oom") {
    std::vector<std::unique_ptr<char[]>> blocks;
    for (;;) blocks.push_back(std::make_unique<char[]>(std::size_t{16} << 20));
  }
  if (mode == "hang" || mode == "linger") {
    if (mode == "linger") {
      write_reply(reply, tetrahedron_reply(3));
      ::close(reply);
    }
    for (;;) ::pause();
  }
  if (mode == "spin") {
    volatile std::uint64_t n = 0;
    for (;;) n = n + 1;
  }
  if (mode == "exit-7") return 7;
  if (mode == "garbage") return write_reply(reply, "this is not a reply") ? 0 : 1;
  if (mode == "truncated") {
    const std::string bytes = tetrahedron_reply(3);
    return write_reply(reply, bytes.substr(0, bytes.size() / 2)) ? 0 : 1;
  }
  if (mode == "bad-index") return write_reply(reply, tetrahedron_reply(7)) ? 0 : 1;
  if (mode == "huge-count") {
    // magic 8, version 4, kind 1, format (4 + 4 "fake"), unit flag 1, unit 8, warnings 4, parts 4,
    // name 4: the vertex count is the u64 at byte 42.
    std::string bytes = tetrahedron_reply(3);
    const std::uint64_t huge = 4'000'000'000;
    std::memcpy(bytes.data() + 42, &huge, sizeof huge);
    return write_reply(reply, bytes) ? 0 : 1;
  }
  if (mode == "flood") {  // from a static block: the test's memory limit leaves no room to allocate
    static char block[1 << 16];
    std::memset(block, 'x', sizeof block);
    while (write_reply(reply, std::string_view(block, sizeof block))) {
    }
    return 1;
  }
  std::fprintf(stderr, "fake importer: unknown IMPETUS_FAKE_IMPORTER '%s'\n", mode.c_str());
  return 9;
}
