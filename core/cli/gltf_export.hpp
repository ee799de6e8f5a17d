#pragma once
/// \file
/// `impetus run SCENE --out run.glb | run.gltf | run.html`: the trajectory as a glTF 2.0 animation
/// (README.md, "The `impetus` tool"; "Seeing a run"). Every body is a node carrying its shape (primitives
/// tessellated, imported meshes as imported, planes as a finite gridded quad), with a deterministic colour;
/// the recorded steps are one animation with a translation and a rotation channel per moving body (linear
/// interpolation). What the viewer page shows besides (velocities, energies, penetration, contacts) rides
/// in `extras` as float accessors, listed in README.md's "Seeing a run". Written with tinygltf (Debian's
/// libtinygltf-dev); `.html` wraps the binary file in the viewer page (viewer_page.hpp).

#include "impetus/engine/world.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace impetus::cli {

/// The extension of `file` in lower case (".glb", ".csv", "" …).
std::string lowercase_extension(const std::filesystem::path& file);

/// Whether `file` names an animation output: `.glb` (binary glTF), `.gltf` (JSON with an embedded buffer)
/// or `.html` (the viewer page around a binary glTF), in any case.
bool is_animation_path(const std::filesystem::path& file);

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
  /// Records the bodies' poses and velocities, the energies, the deepest penetration and the contacts at
  /// the world's current time.
  void record(const World& world);
  /// Builds the glTF document and writes it (as the viewer page for `.html`); throws Error if the write
  /// fails.
  void finish(const World& world);

 private:
  /// The document as a binary glTF (`.glb`) or as JSON.
  std::string serialize(const World& world, bool binary) const;

  std::filesystem::path file_;
  GltfRunInfo info_;
  std::vector<float> times_;
  // Per body: 3 (x, y, z) / 4 (x, y, z, w) / 3 / 3 floats per sample; empty for bodies that do not move.
  std::vector<std::vector<float>> translations_, rotations_, velocities_, angular_velocities_;
  // Per sample: kinetic and potential energy (J), deepest penetration (m); the contact count.
  std::vector<float> kinetic_, potential_, penetration_;
  std::vector<std::uint32_t> contact_counts_;
  // Per contact of every sample: point, normal impulse p n, tangential impulse (N s), 3 floats each.
  std::vector<float> contact_points_, normal_impulses_, tangent_impulses_;
  std::uint64_t bytes_ = 0;       // what the recording holds
  bool contacts_complete_ = true;  // false once contacts stopped being recorded at the memory cap
};

}  // namespace impetus::cli
