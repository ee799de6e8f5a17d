#pragma once
/// \file
/// `impetus run SCENE --out run.glb | run.gltf`: the trajectory as a glTF 2.0 animation (README.md, "The
/// `impetus` tool"). Every body is a node carrying its shape (primitives tessellated, imported meshes as
/// imported, planes as a finite gridded quad), with a deterministic colour; the recorded steps are one
/// animation with a translation and a rotation channel per moving body (linear interpolation). Written
/// with tinygltf (Debian's libtinygltf-dev).

#include "impetus/engine/world.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace impetus::cli {

/// The extension of `file` in lower case (".glb", ".csv", "" …).
std::string lowercase_extension(const std::filesystem::path& file);

/// Whether `file` names a glTF output (`.glb` binary, `.gltf` JSON with an embedded buffer), in any case.
bool is_gltf_path(const std::filesystem::path& file);

/// What the file's `extras` say about the run.
struct GltfRunInfo {
  std::string scene_file;
  std::string integrator, detector, resolver;
  std::string version;
};

/// Records poses step by step (float32, as glTF stores them) and writes the file at finish().
class GltfRecorder {
 public:
  /// The largest animation kept in memory (bytes of poses and times); a longer run is refused before it
  /// starts, naming --every.
  static constexpr std::uint64_t kMaxAnimationBytes = 1ull << 30;

  /// Checks `file` (check_output_path) and that `samples` recorded poses of the world's bodies fit in
  /// kMaxAnimationBytes; throws Error otherwise.
  GltfRecorder(const std::filesystem::path& file, bool overwrite, const std::filesystem::path& input,
               const World& world, std::uint64_t samples, GltfRunInfo info);
  /// Records the bodies' poses at the world's current time.
  void record(const World& world);
  /// Builds the glTF document and writes it; throws Error if the write fails.
  void finish(const World& world);

 private:
  std::filesystem::path file_;
  GltfRunInfo info_;
  std::vector<float> times_;
  std::vector<std::vector<float>> translations_, rotations_;  // per body: 3 (x, y, z) / 4 (x, y, z, w) per sample
};

}  // namespace impetus::cli
