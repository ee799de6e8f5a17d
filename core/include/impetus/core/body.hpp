#pragma once
/// \file
/// The rigid body: configuration (shape, mass properties, material) and state (pose, velocities).
///
/// Conventions (docs/conventions.md): `position` is the world position of the center of mass; `rotation`
/// maps body to world coordinates (p_world = position + rotation · p_body); the body frame's origin is
/// the center of mass. World inertia J_world = R J_body Rᵀ. Velocities are in the world frame.
/// A fixed body has infinite mass and inertia: its inverse mass and inverse inertia are zero, so its
/// terms vanish from every formula (paper, after eq. 8).

#include "impetus/core/math.hpp"
#include "impetus/core/shape.hpp"

#include <cstdint>
#include <limits>
#include <string>

namespace impetus {

/// Index of a body in its World (stable for the World's lifetime).
using BodyIndex = std::uint32_t;

/// How a fixed body moves (docs/conventions.md, "Applied loads and prescribed motion"). A fixed body
/// has infinite mass: contacts never change its velocities, which are prescribed, constant until the
/// program changes them.
enum class PrescribedMotion : std::uint8_t {
  /// At rest: its velocities are zero.
  none,
  /// Moves with its `velocity` (of its body origin) and `angular_velocity` (world frame): the world
  /// advances its pose exactly each step. A pusher, a lift, a rotating platform.
  moving,
  /// Stays where it is while contacts see its surface move with `velocity` + `angular_velocity` × r:
  /// a conveyor belt, a turntable's surface in place.
  surface
};

/// Surface properties of a body.
struct Material {
  /// Coefficient of restitution e ∈ [0, 1]; a contact uses the larger of its two bodies' values
  /// (a rigid wall does not make a bouncing ball less elastic).
  double restitution = 0.0;
  /// Coefficient of Coulomb friction μ ≥ 0; a contact uses √(μ_a μ_b). Refused by resolvers that do not
  /// model friction (the paper's method is frictionless).
  double friction = 0.0;
};

/// A rigid body. Plain data: modules read and write it directly.
struct RigidBody {
  // --- configuration ---
  std::string name;       ///< unique within a world
  Shape shape = Sphere{};
  bool fixed = false;     ///< immovable: infinite mass and inertia
  /// How a fixed body moves (must be `none` for a movable body).
  PrescribedMotion motion = PrescribedMotion::none;
  double mass = 1.0;      ///< kg (infinity for a fixed body)
  double inv_mass = 1.0;  ///< 1/kg (0 for a fixed body)
  Mat3 inertia_body = Mat3::Identity();      ///< kg·m² about the center of mass, body frame
  Mat3 inv_inertia_body = Mat3::Identity();  ///< its inverse (zero for a fixed body)
  Material material;
  std::uint32_t collision_group = 1;  ///< bit(s) this body belongs to
  std::uint32_t collision_mask = 0xFFFFFFFFu;  ///< groups it collides with (both ways must agree)

  // --- state ---
  Vec3 position = Vec3::Zero();          ///< center of mass, world frame (m)
  Mat3 rotation = Mat3::Identity();      ///< body → world
  Vec3 velocity = Vec3::Zero();          ///< of the center of mass, world frame (m/s)
  Vec3 angular_velocity = Vec3::Zero();  ///< world frame (rad/s)
  /// Asleep (movable bodies only; World's sleeping islands, docs/conventions.md "Sleeping"): at rest with
  /// zero velocities, not integrated, and no contact between two sleeping or fixed-at-rest bodies is
  /// detected or resolved. Set and cleared by the world.
  bool asleep = false;

  // --- applied loads (movable bodies only; persistent until changed; gravity is added separately) ---
  Vec3 force = Vec3::Zero();        ///< N, world frame, through the center of mass
  Vec3 torque = Vec3::Zero();       ///< N·m, world frame, about the center of mass
  Vec3 force_body = Vec3::Zero();   ///< N, body frame (turns with the body, as a thruster), through the center of mass
  Vec3 torque_body = Vec3::Zero();  ///< N·m, body frame, about the center of mass

  /// The total applied force in the world frame: force + R force_body (N).
  Vec3 applied_force() const { return force + rotation * force_body; }
  /// The total applied torque in the world frame: torque + R torque_body (N·m).
  Vec3 applied_torque() const { return torque + rotation * torque_body; }
  /// True if the body carries any applied load.
  bool loaded() const {
    return !force.isZero(0.0) || !torque.isZero(0.0) || !force_body.isZero(0.0) || !torque_body.isZero(0.0);
  }

  /// J_world = R J_body Rᵀ (kg·m²).
  Mat3 inertia_world() const { return rotation * inertia_body * rotation.transpose(); }
  /// J_world⁻¹ = R J_body⁻¹ Rᵀ (zero for a fixed body).
  Mat3 inv_inertia_world() const {
    Mat3 out;
    inv_inertia_world(out);
    return out;
  }
  /// The same, evaluated in place (a cache of them: no copy through the stack).
  void inv_inertia_world(Mat3& out) const { out.noalias() = rotation * inv_inertia_body * rotation.transpose(); }
  /// Velocity of the material point at world position `p`: u = v + ω × r, r = p − x. The lever arm is
  /// named first: GCC compiles the nested expression through the stack (two scalar stores read back as
  /// one vector, a failed store forwarding), which tripled the cost of the resolvers' most frequent call.
  Vec3 velocity_at(const Vec3& p) const {
    const Vec3 arm = p - position;
    return velocity + angular_velocity.cross(arm);
  }
  /// Orientation as a unit quaternion (w, x, y, z).
  Quat orientation() const { return Quat(rotation).normalized(); }
};

/// Makes `body` fixed: infinite mass and inertia, zero inverses. Its velocities are kept as its
/// prescribed motion if `motion` says it moves, and zeroed otherwise.
inline void make_fixed(RigidBody& body) {
  body.fixed = true;
  body.mass = std::numeric_limits<double>::infinity();
  body.inv_mass = 0.0;
  body.inertia_body = Mat3::Identity() * std::numeric_limits<double>::infinity();
  body.inv_inertia_body.setZero();
  if (body.motion == PrescribedMotion::none) {
    body.velocity.setZero();
    body.angular_velocity.setZero();
  }
}

}  // namespace impetus
