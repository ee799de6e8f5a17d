// The importer's reply: encoder (in the importer process) and decoder (in the library). The format is
// described in import_protocol.hpp.

#include "import_protocol.hpp"

#include <array>
#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <type_traits>

namespace impetus::assets::detail {
namespace {

constexpr std::string_view kMagic = "IMPMESH\n";
constexpr std::string_view kEnd = "END\n";
constexpr std::uint8_t kKindMesh = 1;
constexpr std::uint8_t kKindError = 2;

class Writer {
 public:
  template <class T>
  void put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out_.append(bytes, sizeof(T));
  }
  void put_text(std::string_view text) {
    put(static_cast<std::uint32_t>(text.size()));
    out_.append(text);
  }
  void put_raw(std::string_view bytes) { out_.append(bytes); }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(std::string_view bytes) : rest_(bytes), total_(bytes.size()) {}

  template <class T>
  T get(const char* what) {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T), what);
    T value;
    std::memcpy(&value, rest_.data(), sizeof(T));
    rest_.remove_prefix(sizeof(T));
    return value;
  }
  std::string get_text(const char* what) {
    const auto length = get<std::uint32_t>(what);
    need(length, what);
    std::string text(rest_.substr(0, length));
    rest_.remove_prefix(length);
    return text;
  }
  void expect(std::string_view marker, const char* what) {
    need(marker.size(), what);
    if (rest_.substr(0, marker.size()) != marker) fail(std::string("no ") + what + " where one belongs");
    rest_.remove_prefix(marker.size());
  }
  /// Checks that `count` items of `item_bytes` each fit in what remains, before anything is allocated.
  void need_items(std::uint64_t count, std::size_t item_bytes, const char* what) {
    if (count > rest_.size() / item_bytes)
      fail(std::string("it announces ") + std::to_string(count) + " " + what + ", more than its remaining " +
           std::to_string(rest_.size()) + " bytes hold");
  }
  bool at_end() const { return rest_.empty(); }
  std::size_t offset() const { return total_ - rest_.size(); }
  [[noreturn]] void fail(const std::string& why) const {
    throw ProtocolError(why + " (at byte " + std::to_string(offset()) + " of " + std::to_string(total_) + ")");
  }

 private:
  void need(std::size_t bytes, const char* what) {
    if (bytes > rest_.size()) fail(std::string("it ends inside ") + what);
  }

  std::string_view rest_;
  std::size_t total_;
};

}  // namespace

std::vector<std::string> importer_arguments(const ImportRequest& request) {
  char scale[64];
  std::snprintf(scale, sizeof scale, "%a", request.options.scale);  // hexadecimal: read back exactly
  return {"--protocol=" + std::to_string(kProtocolVersion),
          std::to_string(request.limits.memory_bytes),
          std::to_string(request.limits.cpu_seconds),
          scale,
          request.options.parts == PartMode::merge ? "merge" : "separate",
          request.options.units == UnitMode::convert ? "convert" : "as_written",
          request.file.string()};
}

ImportRequest parse_importer_arguments(int argc, const char* const* argv) {
  if (argc != 8) throw ProtocolError("expected 7 arguments, got " + std::to_string(argc - 1));
  if (std::string_view(argv[1]) != "--protocol=" + std::to_string(kProtocolVersion))
    throw ProtocolError(std::string("protocol '") + argv[1] + "', expected version " + std::to_string(kProtocolVersion));
  const auto whole = [](const char* text, const char* what) {
    char* end = nullptr;
    errno = 0;
    const std::uintmax_t value = std::strtoumax(text, &end, 10);
    if (errno != 0 || end == text || *end != '\0' || text[0] == '-')
      throw ProtocolError(std::string("bad ") + what + " '" + text + "'");
    return static_cast<std::uint64_t>(value);
  };
  ImportRequest request;
  request.limits.memory_bytes = whole(argv[2], "memory limit");
  request.limits.cpu_seconds = whole(argv[3], "CPU time limit");
  char* end = nullptr;
  request.options.scale = std::strtod(argv[4], &end);
  if (end == argv[4] || *end != '\0') throw ProtocolError(std::string("bad scale '") + argv[4] + "'");
  const std::string_view parts = argv[5], units = argv[6];
  if (parts != "merge" && parts != "separate") throw ProtocolError("bad part mode '" + std::string(parts) + "'");
  if (units != "convert" && units != "as_written") throw ProtocolError("bad unit mode '" + std::string(units) + "'");
  request.options.parts = parts == "merge" ? PartMode::merge : PartMode::separate;
  request.options.units = units == "convert" ? UnitMode::convert : UnitMode::as_written;
  request.file = argv[7];
  return request;
}

std::string encode_mesh_reply(const ImportedMesh& mesh) {
  Writer out;
  out.put_raw(kMagic);
  out.put(kProtocolVersion);
  out.put(kKindMesh);
  out.put_text(mesh.format);
  out.put(static_cast<std::uint8_t>(mesh.file_unit.has_value()));
  out.put(mesh.file_unit.value_or(1.0));
  out.put(static_cast<std::uint32_t>(mesh.warnings.size()));
  for (const std::string& warning : mesh.warnings) out.put_text(warning);
  out.put(static_cast<std::uint32_t>(mesh.parts.size()));
  for (const ImportedPart& part : mesh.parts) {
    out.put_text(part.name);
    out.put(static_cast<std::uint64_t>(part.mesh.vertices.size()));
    out.put(static_cast<std::uint64_t>(part.mesh.triangles.size()));
    for (const Vec3& v : part.mesh.vertices) {
      out.put(v.x());
      out.put(v.y());
      out.put(v.z());
    }
    for (const auto& t : part.mesh.triangles)
      for (std::uint32_t i : t) out.put(i);
  }
  out.put_raw(kEnd);
  return out.take();
}

std::string encode_error_reply(std::string_view message) {
  Writer out;
  out.put_raw(kMagic);
  out.put(kProtocolVersion);
  out.put(kKindError);
  out.put_text(message);
  out.put_raw(kEnd);
  return out.take();
}

Reply decode_reply(std::string_view bytes) {
  if (bytes.empty()) throw ProtocolError("it is empty");
  Reader in(bytes);
  in.expect(kMagic, "magic word");
  const auto version = in.get<std::uint32_t>("the version");
  if (version != kProtocolVersion)
    in.fail("protocol version " + std::to_string(version) + ", expected " + std::to_string(kProtocolVersion) +
            " (the importer program is from another build)");
  Reply reply;
  const auto kind = in.get<std::uint8_t>("the kind");
  if (kind == kKindError) {
    reply.error = in.get_text("the error message");
    if (reply.error.empty()) in.fail("an empty error message");
  } else if (kind == kKindMesh) {
    ImportedMesh mesh;
    mesh.format = in.get_text("the format name");
    const auto has_unit = in.get<std::uint8_t>("the unit flag");
    const auto unit = in.get<double>("the unit");
    if (has_unit > 1) in.fail("a unit flag that is neither 0 nor 1");
    if (has_unit) {
      if (!(std::isfinite(unit) && unit > 0.0)) in.fail("a file unit that is not a positive finite number");
      mesh.file_unit = unit;
    }
    const auto warnings = in.get<std::uint32_t>("the warning count");
    in.need_items(warnings, sizeof(std::uint32_t), "warnings");
    for (std::uint32_t k = 0; k < warnings; ++k) mesh.warnings.push_back(in.get_text("a warning"));
    const auto parts = in.get<std::uint32_t>("the part count");
    if (parts == 0) in.fail("a mesh without parts");
    in.need_items(parts, sizeof(std::uint32_t) + 2 * sizeof(std::uint64_t), "parts");
    for (std::uint32_t k = 0; k < parts; ++k) {
      ImportedPart part;
      part.name = in.get_text("a part name");
      const auto vertices = in.get<std::uint64_t>("a vertex count");
      const auto triangles = in.get<std::uint64_t>("a triangle count");
      if (triangles == 0) in.fail("a part without triangles");
      if (vertices > UINT32_MAX) in.fail("more vertices than 32-bit indices reach");
      in.need_items(vertices, 3 * sizeof(double), "vertices");
      part.mesh.vertices.reserve(vertices);
      for (std::uint64_t v = 0; v < vertices; ++v) {
        const auto x = in.get<double>("a vertex");
        const auto y = in.get<double>("a vertex");
        const auto z = in.get<double>("a vertex");
        part.mesh.vertices.emplace_back(x, y, z);
      }
      in.need_items(triangles, 3 * sizeof(std::uint32_t), "triangles");
      part.mesh.triangles.reserve(triangles);
      for (std::uint64_t t = 0; t < triangles; ++t) {
        std::array<std::uint32_t, 3> triangle{};
        for (std::uint32_t& i : triangle) {
          i = in.get<std::uint32_t>("a triangle");
          if (i >= vertices)
            in.fail("a triangle index " + std::to_string(i) + " beyond the part's " + std::to_string(vertices) +
                    " vertices");
        }
        part.mesh.triangles.push_back(triangle);
      }
      mesh.parts.push_back(std::move(part));
    }
    reply.mesh = std::move(mesh);
  } else {
    in.fail("unknown reply kind " + std::to_string(kind));
  }
  in.expect(kEnd, "end marker");
  if (!in.at_end()) in.fail("bytes after the end marker");
  return reply;
}

}  // namespace impetus::assets::detail
