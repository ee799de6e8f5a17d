#pragma once
// The reply of the importer process (impetus-mesh-import) to the library, and its exit statuses
// (internal). One reply per run, written to the importer's standard output:
//
//   magic "IMPMESH\n" · u32 version · u8 kind · body · "END\n"
//   kind 1, a mesh:  str format · u8 has_unit · f64 unit · u32 warnings · str × warnings ·
//                    u32 parts · per part: str name · u64 vertices · u64 triangles ·
//                    f64 × 3 × vertices (x, y, z) · u32 × 3 × triangles
//   kind 2, an error: str message (complete, naming the file)
//   str = u32 length · bytes
//
// Numbers are in the machine's byte order: both ends are one build on one machine, and the version
// word catches a program from another build. The decoder trusts nothing: every count is checked
// against the bytes that remain before anything is allocated, every index against its vertex count,
// and the reply must end exactly after its end marker.

#include "impetus/assets/mesh_import.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace impetus::assets::detail {

inline constexpr std::uint32_t kProtocolVersion = 1;
/// Exit statuses of the importer besides 0 (a reply was written, a mesh or an error).
inline constexpr int kExitUsage = 2;        ///< bad command line: library and program do not match
inline constexpr int kExitOutOfMemory = 3;  ///< an allocation failed under the memory limit
inline constexpr int kExitSetupFailed = 4;  ///< the limits or the reply channel could not be set up

/// A malformed reply; what() says what is wrong, without the file name.
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A decoded reply: a mesh (its `file` left empty for the caller to fill in), or an error message.
struct Reply {
  std::optional<ImportedMesh> mesh;
  std::string error;
};

/// Limits the importer process puts on itself before assimp runs.
struct ImporterLimits {
  std::uint64_t memory_bytes = 0;  ///< RLIMIT_AS: address space, bytes
  std::uint64_t cpu_seconds = 0;   ///< RLIMIT_CPU: processor time, whole seconds
};

/// What the library asks the importer for: one file, its options and the limits.
struct ImportRequest {
  std::filesystem::path file;
  ImportOptions options;
  ImporterLimits limits;
};

/// The importer's command line for `request`, program name excluded:
/// `--protocol=1 MEMORY_BYTES CPU_SECONDS SCALE(%a, exact) merge|separate convert|as_written FILE`.
std::vector<std::string> importer_arguments(const ImportRequest& request);

/// Parses what importer_arguments wrote (argv[1] onwards). Throws ProtocolError.
ImportRequest parse_importer_arguments(int argc, const char* const* argv);

std::string encode_mesh_reply(const ImportedMesh& mesh);
std::string encode_error_reply(std::string_view message);

/// Decodes one complete reply. Throws ProtocolError. Vertex coordinates may be non-finite (a file may
/// hold NaN; validation reports it with its location); everything else is checked here.
Reply decode_reply(std::string_view bytes);

}  // namespace impetus::assets::detail
