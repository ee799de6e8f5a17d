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
/// **Displacement bound.** With conflicting targets (a body pinned by a joint deep inside the ground:
/// the joint holds, the contact pushes) the correction problem has no solution and the best q can be
/// arbitrarily large. No correction may move a point of a body, at the rows' points, further than
///   L = kCorrectionBoundFactor · Σ_k target_k   (twice the total separation the island asks for)
/// nor turn a body by more than kMaxCorrectionTurn; a larger correction is scaled down as a whole (q ← s q,
/// the same direction) and counted in ResolverCounters::corrections_clamped. A consistent correction
/// moves each point by at most the separations along its path to the support, so it never reaches L.
///
/// **Gaps.** A contact found with a gap g (depth = −g < 0: within the detector's margin, or a speculative
/// contact a fast body gets a step ahead) needs v_n⁺ ≥ −g/dt only (gap_target, impulse_rows.hpp): it may
/// approach until the gap closes exactly at the end of the step, so an inelastic body lands on the
/// surface, never short of it, and one that would not reach it this step gets no impulse. A contact that
/// bounces (e > 0 above the threshold) and would close its gap within the step bounces where it is, with
/// target 0: it leaves at e times its whole approach speed (no energy lost or gained) and turns back up to
/// g early, as Box2D v3's speculative contacts do; the position error is at most (1 + e) g ≤ (1 + e)|v| dt.
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

/// L = kCorrectionBoundFactor · Σ targets (m); see "Displacement bound" above.
inline constexpr double kCorrectionBoundFactor = 2.0;
/// Largest turn a position correction may give a body in one step (rad).
inline constexpr double kMaxCorrectionTurn = 0.5;

/// What bound_correction found: the factor applied to q (1: untouched) and the largest displacement of
/// a row point after it (m).
struct CorrectionBound {
  double scale = 1.0;
  double largest = 0.0;
};

/// The displacement bound of one island's correction: `rows[j]` receives the pseudo-impulse `q[j]`
/// (kg·m), `limit` is L (m). Scales every q[j] by s < 1 when the displacement (translation plus turn at
/// the rows' points, to first order) or a turn would exceed the bound; leaves q bit for bit otherwise.
CorrectionBound bound_correction(std::span<const ImpulseRow* const> rows, std::span<double> q, double limit,
                                 std::span<const RigidBody> bodies);

/// Moves the row's bodies apart by pseudo-impulse `q` (kg·m): Δx = σ q n / M, and R turned by
/// σ q J⁻¹ (r × n) (Rodrigues). Velocities are unchanged. Fixed bodies do not move.
void apply_row_displacement(const ImpulseRow& row, double q, std::span<RigidBody> bodies);

}  // namespace impetus::resolution
