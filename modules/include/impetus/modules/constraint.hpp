#pragma once
/// \file
/// Assembly constraints (paper, sec. 4), handed to the resolver alongside the contacts.

#include "impetus/core/body.hpp"

#include <cstdint>
#include <variant>

namespace impetus {

/// How a constraint is enforced (paper, sec. 4).
enum class ConstraintLevel : std::uint8_t {
  velocity,  ///< the joined points' relative velocity is zeroed each step (drifts apart slowly)
  position   ///< the impulse makes the points coincide after the step (eq. 10, as DESIGN.md reads it)
};

/// "Point-point": a point of body a and a point of body b stay together (a ball joint).
struct PointPointConstraint {
  BodyIndex a = 0;
  BodyIndex b = 0;
  Vec3 anchor_a = Vec3::Zero();  ///< the joined point in a's body frame (m)
  Vec3 anchor_b = Vec3::Zero();  ///< the joined point in b's body frame (m)
  ConstraintLevel level = ConstraintLevel::position;
  bool collide = false;  ///< whether the detector still reports contacts between a and b
};

/// Any constraint kind.
using Constraint = std::variant<PointPointConstraint>;

}  // namespace impetus
