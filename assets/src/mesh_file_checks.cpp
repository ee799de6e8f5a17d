// Checks of a mesh file made before assimp reads it: what the file system says (exists, regular,
// not empty, not too large) and, per format, the defects that assimp 5.2 does not survive gracefully
// (found by the fuzzers, fuzz/README.md). They run in the calling process, before the importer process
// is started, so a clear message comes without the cost of a process.

#include "mesh_file_checks.hpp"

#include "impetus/core/error.hpp"
#include "text.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

namespace impetus::assets::detail {
namespace {

// assimp's message for a truncated binary STL ("Failed to determine STL storage representation") does
// not say what is wrong; the header says how long the file must be, so check it first.
void check_binary_stl(const std::filesystem::path& file, std::uintmax_t size) {
  if (lower(file.extension().string()) != ".stl") return;
  std::ifstream in(file, std::ios::binary);
  std::array<char, 84> header{};
  in.read(header.data(), header.size());
  const auto got = static_cast<std::size_t>(in.gcount());
  if (got >= 5 && std::memcmp(header.data(), "solid", 5) == 0) return;  // ASCII (or a binary header
                                                                          // that starts like one)
  if (got < header.size())
    throw Error(file.string() + ": truncated binary STL: " + std::to_string(size) +
                " bytes, fewer than its 84-byte header");
  std::uint32_t facets = 0;  // little-endian uint32 after the 80-byte comment
  for (int k = 3; k >= 0; --k) facets = (facets << 8) | static_cast<unsigned char>(header[80 + k]);
  const std::uintmax_t expected = 84 + 50 * std::uintmax_t{facets};
  if (size < expected)
    throw Error(file.string() + ": truncated binary STL: its header announces " + std::to_string(facets) +
                " triangles (" + std::to_string(expected) + " bytes) but the file has " + std::to_string(size) +
                " bytes");
}

// Reads the rest of `in` and refuses anything that cannot be part of a list of numbers: assimp's text
// readers do not all survive stray bytes. '#' starts a comment line (OFF).
void require_number_text(const std::filesystem::path& file, std::istream& in, const char* format) {
  std::string line;
  std::uintmax_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line[0] == '#') continue;
    for (const char ch : line) {
      const auto c = static_cast<unsigned char>(ch);
      if (!(std::isdigit(c) || std::isspace(c) || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E'))
        throw Error(file.string() + ": malformed " + format + ": line " + std::to_string(number) +
                    " of its data holds a character that is not part of a number");
    }
  }
}

// assimp 5.2's OFF reader allocates what the counts line announces before reading (a 200-byte file
// announcing 777 777 774 faces made it allocate 12 GB; fuzz/mesh_off): each count must fit the file.
void check_off(const std::filesystem::path& file, std::uintmax_t size) {
  if (lower(file.extension().string()) != ".off") return;
  std::ifstream in(file, std::ios::binary);
  std::string line;
  bool counts_read = false;
  while (!counts_read && std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string first;
    if (!(words >> first) || first[0] == '#') continue;
    if (first.find("OFF") != std::string::npos) {
      if (!(words >> first)) continue;  // counts on the next line
    }
    std::istringstream counts(line.substr(line.find(first)));
    double vertices = -1, faces = -1;
    if (!(counts >> vertices >> faces) || vertices < 0 || faces < 0)
      throw Error(file.string() + ": malformed OFF: no vertex and face counts");
    // Each vertex and face takes at least two bytes of text.
    if (vertices > static_cast<double>(size) / 2 || faces > static_cast<double>(size) / 2)
      throw Error(file.string() + ": malformed OFF: it announces " + number(vertices) + " vertices and " +
                  number(faces) + " faces, more than its " + std::to_string(size) + " bytes can hold");
    counts_read = true;
  }
  require_number_text(file, in, "OFF");
}

// assimp 5.2's PLY reader trusts the header: a header without `end_header`, or a binary body shorter than
// the header announces, makes it read past its buffer (found by fuzz/mesh_ply). So the header is checked
// here first: known lines only, an end, and for a binary body at least the bytes its elements need.
void check_ply(const std::filesystem::path& file, std::uintmax_t size) {
  std::ifstream in(file, std::ios::binary);
  std::string magic(4, '\0');
  in.read(magic.data(), 4);
  if (in.gcount() < 4 || magic.compare(0, 3, "ply") != 0 || (magic[3] != '\n' && magic[3] != '\r')) {
    if (lower(file.extension().string()) == ".ply") throw Error(file.string() + ": not a PLY file: it does not start with 'ply'");
    return;  // not PLY; another reader's business
  }
  const auto bad = [&](const std::string& why) { throw Error(file.string() + ": malformed PLY header: " + why); };
  const std::uintmax_t kMaxHeader = 1 << 16;
  bool binary = false, little_endian = true, ended = false;
  struct Property {
    std::uintmax_t size = 0;        // bytes of a scalar, or of each list item
    std::uintmax_t count_size = 0;  // > 0: a list, whose length takes this many bytes
  };
  struct Element {
    std::string name;
    std::uintmax_t count = 0;
    std::vector<Property> properties;
  };
  std::vector<Element> elements;
  const auto type_size = [](const std::string& t) -> std::uintmax_t {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
    if (t == "double" || t == "float64") return 8;
    return 0;
  };
  std::string line;
  while (static_cast<std::uintmax_t>(in.tellg()) < kMaxHeader && std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") {
      ended = true;
      break;
    }
    if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) continue;
    if (keyword == "format") {
      std::string kind;
      words >> kind;
      if (kind != "ascii" && kind != "binary_little_endian" && kind != "binary_big_endian")
        bad("unknown format '" + kind + "'");
      binary = kind != "ascii";
      little_endian = kind == "binary_little_endian";
    } else if (keyword == "element") {
      std::string name;
      Element element;
      if (!(words >> name >> element.count)) bad("an element line needs a name and a count: '" + line + "'");
      element.name = name;
      if (element.count > size) bad("element '" + name + "' announces more items than the file has bytes");
      elements.push_back(element);
    } else if (keyword == "property") {
      if (elements.empty()) bad("a property before any element");
      std::string type, item_type;
      words >> type;
      Property property;
      if (type == "list") {
        words >> type >> item_type;
        property.count_size = type_size(type);
        property.size = type_size(item_type);
        if (property.count_size == 0 || property.size == 0) bad("unknown list types '" + type + " " + item_type + "'");
      } else {
        property.size = type_size(type);
        if (property.size == 0) bad("unknown property type '" + type + "'");
      }
      elements.back().properties.push_back(property);
    } else {
      bad("unknown header line '" + line.substr(0, 40) + "'");
    }
  }
  if (!ended) bad("no 'end_header' line in its first " + std::to_string(kMaxHeader) + " bytes");
  // Faces with no vertex element to index made assimp 5.2 loop until its CPU limit (fuzz/mesh_ply).
  const auto count_of = [&](const std::string& name) {
    std::uintmax_t count = 0;
    for (const Element& element : elements)
      if (element.name == name) count += element.count;
    return count;
  };
  if (count_of("face") > 0 && count_of("vertex") == 0)
    bad(std::to_string(count_of("face")) + " faces but no vertices (no 'element vertex' with a count above 0)");
  if (binary) {
    // Walk the body as assimp will, list lengths included (garbage lengths made it abort; fuzz/mesh_ply).
    std::uintmax_t at = static_cast<std::uintmax_t>(in.tellg());
    const auto truncated = [&] {
      throw Error(file.string() + ": truncated binary PLY: its header and list lengths announce more data than its " +
                  std::to_string(size) + " bytes");
    };
    for (const Element& element : elements)
      for (std::uintmax_t item = 0; item < element.count; ++item)
        for (const Property& property : element.properties) {
          if (property.count_size == 0) {
            at += property.size;
            if (at > size) truncated();
            continue;
          }
          if (at + property.count_size > size) truncated();
          unsigned char bytes[8] = {};
          in.seekg(static_cast<std::streamoff>(at));
          in.read(reinterpret_cast<char*>(bytes), static_cast<std::streamsize>(property.count_size));
          std::uintmax_t length = 0;
          for (std::uintmax_t k = 0; k < property.count_size; ++k) {
            const std::uintmax_t byte = bytes[little_endian ? property.count_size - 1 - k : k];
            length = (length << 8) | byte;
          }
          if (length > size) truncated();
          at += property.count_size + length * property.size;
          if (at > size) truncated();
        }
    return;
  }
  // An ASCII body holds numbers only; stray bytes there made assimp abort (fuzz/mesh_ply).
  require_number_text(file, in, "PLY");
}

// assimp 5.2's COLLADA reader turns stray bytes inside an index or number list into enormous
// allocations: a 1.7 KB file with two bytes changed in a <p> list made it allocate 15 GB before failing
// (found by fuzz/mesh_dae). The lists that hold numbers must hold only number characters.
void check_collada(const std::filesystem::path& file, std::uintmax_t size) {
  if (lower(file.extension().string()) != ".dae" || size > (std::uintmax_t{64} << 20)) return;
  std::ifstream in(file, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* tag : {"<p>", "<p ", "<vcount", "<v>", "<h>", "<float_array", "<int_array"}) {
    for (std::size_t at = text.find(tag); at != std::string::npos; at = text.find(tag, at + 1)) {
      const std::size_t open_end = text.find('>', at);
      const std::size_t close = open_end == std::string::npos ? std::string::npos : text.find('<', open_end);
      if (close == std::string::npos) throw Error(file.string() + ": malformed COLLADA: an unterminated list");
      for (std::size_t i = open_end + 1; i < close; ++i) {
        const unsigned char c = static_cast<unsigned char>(text[i]);
        if (!(std::isdigit(c) || std::isspace(c) || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E'))
          throw Error(file.string() + ": malformed COLLADA: a <" + std::string(tag).substr(1, std::strlen(tag) - 2) +
                      "> list holds a character that is not part of a number (byte " + std::to_string(i) + ")");
      }
    }
  }
}

// glTF `data:` URIs: assimp decodes each one into memory from the file's text, so they are bounded here,
// together, by kMaxDataUriBytes. The text scanned is a file whose first non-blank byte is '{' (JSON,
// whatever its extension: assimp also recognises a glTF by its content) or the JSON chunk of a binary
// glTF ('glTF' magic; version 1 and 2 alike put its length at byte 12 and its text at byte 20). Every
// JSON string is decoded as far as its first five characters (escapes included, so `"d\u0061ta:…"` is
// counted too), and the raw length of those that start "data:" (in any case) is summed.
void check_data_uris(const std::filesystem::path& file, std::uintmax_t size) {
  std::ifstream in(file, std::ios::binary);
  std::array<char, 20> head{};
  in.read(head.data(), head.size());
  const auto got = static_cast<std::uintmax_t>(in.gcount());
  std::uintmax_t begin = 0, length = size;
  if (got == head.size() && std::memcmp(head.data(), "glTF", 4) == 0) {
    std::uint32_t json = 0;  // little-endian uint32
    for (int k = 3; k >= 0; --k) json = (json << 8) | static_cast<unsigned char>(head[12 + k]);
    begin = 20;
    length = std::min<std::uintmax_t>(json, size - 20);
  } else {
    std::uintmax_t at = 0;
    if (got >= 3 && std::memcmp(head.data(), "\xEF\xBB\xBF", 3) == 0) at = 3;  // UTF-8 byte order mark
    while (at < got && std::isspace(static_cast<unsigned char>(head[at]))) ++at;
    if (at == got || head[at] != '{') return;  // not JSON (a JSON file starting with 20 blanks: not a mesh)
  }
  in.clear();
  in.seekg(static_cast<std::streamoff>(begin));

  bool in_string = false, escape = false;
  int hex_left = 0;
  unsigned hex_value = 0;
  std::string start;         // the string's first decoded characters, lower case (five at most)
  std::string raw_start;     // its first raw characters, for the message
  std::uintmax_t raw = 0;    // the string's raw length so far
  std::uintmax_t total = 0;  // raw length of the data: URIs ended so far
  const auto decoded = [&](unsigned c) {
    if (start.size() < 5) start.push_back(static_cast<char>(c < 128 ? std::tolower(static_cast<int>(c)) : 0x80));
  };
  std::vector<char> buffer(std::size_t{1} << 20);
  for (std::uintmax_t left = length; left > 0 && in;) {
    in.read(buffer.data(), static_cast<std::streamsize>(std::min<std::uintmax_t>(left, buffer.size())));
    const auto n = static_cast<std::size_t>(in.gcount());
    if (n == 0) break;
    left -= n;
    for (std::size_t i = 0; i < n; ++i) {
      const char c = buffer[i];
      if (!in_string) {
        if (c == '"') in_string = true, escape = false, hex_left = 0, start.clear(), raw_start.clear(), raw = 0;
        continue;
      }
      if (!escape && hex_left == 0 && c == '"') {
        in_string = false;
        if (start == "data:") total += raw;
        continue;
      }
      ++raw;
      if (raw_start.size() < 48) raw_start.push_back(c);
      if (hex_left > 0) {
        const unsigned char u = static_cast<unsigned char>(c);
        hex_value = hex_value * 16 + static_cast<unsigned>(std::isdigit(u) ? u - '0' : (std::tolower(u) - 'a' + 10) & 15);
        if (--hex_left == 0) decoded(hex_value);
      } else if (escape) {
        escape = false;
        if (c == 'u') hex_left = 4, hex_value = 0;
        else decoded(static_cast<unsigned char>(c));
      } else if (c == '\\') {
        escape = true;
      } else {
        decoded(static_cast<unsigned char>(c));
      }
      if (start == "data:" && total + raw > kMaxDataUriBytes)
        throw Error(file.string() + ": refers to '" + raw_start +
                    "…', a data: URI that brings the file's data: URIs past the limit of " +
                    std::to_string(kMaxDataUriBytes) +
                    " bytes (64 MiB) of text; put a large buffer in a file beside the mesh or in a .glb's binary chunk");
    }
  }
}

}  // namespace

std::uintmax_t check_mesh_file(const std::filesystem::path& file) {
  const std::string label = file.string();
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file, ec);
  if (status.type() == std::filesystem::file_type::not_found) throw Error(label + ": no such mesh file");
  if (ec) throw Error(label + ": cannot read the mesh file: " + ec.message());  // e.g. a symlink loop
  if (status.type() == std::filesystem::file_type::directory) throw Error(label + ": is a directory, not a mesh file");
  if (status.type() != std::filesystem::file_type::regular)
    throw Error(label + ": is not a regular file (a device, pipe or socket), so it cannot be a mesh file");
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec) throw Error(label + ": cannot read the mesh file: " + ec.message());
  if (size == 0) throw Error(label + ": the mesh file is empty");
  if (size > kMaxMeshBytes)
    throw Error(label + ": the mesh file is " + std::to_string(size) + " bytes, larger than the limit of " +
                std::to_string(kMaxMeshBytes) + " bytes (1 GiB)");
  check_binary_stl(file, size);
  check_ply(file, size);
  check_off(file, size);
  check_collada(file, size);
  check_data_uris(file, size);
  return size;
}

}  // namespace impetus::assets::detail
