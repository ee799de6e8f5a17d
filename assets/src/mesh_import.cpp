// Mesh import through assimp: the only file that includes assimp headers (keep it so).
// assimp reads the file into its scene graph; we walk the graph ourselves, applying node transforms
// in double precision (aiProcess_PreTransformVertices would merge meshes by material and lose the
// parts), convert units, and weld vertices on exact equality (see mesh_import.hpp for why not
// aiProcess_JoinIdenticalVertices).

#include "impetus/assets/mesh_import.hpp"

#include "impetus/core/error.hpp"

#include <assimp/Importer.hpp>
#include <assimp/commonMetaData.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unordered_map>

namespace impetus::assets {
namespace {

using Mat4 = Eigen::Matrix4d;

constexpr double kLargeMesh = 10.0;  // m: beyond this a unitless file is probably in mm or cm
// Larger files are refused before assimp reads them: assimp holds the whole file and its scene graph in
// memory (about 20 million triangles of binary STL fit below this).
constexpr std::uintmax_t kMaxMeshBytes = std::uintmax_t{1} << 30;

Mat4 to_eigen(const aiMatrix4x4& m) {
  Mat4 out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return out;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

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

// One node that carries meshes, with its transform to the file's root frame.
struct NodeMeshes {
  std::string name;
  Mat4 transform;
  std::vector<unsigned> meshes;
};

void collect(const aiNode* node, const Mat4& parent, std::vector<NodeMeshes>& out) {
  const Mat4 transform = parent * to_eigen(node->mTransformation);
  if (node->mNumMeshes > 0)
    out.push_back({node->mName.C_Str(), transform, {node->mMeshes, node->mMeshes + node->mNumMeshes}});
  for (unsigned i = 0; i < node->mNumChildren; ++i) collect(node->mChildren[i], transform, out);
}

// Appends the triangles of `node`'s meshes to `mesh`, transformed by `to_metres` · node transform.
// A mirroring transform (negative determinant) reverses the winding, so the triangles are reversed
// back. Points and lines are counted in `dropped`.
void append(const aiScene& scene, const NodeMeshes& node, const Mat4& to_metres, TriangleMesh& mesh,
            std::size_t& dropped) {
  const Mat4 m = to_metres * node.transform;
  const Mat3 linear = m.topLeftCorner<3, 3>();
  const Vec3 translation = m.topRightCorner<3, 1>();
  const bool mirrored = linear.determinant() < 0.0;
  for (unsigned index : node.meshes) {
    const aiMesh& source = *scene.mMeshes[index];
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < source.mNumVertices; ++v) {
      const aiVector3D& p = source.mVertices[v];
      mesh.vertices.push_back(linear * Vec3(p.x, p.y, p.z) + translation);
    }
    for (unsigned f = 0; f < source.mNumFaces; ++f) {
      const aiFace& face = source.mFaces[f];
      if (face.mNumIndices != 3) {
        ++dropped;
        continue;
      }
      std::array<std::uint32_t, 3> t = {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]};
      if (mirrored) std::swap(t[1], t[2]);
      mesh.triangles.push_back(t);
    }
  }
}

// The file's length unit in metres, when it states one. COLLADA: assimp has already scaled the root
// node by <unit meter=…> (the root is the visual scene, which has no transform of its own, and the up
// axis is left alone here), so the root's scale is the unit. FBX: "UnitScaleFactor" is centimetres
// per file unit, and the coordinates are left in file units.
std::optional<double> file_unit(const aiScene& scene, const std::string& format, bool& already_applied) {
  already_applied = false;
  if (lower(format).find("collada") != std::string::npos) {
    already_applied = true;
    const aiMatrix4x4& m = scene.mRootNode->mTransformation;
    return Vec3(m.a1, m.b1, m.c1).norm();
  }
  if (scene.mMetaData) {
    double factor = 0.0;
    float factor_f = 0.0f;
    if (scene.mMetaData->Get("UnitScaleFactor", factor) && factor > 0.0) return factor / 100.0;
    if (scene.mMetaData->Get("UnitScaleFactor", factor_f) && factor_f > 0.0f) return factor_f / 100.0;
  }
  return std::nullopt;
}

// The unit's name, for messages; the unit came through float32 (assimp's ai_real), hence the tolerance.
std::string unit_name(double metres) {
  const auto is = [metres](double unit) { return std::abs(metres - unit) < 1e-6 * unit; };
  if (is(0.001)) return " (millimetres)";
  if (is(0.01)) return " (centimetres)";
  if (is(0.0254)) return " (inches)";
  if (is(0.3048)) return " (feet)";
  return "";
}

}  // namespace

void weld_identical_vertices(TriangleMesh& mesh) {
  struct Key {
    std::array<std::uint64_t, 3> bits;
    bool operator==(const Key&) const = default;
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      std::size_t h = 0;
      for (std::uint64_t b : k.bits) h = h * 0x9E3779B97F4A7C15ull + std::hash<std::uint64_t>{}(b);
      return h;
    }
  };
  std::unordered_map<Key, std::uint32_t, Hash> index_of;
  std::vector<std::uint32_t> renumber(mesh.vertices.size(), UINT32_MAX);
  std::vector<Vec3> vertices;
  for (auto& t : mesh.triangles)
    for (std::uint32_t& i : t) {
      if (renumber[i] == UINT32_MAX) {
        const Vec3& p = mesh.vertices[i];
        const auto next = static_cast<std::uint32_t>(vertices.size());
        if (p.allFinite()) {
          // + 0.0 turns −0 into +0, so the two zeros weld.
          const Key key{{std::bit_cast<std::uint64_t>(p.x() + 0.0), std::bit_cast<std::uint64_t>(p.y() + 0.0),
                         std::bit_cast<std::uint64_t>(p.z() + 0.0)}};
          renumber[i] = index_of.emplace(key, next).first->second;
        } else {
          renumber[i] = next;  // NaN equals nothing: never welded
        }
        if (renumber[i] == next) vertices.push_back(p);
      }
      i = renumber[i];
    }
  mesh.vertices = std::move(vertices);
}

ImportedMesh import_mesh(const std::filesystem::path& file, const ImportOptions& options) {
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

  Assimp::Importer importer;
  // Keep the file's axes: a Z-up COLLADA file stays Z-up (the engine's convention too).
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(file.string(), aiProcess_Triangulate | aiProcess_ValidateDataStructure);
  } catch (const std::exception& e) {
    throw Error(label + ": assimp failed to read it: " + e.what());
  }
  if (!scene || !scene->mRootNode)
    throw Error(label + ": assimp cannot read it: " + std::string(importer.GetErrorString()));

  ImportedMesh out;
  out.file = file;
  aiString format;
  out.format = scene->mMetaData && scene->mMetaData->Get(AI_METADATA_SOURCE_FORMAT, format)
                   ? std::string(format.C_Str())
                   : lower(file.extension().string());
  bool applied = false;
  out.file_unit = file_unit(*scene, out.format, applied);
  // Factor from what the scene graph holds to metres, before the user's scale.
  double to_metres = 1.0;
  if (out.file_unit && std::abs(*out.file_unit - 1.0) > 1e-12) {
    const std::string unit = number(*out.file_unit) + " m" + unit_name(*out.file_unit);
    if (options.units == UnitMode::convert) {
      if (!applied) to_metres = *out.file_unit;
      out.warnings.push_back(label + ": the file's unit is " + unit + "; converted to metres");
    } else {
      if (applied) to_metres = 1.0 / *out.file_unit;
      out.warnings.push_back(label + ": the file's unit is " + unit + ", but its numbers are kept as metres");
    }
  }
  Mat4 transform = Mat4::Identity();
  transform.topLeftCorner<3, 3>() *= to_metres * options.scale;

  std::vector<NodeMeshes> nodes;
  collect(scene->mRootNode, Mat4::Identity(), nodes);
  std::size_t dropped = 0;
  if (options.parts == PartMode::merge) {
    ImportedPart part{file.stem().string(), {}};
    for (const NodeMeshes& node : nodes) append(*scene, node, transform, part.mesh, dropped);
    if (!part.mesh.triangles.empty()) out.parts.push_back(std::move(part));
  } else {
    for (const NodeMeshes& node : nodes) {
      ImportedPart part{node.name, {}};
      append(*scene, node, transform, part.mesh, dropped);
      if (!part.mesh.triangles.empty()) out.parts.push_back(std::move(part));
    }
  }
  if (out.parts.empty())
    throw Error(label + ": the file holds no triangles" +
                (dropped ? " (only " + std::to_string(dropped) + " points or lines)" : std::string()));
  if (dropped)
    out.warnings.push_back(label + ": dropped " + std::to_string(dropped) +
                           " points and lines (a solid is made of triangles only)");
  for (ImportedPart& part : out.parts) weld_identical_vertices(part.mesh);

  // A unitless file read as metres that comes out huge was probably written in mm or cm.
  if (!out.file_unit && options.scale == 1.0 && lower(out.format).find("gltf") == std::string::npos) {
    double extent = 0.0;
    for (const ImportedPart& part : out.parts) {
      Vec3 lo = Vec3::Constant(INFINITY), hi = -lo;
      for (const Vec3& v : part.mesh.vertices)
        if (v.allFinite()) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      if ((hi.array() >= lo.array()).all()) extent = std::max(extent, (hi - lo).maxCoeff());
    }
    if (extent > kLargeMesh)
      out.warnings.push_back(label + ": the mesh is " + number(extent) +
                             " m across; this format carries no unit, so its numbers were read as metres (if they "
                             "are millimetres, give scale 0.001; centimetres, 0.01)");
  }
  return out;
}

}  // namespace impetus::assets
