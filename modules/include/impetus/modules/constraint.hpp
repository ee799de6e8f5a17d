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
  position   ///< the impulse makes the points coincide after the step (eq. 10, as docs/conventions.md reads it)
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

/// "Coaxial" (paper, end of sec. 4): an axis of body b stays on an axis of body a; b may slide along
/// it and turn about it (a cylindrical joint). Enforced at two points of b's axis, `anchor_b` and
/// `anchor_b + length·axis_b`, each with two rows whose normals are perpendicular to a's axis.
struct CoaxialConstraint {
  BodyIndex a = 0;
  BodyIndex b = 0;
  Vec3 anchor_a = Vec3::Zero();  ///< a point of the axis in a's body frame (m)
  Vec3 anchor_b = Vec3::Zero();  ///< a point of the axis in b's body frame (m)
  Vec3 axis_a = Vec3::UnitZ();   ///< direction of the axis in a's body frame (unit)
  Vec3 axis_b = Vec3::UnitZ();   ///< direction of the axis in b's body frame (unit)
  double length = 1.0;           ///< distance between the two points held on the axis (m), > 0
  ConstraintLevel level = ConstraintLevel::position;
  bool collide = false;  ///< whether the detector still reports contacts between a and b
};

/// Any constraint kind. Every alternative has the members `a`, `b` and `collide`.
using Constraint = std::variant<PointPointConstraint, CoaxialConstraint>;

}  // namespace impetus
