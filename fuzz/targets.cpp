// The fuzz targets (see targets.hpp). Shared by the libFuzzer binaries and tests/reliability.

#include "targets.hpp"

#include "impetus/assets/mesh_body.hpp"
#include "impetus/core/error.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/engine/world.hpp"

#include <unistd.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#ifndef IMPETUS_FUZZ_SCENE_DIR
#error "IMPETUS_FUZZ_SCENE_DIR must be defined by the build (the bundled scene directory)"
#endif

namespace impetus::fuzz {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void invariant_broken(const std::string& what) {
  std::fprintf(stderr, "impetus fuzz: invariant broken: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

constexpr const char* kBufferName = "buffer.bin";

// The unit cube [0, 1]³ as glTF buffer bytes (240): 36 uint32 indices (outward), then 8 float32 vertices,
// little-endian; the seeds fuzz/corpus/mesh_gltf/cube_external_buffer.gltf and
// fuzz/corpus/mesh_glb/cube_external_buffer.glb refer to it.
std::string cube_buffer() {
  const std::uint32_t indices[36] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 0, 3, 5, 0, 5, 4,
                                     1, 7, 6, 1, 6, 2, 0, 4, 7, 0, 7, 1, 3, 2, 6, 3, 6, 5};
  const float vertices[24] = {0, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  std::string bytes;
  for (const std::uint32_t i : indices)
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<char>((i >> (8 * k)) & 0xFF));
  for (const float v : vertices) {
    const auto bits = std::bit_cast<std::uint32_t>(v);
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<char>((bits >> (8 * k)) & 0xFF));
  }
  return bytes;
}

// A private directory for the mesh files (and buffer.bin), removed when the process exits normally.
class ScratchDir {
 public:
  ScratchDir() {
    std::error_code ec;
    path_ = fs::temp_directory_path(ec) / ("impetus-fuzz-" + std::to_string(getpid()));
    fs::create_directories(path_, ec);
    // A file a glTF input can refer to ("uri": "buffer.bin"), so the fuzzers reach reference resolution
    // with a reference that resolves, beside the ones that climb out ("../buffer.bin") and are refused.
    std::ofstream(path_ / kBufferName, std::ios::binary) << cube_buffer();
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Scenes are fuzzed for correctness, not for size: 20,000 bodies load in about a second under the
// sanitizers and coverage, where the default limit (2^20) takes about a minute and 2 GB, past libFuzzer's
// timeout and memory limit. The limit itself is fuzzed: a generator that would cross it is refused before
// it makes anything (tests/reliability/hostile_input_round2_test.cpp checks the default).
const SceneLimits kFuzzLimits{.bodies = 20'000};

// What the loader accepts, the World must accept: the same checks live in both places. The bodies go in
// as make_world puts them (add_bodies, linear); add_body one by one is quadratic in the name checks, and a
// generator of 500,001 bodies once timed the fuzzer out that way.
void require_world_accepts(const Scene& scene) {
  try {
    World world(scene.settings);
    world.add_bodies(scene.bodies);
    for (const Constraint& constraint : scene.constraints) world.add_constraint(constraint);
  } catch (const Error& e) {
    invariant_broken(std::string("the scene loaded but the World refused it: ") + e.what());
  }
}

}  // namespace

Outcome scene_one_input(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Scene scene;
  try {
    scene = load_scene_text(text, "fuzz.yaml", IMPETUS_FUZZ_SCENE_DIR, {}, kFuzzLimits);
  } catch (const Error&) {
    return Outcome::rejected;
  }
  require_world_accepts(scene);
  return Outcome::accepted;
}

Outcome overrides_one_input(const std::uint8_t* data, std::size_t size) {
  static const std::string base =
      "dt: 0.001\n"
      "modules: {integrator: momentum, detector: {plugin: fcl, margin: 1.0e-4}, resolver: ledas}\n"
      "bodies:\n"
      "  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1], offset: -5}}}\n"
      "  - {name: ball, shape: {sphere: {radius: 0.5}}, mass: 1, position: [0, 0, 3]}\n"
      "  - {name: box, shape: {box: {size: [1, 1, 1]}}, mass: 2, position: [3, 0, 3]}\n"
      "generators:\n"
      "  - line: {count: 3, radius: 0.1, velocity: [1, 0, 0]}\n"
      "  - pyramid: {rows: 2, radius: 0.1, ground: false}\n"
      "constraints:\n"
      "  - point_point: {bodies: [ball, box], point: [1.5, 0, 3]}\n";
  const std::string text(reinterpret_cast<const char*>(data), size);
  Scene scene;
  try {
    std::vector<SceneOverride> overrides;
    std::size_t start = 0;
    while (start <= text.size()) {
      const std::size_t end = std::min(text.find('\n', start), text.size());
      if (end > start) overrides.push_back(parse_override(text.substr(start, end - start)));
      start = end + 1;
    }
    scene = load_scene_text(base, "fuzz.yaml", IMPETUS_FUZZ_SCENE_DIR, overrides, kFuzzLimits);
  } catch (const Error&) {
    return Outcome::rejected;
  }
  require_world_accepts(scene);
  return Outcome::accepted;
}

Outcome mesh_one_input(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  static const ScratchDir scratch;
  const fs::path file = scratch.path() / ("input." + extension);
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) invariant_broken("cannot write the scratch file " + file.string());
  }
  assets::MeshBody body;
  try {
    body = assets::load_mesh_body(file);
  } catch (const Error&) {
    return Outcome::rejected;
  }
  // Mass properties of a mesh that passed validation must describe a real solid.
  const assets::MassProperties& unit = body.unit;
  if (!(unit.volume > 0.0) || !std::isfinite(unit.volume))
    invariant_broken("validated mesh with volume " + std::to_string(unit.volume));
  if (!unit.inertia.allFinite() || !unit.center_of_mass.allFinite() || !unit.principal_moments.allFinite())
    invariant_broken("validated mesh with non-finite mass properties");
  const double scale = unit.inertia.cwiseAbs().maxCoeff();
  if ((unit.inertia - unit.inertia.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale)
    invariant_broken("validated mesh with a non-symmetric inertia");
  if (!(unit.principal_moments.minCoeff() > -1e-9 * scale))
    invariant_broken("validated mesh with a negative principal moment of inertia");
  if (body.mesh == nullptr || body.mesh->triangles.empty()) invariant_broken("validated mesh without triangles");
  return Outcome::accepted;
}

}  // namespace impetus::fuzz
