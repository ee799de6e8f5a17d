#pragma once
/// \file
/// The collision detector module contract.

#include "impetus/core/body.hpp"
#include "impetus/modules/contact.hpp"
#include "impetus/modules/status.hpp"
#include "impetus/modules/step.hpp"

#include <span>
#include <utility>
#include <vector>

namespace impetus {

/// A pair of bodies (lower index first), e.g. two bodies joined by a constraint that must not collide.
using BodyPair = std::pair<BodyIndex, BodyIndex>;

/// Finds contacts between bodies at their current poses.
class CollisionDetector {
 public:
  virtual ~CollisionDetector() = default;

  /// Called before the first detect() and whenever bodies are added or removed: builds the detector's
  /// geometry and broadphase. `excluded` lists pairs that must never produce contacts (sorted).
  /// Fails (with a message naming the body) for a shape the detector cannot handle.
  virtual ModuleStatus set_bodies(std::span<const RigidBody> bodies,
                                  std::span<const BodyPair> excluded) noexcept = 0;

  /// Replaces `contacts` with every contact at the bodies' current poses, following the Contact
  /// convention (a < b, normal out of a into b), sorted deterministically.
  virtual void detect(std::span<const RigidBody> bodies, const StepContext& ctx,
                      std::vector<Contact>& contacts, DetectorCounters& counters) noexcept = 0;
};

}  // namespace impetus
