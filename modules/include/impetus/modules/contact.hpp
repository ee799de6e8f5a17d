#pragma once
/// \file
/// Contacts: what a collision detector hands a collision resolver.
///
/// Convention (docs/conventions.md): bodies `a` < `b` by index; world point `point`; unit `normal` pointing
/// **out of a into b**; `depth` ≥ 0 is penetration, a negative value a gap within the detector's margin.
/// Relative normal velocity v_n = (u_b − u_a)·n, with u = v + ω × r; the contact approaches when v_n < 0.
/// An impulse magnitude p ≥ 0 pushes the bodies apart: −p n on a, +p n on b.
/// Friction (docs/conventions.md, "Friction"): a contact's whole impulse is P = p n + p_t with the
/// tangential part p_t ⊥ n, ‖p_t‖ ≤ μ p, μ = combined_friction(a, b); −P acts on a and +P on b.

#include "impetus/core/body.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace impetus {

/// What a resolved contact did (docs/conventions.md, "Friction").
enum class ContactMode : std::uint8_t {
  separate = 0,  ///< no impulse: the bodies part (or never met)
  stick = 1,     ///< an impulse, and no slip after it: v_t⁺ = 0
  slide = 2      ///< an impulse, and slip after it: ‖p_t‖ = μ p, p_t opposite to v_t⁺ (any slip if μ = 0)
};

/// The mode's name as `impetus resolve --json` prints it: "separate", "stick" or "slide".
inline const char* contact_mode_name(ContactMode mode) {
  switch (mode) {
    case ContactMode::stick: return "stick";
    case ContactMode::slide: return "slide";
    default: return "separate";
  }
}

/// One contact point between two bodies.
struct Contact {
  BodyIndex a = 0;           ///< first body (lower index)
  BodyIndex b = 0;           ///< second body
  Vec3 point = Vec3::Zero();   ///< world position of the contact point (m)
  Vec3 normal = Vec3::UnitZ(); ///< unit, world frame, out of a into b
  double depth = 0.0;        ///< penetration (m): > 0 overlap, < 0 gap within the margin
  std::uint64_t feature = 0; ///< detector's stable key (features of a and b) for sorting and matching
  double impulse = 0.0;      ///< output of the resolver: total normal impulse applied (N·s), ≥ 0 pushes
  /// Output of the resolver: total tangential (friction) impulse p_t applied to b, world frame, ⊥ normal
  /// (N·s); −p_t acts on a. Zero when μ = 0.
  Vec3 tangent_impulse = Vec3::Zero();
  ContactMode mode = ContactMode::separate;  ///< output of the resolver: what the contact did
};

/// Coulomb coefficient of a contact between two bodies: the geometric mean √(μ_a μ_b) of the two
/// materials' `friction` (Box2D's rule: a frictionless body makes every one of its contacts frictionless).
inline double combined_friction(const RigidBody& a, const RigidBody& b) {
  return std::sqrt(a.material.friction * b.material.friction);
}

/// A right-handed orthonormal tangent basis (t1, t2, n), t1 × t2 = n, that is a continuous function of
/// the unit `n` except across n_z = −0 (Duff et al., "Building an Orthonormal Basis, Revisited", 2017).
/// Friction does not depend on which basis is used (the cone is round); this one is the convention so
/// that tangent rows and logs are reproducible.
inline void tangent_basis(const Vec3& n, Vec3& t1, Vec3& t2) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double b = n.x() * n.y() * a;
  t1 = Vec3(1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  t2 = Vec3(b, sign + n.y() * n.y() * a, -n.y());
}

/// Relative velocity u_b − u_a of the two bodies at the contact point, u = v + ω × r (m/s); its part
/// along the normal is eq. 5's v_n, the rest is the slip v_t.
inline Vec3 relative_velocity(const Contact& c, const RigidBody& a, const RigidBody& b) {
  return b.velocity_at(c.point) - a.velocity_at(c.point);
}

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

/// Applies the world impulse vector `impulse` at contact `c`: −impulse on a, +impulse on b (Δv = ±P/M,
/// Δω = ±J⁻¹ (r × P)). Fixed bodies are untouched. Friction resolvers apply p n + p_t through it.
inline void apply_contact_impulse(const Contact& c, const Vec3& impulse, RigidBody& a, RigidBody& b) {
  const auto push = [&c](RigidBody& body, const Vec3& p) {
    if (body.fixed) return;
    body.velocity += body.inv_mass * p;
    body.angular_velocity += body.inv_inertia_world() * (c.point - body.position).cross(p);
  };
  push(a, -impulse);
  push(b, impulse);
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
