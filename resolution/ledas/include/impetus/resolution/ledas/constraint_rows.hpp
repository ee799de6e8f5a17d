#pragma once
/// \file
/// The rows of the LEDAS system besides contacts: assembly constraints (paper, sec. 4), as equality
/// rows of the same A p = c (eq. 6). Each row reuses resolution::ImpulseRow (A of eq. 7 through
/// resolution::coupling, impulses through resolution::apply_row_impulse); what a row needs beyond
/// that algebra is in RowInfo.
///
/// A joint row acts at the joined point of a on body a and at the joined point of b on body b: once the
/// points have drifted apart the two lever arms differ, and the row's arms are taken from each body's
/// own point so that A stays exactly G M⁻¹ Gᵀ for the velocities the row measures.
///
/// Levels (ConstraintLevel):
///  - velocity: target v_n⁺ = 0 along each row (the paper's first scheme; the points drift apart);
///  - position: eqs. 9–10 as docs/conventions.md reads them: the points coincide after the step. To first
///    order, s + dt·v_n⁺ = 0 with s the current separation along the row, i.e. target v_n⁺ = −s/dt.
///    The row uses the exact prediction instead: s⁺ = the separation after a step at the current
///    velocities, the bodies moved as eq. 2 moves them (x += dt v, R = Q(ω dt) R), and target
///    v_n⁺ = v_n⁻ − s⁺/dt. It equals −s/dt to first order, and removes the gap that the rotation's
///    curvature (½ (ω dt)² r per step) leaves with the first-order form. Eq. 9's factor dt multiplies
///    a whole row of A and b and is divided out, keeping A symmetric.

#include "impetus/modules/constraint.hpp"
#include "impetus/resolution/common/impulse_rows.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace impetus::ledas {

/// What the system needs about a row beyond its algebra (resolution::ImpulseRow): its kind and target.
struct RowInfo {
  double depth = 0.0;           ///< contact penetration (m): > 0 overlap, < 0 gap; 0 for a joint row
  double target = 0.0;          ///< joint rows: the wanted v_n⁺ (m/s): 0, or v_n⁻ − s⁺/dt (see the file comment)
  bool equality = false;        ///< a joint row: impulse of either sign, never released, e = 0
  bool position_level = false;  ///< a joint row of ConstraintLevel::position (target recomputed by the resolver)
  std::int64_t contact = -1;    ///< index of the row's contact, or −1 for a joint row
  /// A contact's rows: 0 for its normal row, 1 or 2 for its tangent rows (friction), which follow the
  /// normal row directly (directions t1, t2 of tangent_basis(normal)).
  std::uint8_t tangent = 0;
  double friction = 0.0;        ///< a contact's μ (combined_friction; on all three of its rows)
};

/// A position-level joint row's separation s⁺ (m, along the row) after a step of `dt` at the bodies'
/// current velocities, the bodies moved as eq. 2 moves them (x += dt v, R = Q(ω dt) R).
double predicted_separation(const resolution::ImpulseRow& row, std::span<const RigidBody> bodies, double dt);

/// The most rows append_constraint_rows() adds for one constraint (point-point 3, coaxial 4).
inline constexpr std::size_t kMaxConstraintRows = 4;

/// Appends the rows of `constraint` at the bodies' current poses for a step of `dt` (s), the bodies' J⁻¹
/// from `inertia` (reset for `bodies`):
///  - point-point: three rows at the joined points, normals along the world axes (mutually
///    perpendicular, as the paper prescribes), e = 0;
///  - coaxial: at b's two axis points q_0 = anchor_b and q_1 = anchor_b + length·axis_b, the foot of
///    each on a's axis, two rows with normals perpendicular to a's axis (sec. 4, last paragraph).
void append_constraint_rows(std::span<const RigidBody> bodies, resolution::InverseInertiaCache& inertia,
                            const Constraint& constraint, double dt, std::vector<resolution::ImpulseRow>& rows,
                            std::vector<RowInfo>& info);

/// How far a constraint is from holding (m): point-point, |p_b − p_a|; coaxial, the larger distance of
/// b's two axis points from a's axis.
double constraint_gap(std::span<const RigidBody> bodies, const Constraint& constraint);

/// Why this resolver cannot enforce `constraint` (empty when it can): a zero or non-finite axis, a
/// non-positive length, a non-finite anchor.
std::string constraint_problem(const Constraint& constraint);

/// Per constraint: whether it is identical to an earlier one (same kind, bodies, anchors, axes, length
/// and level; `collide` aside), so its rows would repeat the earlier one's row for row. Hashed keys:
/// O(n) in the number of constraints.
std::vector<char> duplicate_constraints(std::span<const Constraint> constraints);

}  // namespace impetus::ledas
