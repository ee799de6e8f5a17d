// Files outside the scene (issue 22): what a mesh file refers to (a glTF buffer, an OBJ material
// library) is read only from inside the mesh's own folder tree, as a regular file within the size
// bound, or the import is refused naming the mesh file and the reference; `data:` URIs are bounded.
// And values that overflow: a scale, density or mass whose products are not finite is refused naming
// the value (the library) or the option (`impetus mass`), and no non-finite number is ever printed.
#include "reliability_support.hpp"

#include "impetus/assets/mesh_body.hpp"

#include <sys/stat.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>

namespace impetus::reliability {
namespace {

// The unit cube [0, 1]³ as glTF buffer bytes: 36 uint32 indices (outward), then 8 float32 vertices.
std::string cube_buffer() {
  const std::uint32_t indices[36] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 0, 3, 5, 0, 5, 4,
                                     1, 7, 6, 1, 6, 2, 0, 4, 7, 0, 7, 1, 3, 2, 6, 3, 6, 5};
  const float vertices[24] = {0, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  std::string bytes(sizeof indices + sizeof vertices, '\0');
  std::memcpy(bytes.data(), indices, sizeof indices);  // little-endian, as glTF is (x86, ARM)
  std::memcpy(bytes.data() + sizeof indices, vertices, sizeof vertices);
  return bytes;
}

// A glTF 2.0 cube whose one buffer is `uri` (240 bytes, the layout of cube_buffer).
std::string cube_gltf(const std::string& uri) {
  return R"({"asset": {"version": "2.0"},
 "buffers": [{"byteLength": 240, "uri": ")" +
         uri + R"("}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 144}, {"buffer": 0, "byteOffset": 144, "byteLength": 96}],
 "accessors": [{"bufferView": 0, "componentType": 5125, "count": 36, "type": "SCALAR"},
               {"bufferView": 1, "componentType": 5126, "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0, "mode": 4}]}],
 "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}
)";
}

const std::string kCubeObj =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
    "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";

// A scratch directory holding `mesh/` (the mesh's folder) and, beside it, outside.bin: a valid cube
// buffer, so a reference that escaped would load a plausible mesh rather than fail.
struct Folders {
  Scratch scratch{"mesh-reference"};
  fs::path folder = scratch.path() / "mesh";
  fs::path outside = scratch.path() / "outside.bin";
  Folders() {
    fs::create_directories(folder);
    scratch.write("outside.bin", cube_buffer());
  }
  fs::path write(const std::string& name, const std::string& bytes) const {
    const fs::path file = folder / name;
    fs::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << bytes;
    return file;
  }
};

// Sets an environment variable for one scope (the import mode), restoring the previous value.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_) ::setenv(name_, old_->c_str(), 1);
    else ::unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// The load error of `file`, through the importer process (the default) and in this process, which must
// agree: the message has to survive the trip from the importer.
std::string load_error(const fs::path& file) {
  const std::string isolated = error_of([&] { assets::load_mesh_body(file); });
  ScopedEnv in_process("IMPETUS_MESH_IMPORT", "in-process");
  const std::string local = error_of([&] { assets::load_mesh_body(file); });
  EXPECT_EQ(isolated, local) << "the importer process and the in-process import disagree";
  return isolated;
}

void expect_refusal(const std::string& error, const fs::path& file, const std::string& fragment) {
  EXPECT_NE(error.find(file.string() + ": "), std::string::npos) << "the error must name the mesh: " << error;
  EXPECT_NE(error.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << error;
}

TEST(MeshReference, BufferOutsideTheFolderIsRefused) {
  const Folders f;
  const fs::path mesh = f.write("mesh.gltf", cube_gltf("../outside.bin"));
  expect_refusal(load_error(mesh), mesh, "refers to '../outside.bin', outside the mesh's folder");
}

TEST(MeshReference, DeepClimbIsRefused) {
  const Folders f;
  const fs::path mesh = f.write("mesh.gltf", cube_gltf("../../../../../../../../etc/passwd"));
  expect_refusal(load_error(mesh), mesh, "refers to '../../../../../../../../etc/passwd', outside the mesh's folder");
}

TEST(MeshReference, AbsoluteUriIsRefused) {
  const Folders f;
  const fs::path mesh = f.write("mesh.gltf", cube_gltf("/etc/passwd"));
  expect_refusal(load_error(mesh), mesh, "refers to '/etc/passwd', an absolute path");
  // Absolute and pointing at a valid buffer outside: refused all the same.
  const fs::path to_buffer = f.write("to_buffer.gltf", cube_gltf(f.outside.string()));
  expect_refusal(load_error(to_buffer), to_buffer, "refers to '" + f.outside.string() + "', an absolute path");
}

TEST(MeshReference, DirectoryIsRefused) {
  const Folders f;
  fs::create_directories(f.folder / "buffers");
  const fs::path mesh = f.write("mesh.gltf", cube_gltf("buffers"));
  expect_refusal(load_error(mesh), mesh, "refers to 'buffers', which is a directory");
}

TEST(MeshReference, FifoIsRefusedWithoutWaiting) {
  const Folders f;
  ASSERT_EQ(::mkfifo((f.folder / "pipe.bin").c_str(), 0600), 0) << std::strerror(errno);
  const fs::path mesh = f.write("mesh.gltf", cube_gltf("pipe.bin"));
  expect_refusal(load_error(mesh), mesh, "refers to 'pipe.bin', which is not a regular file");
}

TEST(MeshReference, SymlinkOutOfTheFolderIsRefused) {
  const Folders f;
  fs::create_symlink(f.outside, f.folder / "link.bin");
  const fs::path mesh = f.write("mesh.gltf", cube_gltf("link.bin"));
  expect_refusal(load_error(mesh), mesh, "refers to 'link.bin', a symbolic link to '" + f.outside.string() + "'");
}

TEST(MeshReference, ReferencedFileLargerThanTheBoundIsRefused) {
  const Folders f;
  const fs::path big = f.write("big.bin", cube_buffer());
  fs::resize_file(big, (std::uintmax_t{1} << 30) + 1);  // sparse: nothing is written
  const fs::path mesh = f.write("mesh.gltf", cube_gltf("big.bin"));
  expect_refusal(load_error(mesh), mesh,
                 "refers to 'big.bin', 1073741825 bytes, larger than the limit of 1073741824 bytes (1 GiB)");
}

TEST(MeshReference, BufferInsideTheFolderLoads) {
  const Folders f;
  f.write("cube.bin", cube_buffer());
  f.write("buffers/cube.bin", cube_buffer());
  fs::create_symlink("cube.bin", f.folder / "link.bin");  // a link that stays inside is fine
  for (const std::string uri : {"cube.bin", "buffers/cube.bin", "./buffers/../cube.bin", "link.bin"}) {
    const fs::path mesh = f.write("mesh.gltf", cube_gltf(uri));
    for (const char* mode : {"isolated", "in-process"}) {
      ScopedEnv env("IMPETUS_MESH_IMPORT", mode);
      assets::MeshBody body;
      ASSERT_NO_THROW(body = assets::load_mesh_body(mesh)) << uri << " (" << mode << ")";
      EXPECT_NEAR(body.unit.volume, 1.0, 1e-12) << uri;
      EXPECT_NEAR(body.center_of_mass_file.x(), 0.5, 1e-12) << uri;
      EXPECT_NEAR(body.unit.inertia(0, 0), 1.0 / 6.0, 1e-12) << uri;  // m (1² + 1²) / 12
    }
  }
}

// The engine's own OBJ reader never opens a material library: `mtllib ../x.mtl` is skipped, the cube
// loads. x.mtl is a FIFO, so an attempt to open it for reading would block.
TEST(MeshReference, ObjMaterialLibraryIsNeverOpenedByTheObjReader) {
  const Folders f;
  ASSERT_EQ(::mkfifo((f.scratch.path() / "x.mtl").c_str(), 0600), 0) << std::strerror(errno);
  const fs::path mesh = f.write("mesh.obj", "mtllib ../x.mtl\nusemtl steel\n" + kCubeObj);
  assets::MeshBody body;
  ASSERT_NO_THROW(body = assets::load_mesh_body(mesh));
  EXPECT_NEAR(body.unit.volume, 1.0, 1e-12);
}

// The same OBJ text under an extension assimp does not know: assimp recognises it by content and its OBJ
// reader does open material libraries; the one outside the folder is refused.
TEST(MeshReference, ObjMaterialLibraryOutsideIsRefusedWhenAssimpReadsTheObj) {
  const Folders f;
  ASSERT_EQ(::mkfifo((f.scratch.path() / "x.mtl").c_str(), 0600), 0) << std::strerror(errno);
  const fs::path mesh = f.write("mesh.model", "mtllib ../x.mtl\nusemtl steel\n" + kCubeObj);
  expect_refusal(load_error(mesh), mesh, "refers to '../x.mtl', outside the mesh's folder");
}

TEST(MeshReference, OversizedDataUriIsRefused) {
  const Folders f;
  const std::string prefix = "data:application/octet-stream;base64,";
  const fs::path mesh = f.write("mesh.gltf", cube_gltf(prefix + std::string(std::size_t{64} << 20, 'A')));
  const std::string error = error_of([&] { assets::load_mesh_body(mesh); });
  expect_refusal(error, mesh, "refers to 'data:application/octet-stream;base64,AAAAAAAAAAA");
  expect_refusal(error, mesh, "a data: URI that brings the file's data: URIs past the limit of 67108864 bytes (64 MiB) of text");
  // Spelled with a JSON escape, it is the same URI to assimp's JSON parser, and to the check.
  const fs::path escaped = f.write("escaped.gltf", cube_gltf("d\\u0061" + prefix.substr(2) + std::string(std::size_t{64} << 20, 'A')));
  expect_refusal(error_of([&] { assets::load_mesh_body(escaped); }), escaped, "past the limit of 67108864 bytes");
  // In a .glb, the JSON chunk is scanned (its length at byte 12, its text from byte 20).
  std::string json = cube_gltf(prefix + std::string(std::size_t{64} << 20, 'A'));
  json.append((4 - json.size() % 4) % 4, ' ');
  const auto le32 = [](std::size_t n) {
    std::string bytes;
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<char>((n >> (8 * k)) & 0xFF));
    return bytes;
  };
  const fs::path glb = f.write("mesh.glb", "glTF" + le32(2) + le32(20 + json.size()) + le32(json.size()) + "JSON" + json);
  expect_refusal(error_of([&] { assets::load_mesh_body(glb); }), glb, "a data: URI that brings the file's data: URIs past");
}

// --- Values that overflow ----------------------------------------------------------------------------

fs::path cube_obj() { return meshes_dir() / "cube.obj"; }
fs::path box_obj() { return meshes_dir() / "box.obj"; }

assets::ImportOptions at_scale(double scale) {
  assets::ImportOptions options;
  options.scale = scale;
  return options;
}

TEST(MassOverflow, ScaleWhoseInertiaOverflowsIsRefusedNamingTheScale) {
  // Unit cube at 1e70: volume 1e210 is finite, the inertia (1e350) is not.
  const std::string error = error_of([] { assets::load_mesh_body(cube_obj(), at_scale(1e70)); });
  expect_refusal(error, cube_obj(), "scale 1e+70 is too large: the mesh's mass properties overflow a double");
  EXPECT_EQ(error.find("intersects itself"), std::string::npos) << error;
}

TEST(MassOverflow, ScaleWhoseCoordinatesOverflowIsRefusedNamingTheScale) {
  // box.obj reaches z = 2.25: times 1e308 that is beyond a double.
  expect_refusal(error_of([] { assets::load_mesh_body(box_obj(), at_scale(1e308)); }), box_obj(),
                 "scale 1e+308 is too large: a vertex coordinate overflows a double");
}

TEST(MassOverflow, NonFiniteScaleIsRefused) {
  for (const double scale : {double(INFINITY), double(NAN), -1.0, 0.0}) {
    const std::string error = error_of([&] { assets::load_mesh_body(cube_obj(), at_scale(scale)); });
    expect_refusal(error, cube_obj(), "is not a positive finite number");
    EXPECT_NE(error.find("scale "), std::string::npos) << error;
  }
}

TEST(MassOverflow, DensityOrMassThatOverflowsIsRefused) {
  const assets::MeshBody body = assets::load_mesh_body(cube_obj(), at_scale(10.0));  // volume 1000
  const std::string label = cube_obj().string();
  expect_refusal(error_of([&] { assets::mesh_mass_properties(body, 1e308, std::nullopt, label); }), cube_obj(),
                 "density 1e+308 is too large: times the volume 1000 m³, the mass overflows a double");
  // Density 1.5e304 gives the mass 1.5e307, but the inertia m s²/6 = 2.5e308 is beyond a double.
  expect_refusal(error_of([&] { assets::mesh_mass_properties(body, 1.5e304, std::nullopt, label); }), cube_obj(),
                 "density 1.5e+304 is too large: the moments of inertia");
  const assets::MeshBody tiny = assets::load_mesh_body(cube_obj(), at_scale(1e-3));  // volume 1e-9
  expect_refusal(error_of([&] { assets::mesh_mass_properties(tiny, 5e-324, std::nullopt, label); }), cube_obj(),
                 "density 5e-324 is too small: times the volume 1e-09 m³, the mass is 0 kg");
  expect_refusal(error_of([&] { assets::mesh_mass_properties(tiny, std::nullopt, 1e308, label); }), cube_obj(),
                 "mass 1e+308 is out of range: with the volume 1e-09 m³");
  expect_refusal(error_of([&] { assets::mesh_mass_properties(body, double(NAN), std::nullopt, label); }), cube_obj(),
                 "density nan is not a positive finite number");
  // In range: the numbers come back.
  const assets::MassProperties p = assets::mesh_mass_properties(body, 1e300, std::nullopt, label);
  EXPECT_DOUBLE_EQ(p.mass, 1e303);
}

// `impetus mass` as a user runs it: stdout and stderr together, and the exit status.
std::pair<int, std::string> run_mass(const std::string& args) {
  const std::string command = std::string(IMPETUS_EXE) + " mass " + args + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  std::string text;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) text.append(buffer, n);
  const int raw = ::pclose(pipe);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, text};
}

TEST(MassOverflow, MassCommandNamesTheOptionAndPrintsNoInfinity) {
  const std::string cube = cube_obj().string();
  const auto [scale_status, scale_text] = run_mass(cube + " --scale 1e70");
  EXPECT_NE(scale_status, 0) << scale_text;
  EXPECT_NE(scale_text.find(cube + ": --scale 1e+70 is too large: the mesh's mass properties overflow a double"),
            std::string::npos)
      << scale_text;
  EXPECT_EQ(scale_text.find("intersects itself"), std::string::npos) << scale_text;

  const auto [density_status, density_text] = run_mass(cube + " --scale 10 --density 1e308");
  EXPECT_NE(density_status, 0) << density_text;
  EXPECT_NE(density_text.find(cube + ": --density 1e+308 is too large: times the volume 1000 m³"), std::string::npos)
      << density_text;
  EXPECT_EQ(density_text.find("inf"), std::string::npos) << density_text;
  EXPECT_EQ(density_text.find("mass   "), std::string::npos) << "no report may be printed: " << density_text;

  const auto [json_status, json_text] = run_mass(cube + " --scale 10 --density 1.5e304 --json");
  EXPECT_NE(json_status, 0) << json_text;
  EXPECT_NE(json_text.find(cube + ": --density 1.5e+304 is too large: the moments of inertia"), std::string::npos)
      << json_text;

  const auto [mass_status, mass_text] = run_mass(cube + " --scale 0.001 --mass 1e308");
  EXPECT_NE(mass_status, 0) << mass_text;
  EXPECT_NE(mass_text.find(cube + ": --mass 1e+308 is out of range"), std::string::npos) << mass_text;

  const auto [ok_status, ok_text] = run_mass(cube + " --density 1e300");
  EXPECT_EQ(ok_status, 0) << ok_text;
  EXPECT_NE(ok_text.find("mass                 1e+300 kg"), std::string::npos) << ok_text;
}

}  // namespace
}  // namespace impetus::reliability
