#pragma once
/// \file
/// One frictional collision at one contact point, integrated in the normal impulse (B. Mirtich,
/// "Impulse-based Dynamic Simulation of Rigid Body Systems", PhD thesis, UC Berkeley 1996, ch. 4).
/// See resolution/mirtich/README.md for the derivation; in short:
///
/// - The collision matrix K (thesis ch. 4) maps a world impulse P applied +P on b, −P on a at the contact
///   point to the change of the relative contact velocity u = u_b − u_a:
///     K = (1/m_a + 1/m_b) I − [r_a]ₓ J_a⁻¹ [r_a]ₓ − [r_b]ₓ J_b⁻¹ [r_b]ₓ   (fixed bodies contribute nothing).
/// - During the collision the impulse grows as dP = (n − μ û_t) dp_n while the contact slips (û_t the
///   unit slip), so du/dp_n = K (n − μ û_t). Where the slip direction is constant this is
///   linear in p_n and is advanced in closed form; otherwise by adaptive RK4.
/// - When the slip reaches zero (found exactly, not by overshooting) the contact sticks if the impulse
///   direction that keeps u_t ≡ 0, n + d_t with d_t = −K_tt⁻¹ K_tn, lies inside the friction cone
///   (‖d_t‖ ≤ μ); otherwise it slides on along the diverging invariant direction û with
///   K_t (n − μ û) = λ û, λ > 0 (slip reversal).
/// - Compression ends at u_n = 0. Restitution uses Stronge's energetic coefficient: the restitution
///   phase ends when the work of the normal impulse in it equals e² times minus its work in
///   compression. Newton's (u_n⁺ = −e u_n⁻) and Poisson's (p = (1 + e) p_c) rules can create energy
///   with friction (Kane's rod); Stronge's cannot for 0 ≤ e ≤ 1. With e = 0 the collision ends at the
///   end of compression.

#include "impetus/core/body.hpp"

#include <cstdint>

namespace impetus::mirtich {

/// K: the change of the relative velocity u_b − u_a at `point` per unit world impulse (+P on b, −P on
/// a), kg⁻¹ (Mirtich 1996, ch. 4). Symmetric positive semi-definite; zero if both bodies are fixed.
Mat3 collision_matrix(const RigidBody& a, const RigidBody& b, const Vec3& point);

/// Bounds of the integration.
struct FrictionalImpactLimits {
  std::uint32_t max_steps = 20000;   ///< integration steps (linear segments + RK4 steps) per collision
  double relative_tolerance = 1e-13;  ///< RK4 local error per step, relative to the impact speed ‖u⁻‖
};

/// The outcome of one frictional collision.
struct FrictionalImpact {
  double normal_impulse = 0.0;          ///< p_n (N·s, ≥ 0)
  Vec3 tangent_impulse = Vec3::Zero();  ///< p_t (N·s, world, ⊥ n), applied +p_t on b
  Vec3 velocity_after = Vec3::Zero();   ///< u⁺ = u⁻ + K P as integrated (m/s, world)
  double friction_work = 0.0;           ///< ∫ u_t·dp_t over the collision (J, ≤ 0)
  double compression_work = 0.0;        ///< ∫ u_n dp_n over compression (J, ≤ 0)
  double restitution_work = 0.0;        ///< ∫ u_n dp_n over restitution (J, ≥ 0; e² × −compression_work)
  std::uint32_t steps = 0;              ///< integration steps taken
  bool stuck = false;                   ///< the slip reached zero and stayed there (stable sticking)
  bool reversed = false;                ///< the slip reached zero and restarted (slip reversal)
  bool converged = true;                ///< false if max_steps was reached or the collision cannot end
  bool finite = true;                   ///< false if a non-finite number appeared (nothing is usable)

  /// The whole world impulse P = p_n n + p_t.
  Vec3 impulse(const Vec3& normal) const { return normal_impulse * normal + tangent_impulse; }
};

/// Integrates one collision with collision matrix `k`, relative contact velocity `u` (world, m/s,
/// approaching: u·n < 0), unit `normal` (out of a into b), Coulomb coefficient `mu` ≥ 0 and
/// Stronge's coefficient `e` in [0, 1]. Deterministic; at most limits.max_steps steps.
FrictionalImpact integrate_frictional_impact(const Mat3& k, const Vec3& u, const Vec3& normal, double mu, double e,
                                             const FrictionalImpactLimits& limits = {});

}  // namespace impetus::mirtich
