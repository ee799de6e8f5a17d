#pragma once
/// \file
/// Contacts: what a collision detector hands a collision resolver.
///
/// Convention (docs/conventions.md): bodies `a` < `b` by index; world point `point`; unit `normal` pointing
/// **out of a into b**; `depth` ≥ 0 is penetration, a negative value a gap within the detector's margin.
/// Relative normal velocity v_n = (u_b − u_a)·n, with u = v + ω × r; the contact approaches when v_n < 0.
/// An impulse magnitude p ≥ 0 pushes the bodies apart: −p n on a, +p n on b.

#include "impetus/core/body.hpp"

#include <algorithm>
#include <cstdint>

namespace impetus {

/// One contact point between two bodies.
struct Contact {
  BodyIndex a = 0;           ///< first body (lower index)
  BodyIndex b = 0;           ///< second body
  Vec3 point = Vec3::Zero();   ///< world position of the contact point (m)
  Vec3 normal = Vec3::UnitZ(); ///< unit, world frame, out of a into b
  double depth = 0.0;        ///< penetration (m): > 0 overlap, < 0 gap within the margin
  std::uint64_t feature = 0; ///< detector's stable key (features of a and b) for sorting and matching
  double impulse = 0.0;      ///< output of the resolver: total normal impulse applied (N·s), ≥ 0 pushes
};

/// Eq. 5, the one definition every module uses: the relative normal velocity
/// v_n = (u_b(point_b) − u_a(point_a))·n of two bodies along the unit `normal` (out of a into b), with
/// u = v + ω × r (m/s); < 0 approaches. A contact has point_a = point_b; a joint row has one point on each.
inline double relative_normal_velocity(const RigidBody& a, const Vec3& point_a, const RigidBody& b,
                                       const Vec3& point_b, const Vec3& normal) {
  return (b.velocity_at(point_b) - a.velocity_at(point_a)).dot(normal);
}

/// Relative normal velocity v_n = (u_b − u_a)·n at the contact (m/s); < 0 approaches.
inline double normal_velocity(const Contact& c, const RigidBody& a, const RigidBody& b) {
  return relative_normal_velocity(a, c.point, b, c.point, c.normal);
}

/// Eq. 3 for one body, the one definition every module uses: an impulse of signed magnitude `p` along
/// the unit `normal` (−p on a contact's body a, +p on its body b) changes the body's velocity by
/// p n / M and its angular velocity by p J⁻¹ (r × n), where `turn` = J⁻¹ (r × n) (1/(kg·m)) is given by
/// the caller (a resolver computes it once per row). A fixed body is untouched.
inline void apply_normal_impulse(RigidBody& body, double p, const Vec3& normal, const Vec3& turn) {
  if (body.fixed) return;
  body.velocity += (p * body.inv_mass) * normal;
  body.angular_velocity += p * turn;
}

/// Restitution of a contact between two bodies: the larger of the two materials' coefficients.
inline double combined_restitution(const RigidBody& a, const RigidBody& b) {
  return std::max(a.material.restitution, b.material.restitution);
}

/// Applies impulse magnitude `p` at contact `c` with the sign of docs/conventions.md: −p n on a, +p n on b
/// (Δv_a = −p n / M_a, Δω_a = −J_a⁻¹ (r_a × n) p, and the opposite for b). Fixed bodies are untouched.
inline void apply_contact_impulse(const Contact& c, double p, RigidBody& a, RigidBody& b) {
  const auto turn = [&c](const RigidBody& body) -> Vec3 {
    return body.fixed ? Vec3::Zero() : Vec3(body.inv_inertia_world() * (c.point - body.position).cross(c.normal));
  };
  apply_normal_impulse(a, -p, c.normal, turn(a));
  apply_normal_impulse(b, p, c.normal, turn(b));
}

}  // namespace impetus
