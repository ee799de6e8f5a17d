#pragma once
/// \file
/// The default collision detector, `fcl`: FCL 0.7's dynamic AABB trees for the broadphase, exact
/// closed forms where they exist and FCL's GJK and MPR (convex shapes) or BVH queries (triangle meshes) for
/// the rest, and real contact manifolds (up to 4 points per pair spanning the contact area). See
/// README.md for what it assumes, guarantees and where it fails. No FCL header here (pimpl).
///
/// Output convention (docs/conventions.md): a < b; normal out of a into b; depth > 0 penetration, < 0 a
/// gap within `margin`; contacts sorted by (a, b, feature, point), identical from run to run.

#include "impetus/modules/detector.hpp"
#include "impetus/modules/options.hpp"
#include "impetus/settings/fcl.hpp"  // FclDetectorSettings

#include <cstdint>
#include <memory>

namespace impetus {

/// What the last detect() cost and had to correct, beyond DetectorCounters (not part of the module
/// contract: benchmarks and tests read it from the plain class).
struct FclDetectorProfile {
  double broadphase = 0.0;   ///< s: box refresh, tree update, tree traversal, plane tests, pair filter
  double narrowphase = 0.0;  ///< s: pair tests, manifolds, reduction, final sort
  std::uint64_t fcl_failures = 0;  ///< FCL queries that failed (threw): a fallback axis was used or the pair skipped
};

/// The `fcl` collision detector. Not thread-safe: one detect() at a time.
class FclDetector final : public CollisionDetector {
 public:
  /// Reads the options (see FclDetectorSettings); throws OptionError on a bad value.
  explicit FclDetector(const ModuleOptions& options);
  explicit FclDetector(const FclDetectorSettings& settings = {});
  ~FclDetector() override;
  FclDetector(const FclDetector&) = delete;
  FclDetector& operator=(const FclDetector&) = delete;

  /// Builds each body's geometry (FCL primitives, fcl::Convex, BVH<OBBRSS>) and the two broadphase
  /// trees (movable, fixed). Fails, naming the body, for a movable plane, a mesh without geometry, a
  /// `convex` mesh that is not convex, a non-positive size, or geometry FCL rejects.
  ModuleStatus set_bodies(std::span<const RigidBody> bodies, std::span<const BodyPair> excluded) noexcept override;

  /// Finds every contact at the current poses (see the file comment). Counters: pairs_tested = candidate
  /// pairs the broadphase reported (tree traversal over fattened boxes, plane tests); narrowphase_calls =
  /// pairs tested exactly, after the exact-box check and the filters (groups/masks, excluded pairs);
  /// contacts; contacts_dropped = non-finite or zero normals, merged duplicates and points removed by
  /// the reduction to `max_contacts_per_pair`.
  void detect(std::span<const RigidBody> bodies, const StepContext& ctx, std::vector<Contact>& contacts,
              DetectorCounters& counters) noexcept override;

  const FclDetectorSettings& settings() const;
  /// Timings and corrections of the last detect().
  const FclDetectorProfile& last_profile() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace impetus
