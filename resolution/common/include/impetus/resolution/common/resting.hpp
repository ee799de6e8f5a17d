#pragma once
/// \file
/// Resting contact, shared by every impulse resolver.
///
/// With the default split step (velocities → detect → resolve → positions; docs/conventions.md, "The
/// step") a resting body does not sink: the resolver removes the approach that gravity added before
/// positions move. What remains is penetration that is already there (initial overlap, rounding,
/// rotation of corners, the paper's step order). It is removed by a **position correction** that adds no
/// kinetic energy: after the velocity solve, each resolver solves the same system once more for
/// non-negative "pseudo-impulses" q whose displacement separates the bodies by
///   target_k = correction · max(0, depth_k − slop)            (m, along n_k)
/// using A q ≥ target, q ≥ 0, q·(A q − target) = 0 (A of eq. 7 maps pseudo-impulses to changes of
/// separation, to first order in the displacement). The displacement moves positions and rotations
/// directly (apply_row_displacement) and never touches velocities.
///
/// A bounce threshold stops jitter: an island whose fastest approach is slower than `bounce_threshold`
/// gets e = 0. It is judged per island, not per contact, because in a simultaneous impact touching
/// contacts (v_n = 0) carry the restitution phase too (Newton's cradle: (1 + e) p on every contact).

#include "impetus/modules/options.hpp"
#include "impetus/resolution/common/impulse_rows.hpp"
#include "impetus/settings/resting.hpp"  // RestingSettings

#include <algorithm>

namespace impetus::resolution {

/// The restitution applied at a row of an island whose fastest approach speed is `impact_speed`
/// (m/s, ≥ 0): the row's coefficient, or 0 below the bounce threshold.
inline double effective_restitution(const ImpulseRow& row, double impact_speed, const RestingSettings& settings) {
  return impact_speed < settings.bounce_threshold ? 0.0 : row.restitution;
}

/// Separation (m along n) the position correction asks for at a contact of `depth` (m).
inline double correction_target(double depth, const RestingSettings& settings) {
  return settings.correction * std::max(0.0, depth - settings.slop);
}

/// Moves the row's bodies apart by pseudo-impulse `q` (kg·m): Δx = σ q n / M, and R turned by
/// σ q J⁻¹ (r × n) (Rodrigues). Velocities are unchanged. Fixed bodies do not move.
void apply_row_displacement(const ImpulseRow& row, double q, std::span<RigidBody> bodies);

}  // namespace impetus::resolution
