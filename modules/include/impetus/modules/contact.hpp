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

/// Relative normal velocity v_n = (u_b − u_a)·n at the contact (m/s); < 0 approaches.
inline double normal_velocity(const Contact& c, const RigidBody& a, const RigidBody& b) {
  return (b.velocity_at(c.point) - a.velocity_at(c.point)).dot(c.normal);
}

/// Restitution of a contact between two bodies: the larger of the two materials' coefficients.
inline double combined_restitution(const RigidBody& a, const RigidBody& b) {
  return std::max(a.material.restitution, b.material.restitution);
}

/// Applies impulse magnitude `p` at contact `c` with the sign of docs/conventions.md: −p n on a, +p n on b
/// (Δv_a = −p n / M_a, Δω_a = −J_a⁻¹ (r_a × p n), and the opposite for b). Fixed bodies are untouched.
inline void apply_contact_impulse(const Contact& c, double p, RigidBody& a, RigidBody& b) {
  const Vec3 impulse = p * c.normal;
  if (!a.fixed) {
    a.velocity -= a.inv_mass * impulse;
    a.angular_velocity -= a.inv_inertia_world() * (c.point - a.position).cross(impulse);
  }
  if (!b.fixed) {
    b.velocity += b.inv_mass * impulse;
    b.angular_velocity += b.inv_inertia_world() * (c.point - b.position).cross(impulse);
  }
}

}  // namespace impetus
