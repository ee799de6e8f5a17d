// Mesh import through assimp: the only file that includes assimp headers (keep it so). It runs in the
// importer process (tools/mesh_import_helper.cpp) by default, or in the calling process when isolation
// is turned off (mesh_import.cpp).
// assimp reads the file into its scene graph; we walk the graph ourselves, applying node transforms
// in double precision (aiProcess_PreTransformVertices would merge meshes by material and lose the
// parts), convert units, and weld vertices on exact equality (see mesh_import.hpp for why not
// aiProcess_JoinIdenticalVertices).
// Every file assimp opens goes through FolderIO below: the mesh file itself, and the files it refers to
// (glTF buffers, OBJ material libraries, …) only inside the mesh's own folder tree.

#include "assimp_reader.hpp"

#include "impetus/core/error.hpp"
#include "mesh_file_checks.hpp"
#include "text.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/commonMetaData.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/version.h>

#include <array>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>

namespace impetus::assets {
namespace {

using detail::lower;
using detail::number;
using Mat4 = Eigen::Matrix4d;

constexpr double kLargeMesh = 10.0;  // m: beyond this a unitless file is probably in mm or cm

Mat4 to_eigen(const aiMatrix4x4& m) {
  Mat4 out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return out;
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

namespace fs = std::filesystem;

// A file opened for assimp: reads with pread from a descriptor, never past the size it had when opened
// (so a file that grows while assimp reads it cannot take more than the bound it was checked against).
class BoundedFile final : public Assimp::IOStream {
 public:
  BoundedFile(int fd, std::size_t size) : fd_(fd), size_(size) {}
  ~BoundedFile() override { ::close(fd_); }
  BoundedFile(const BoundedFile&) = delete;
  BoundedFile& operator=(const BoundedFile&) = delete;

  std::size_t Read(void* buffer, std::size_t size, std::size_t count) override {
    if (size == 0 || count == 0 || count > std::numeric_limits<std::size_t>::max() / size) return 0;
    const std::size_t want = position_ >= size_ ? 0 : std::min(size * count, size_ - position_);
    std::size_t got = 0;
    while (got < want) {
      const ssize_t n = ::pread(fd_, static_cast<char*>(buffer) + got, want - got,
                                static_cast<off_t>(position_ + got));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += static_cast<std::size_t>(n);
    }
    position_ += got;
    return got / size;
  }
  std::size_t Write(const void*, std::size_t, std::size_t) override { return 0; }
  // As assimp's own stream (fseek with the offset cast to long): relative offsets may be negative, a
  // position before the start fails, one past the end is allowed and reads nothing.
  aiReturn Seek(std::size_t offset, aiOrigin origin) override {
    std::int64_t base = 0;
    if (origin == aiOrigin_CUR) base = static_cast<std::int64_t>(position_);
    else if (origin == aiOrigin_END) base = static_cast<std::int64_t>(size_);
    else if (origin != aiOrigin_SET) return aiReturn_FAILURE;
    const auto delta = static_cast<std::int64_t>(offset);
    if (delta < -base || (delta > 0 && base > std::numeric_limits<std::int64_t>::max() - delta)) return aiReturn_FAILURE;
    position_ = static_cast<std::size_t>(base + delta);
    return aiReturn_SUCCESS;
  }
  std::size_t Tell() const override { return position_; }
  std::size_t FileSize() const override { return size_; }
  void Flush() override {}

 private:
  int fd_;
  std::size_t size_;
  std::size_t position_ = 0;
};

// assimp's file system for one mesh file: the mesh itself, and any file it refers to that lies inside
// the mesh's folder tree after lexical normalisation and symbolic link resolution (weakly_canonical),
// is a regular file and is at most kMaxMeshBytes. Anything else is refused: Open returns null (assimp
// then fails, or goes on without the file) and the first refusal is kept, so that read_with_assimp
// throws it whatever assimp made of the missing file. Exists answers false outside the folder, without
// a refusal: importers probe optional files (an OBJ's material library, a Quake 3 shader) that way.
// The check is on names: a folder that another process changes between the check and the open is not
// covered (the mesh's folder is trusted not to change under the import).
class FolderIO final : public Assimp::IOSystem {
 public:
  explicit FolderIO(const fs::path& mesh) : mesh_(mesh.string()) {
    std::error_code ec;
    const fs::path absolute = fs::absolute(mesh, ec);
    mesh_canonical_ = fs::weakly_canonical(absolute, ec);
    root_ = fs::weakly_canonical(absolute.parent_path(), ec);
    // What assimp puts before a name the file gives: the mesh's path up to its last separator.
    const std::size_t slash = mesh_.find_last_of('/');
    prefix_ = slash == std::string::npos ? std::string() : mesh_.substr(0, slash + 1);
  }

  bool Exists(const char* path) const override {
    if (!path) return false;
    const Resolved r = resolve(path);
    std::error_code ec;
    return !r.refusal && fs::exists(r.path, ec);
  }
  char getOsSeparator() const override { return '/'; }

  Assimp::IOStream* Open(const char* path, const char* mode) override {
    if (!path) return nullptr;
    const std::string name = written(path);
    if (mode && std::string_view(mode).find_first_of("wa+") != std::string_view::npos) {
      refuse("asks to write '" + name + "'; mesh import only reads");
      return nullptr;
    }
    const Resolved r = resolve(path);
    if (r.refusal) {
      refuse(*r.refusal);
      return nullptr;
    }
    // O_NONBLOCK: opening a FIFO must not wait for a writer (it is refused just below).
    const int fd = ::open(r.path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) return nullptr;  // missing or unreadable: assimp says so, naming the file
    struct stat info {};
    if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
      ::close(fd);
      refuse("refers to '" + name + "', which is " +
             (S_ISDIR(info.st_mode) ? "a directory" : "not a regular file (a device, pipe or socket)") +
             ", not a file a mesh can refer to");
      return nullptr;
    }
    const auto size = static_cast<std::uintmax_t>(info.st_size);
    if (size > detail::kMaxMeshBytes) {
      ::close(fd);
      refuse("refers to '" + name + "', " + std::to_string(size) + " bytes, larger than the limit of " +
             std::to_string(detail::kMaxMeshBytes) + " bytes (1 GiB) for a file a mesh refers to");
      return nullptr;
    }
    return new BoundedFile(fd, static_cast<std::size_t>(size));
  }
  void Close(Assimp::IOStream* file) override { delete file; }

  const std::optional<std::string>& refusal() const { return refusal_; }

 private:
  struct Resolved {
    fs::path path;
    std::optional<std::string> refusal;
  };

  // The name as the mesh file wrote it: assimp's path with the mesh's folder prefix taken off.
  std::string written(const std::string& path) const {
    if (!prefix_.empty() && path.size() > prefix_.size() && path.compare(0, prefix_.size(), prefix_) == 0)
      return path.substr(prefix_.size());
    return path;
  }

  static bool inside(const fs::path& path, const fs::path& root) {
    auto p = path.begin();
    for (auto r = root.begin(); r != root.end(); ++r, ++p)
      if (p == path.end() || *p != *r) return false;
    return true;
  }

  Resolved resolve(const std::string& path) const {
    std::error_code ec;
    if (path == mesh_) return {mesh_canonical_, std::nullopt};
    const fs::path absolute = fs::absolute(path, ec);
    const fs::path canonical = fs::weakly_canonical(absolute, ec);
    if (!ec && canonical == mesh_canonical_) return {canonical, std::nullopt};
    const std::string name = written(path);
    // An absolute name in the file: assimp puts the mesh's folder before it ("dir//etc/passwd"), which
    // would stay inside; what the file meant is refused.
    const bool absolute_name = !name.empty() && name.front() == '/';
    if (absolute_name && name != path)
      return {{}, "refers to '" + name + "', an absolute path; a mesh may refer only to files inside its own folder"};
    if (ec || root_.empty())
      return {{}, "refers to '" + name + "', which cannot be resolved (" + ec.message() + ")"};
    if (inside(canonical, root_)) return {canonical, std::nullopt};
    if (absolute_name)
      return {{}, "refers to '" + name + "', an absolute path outside the mesh's folder '" + root_.string() + "'"};
    if (inside(absolute.lexically_normal(), root_))
      return {{}, "refers to '" + name + "', a symbolic link to '" + canonical.string() +
                      "', outside the mesh's folder '" + root_.string() + "'"};
    return {{}, "refers to '" + name + "', outside the mesh's folder '" + root_.string() + "'"};
  }

  void refuse(std::string why) {
    if (!refusal_) refusal_ = mesh_ + ": " + std::move(why);
  }

  std::string mesh_;
  std::string prefix_;
  fs::path mesh_canonical_;
  fs::path root_;
  std::optional<std::string> refusal_;
};

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

namespace detail {

// Major and minor only: Debian's assimp 5.2.5 reports its patch level as 4 (upstream never bumped it).
std::string assimp_version() {
  return "assimp " + std::to_string(aiGetVersionMajor()) + "." + std::to_string(aiGetVersionMinor());
}

void finish_import(ImportedMesh& out, std::size_t dropped, const ImportOptions& options) {
  const std::string label = out.file.string();
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
}

ImportedMesh read_with_assimp(const std::filesystem::path& file, const ImportOptions& options) {
  const std::string label = file.string();
  Assimp::Importer importer;
  auto* io = new FolderIO(file);  // the importer owns it
  importer.SetIOHandler(io);
  // Keep the file's axes: a Z-up COLLADA file stays Z-up (the engine's convention too).
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(file.string(), aiProcess_Triangulate | aiProcess_ValidateDataStructure);
  } catch (const std::exception& e) {
    if (io->refusal()) throw Error(*io->refusal());
    throw Error(label + ": assimp failed to read it: " + e.what());
  }
  // A refused reference is an error even when assimp went on without the file (an image, say).
  if (io->refusal()) throw Error(*io->refusal());
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
  finish_import(out, dropped, options);
  return out;
}

}  // namespace detail
}  // namespace impetus::assets
