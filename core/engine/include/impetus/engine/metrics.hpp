#pragma once
/// \file
/// Whole-world measures a user checks a simulation with. Fixed bodies are left out.

#include "impetus/engine/world.hpp"

#include <span>

namespace impetus {

struct WorldMetrics {
  double kinetic_energy = 0.0;    ///< Σ ½ m v² + ½ ωᵀ J_world ω (J)
  double potential_energy = 0.0;  ///< Σ −m g·x (J), zero at the origin
  Vec3 linear_momentum = Vec3::Zero();   ///< Σ m v (kg·m/s)
  Vec3 angular_momentum = Vec3::Zero();  ///< Σ (x × m v + J_world ω), about the world origin (kg·m²/s)
  double max_penetration = 0.0;   ///< largest contact depth of the last detection (m, ≥ 0)
  std::size_t contacts = 0;       ///< contacts of the last detection
};

/// Measures `world` now.
WorldMetrics measure(const World& world);

/// Measures a set of bodies (fixed ones left out), with potential energy in `gravity` (m/s²). The
/// contact fields stay zero.
WorldMetrics measure_bodies(std::span<const RigidBody> bodies, const Vec3& gravity = Vec3(0.0, 0.0, -9.81));

/// Kinetic energy Σ ½ m v² + ½ ωᵀ J_world ω of the movable bodies (J).
double total_kinetic_energy(std::span<const RigidBody> bodies);

/// Potential energy of gravity and the (constant) applied forces, −Σ (m g + F)·x over the movable bodies
/// (J), zero at the origin.
double load_potential_energy(std::span<const RigidBody> bodies, const Vec3& gravity);

/// Total energy: kinetic + potential.
inline double total_energy(const WorldMetrics& m) { return m.kinetic_energy + m.potential_energy; }

}  // namespace impetus
