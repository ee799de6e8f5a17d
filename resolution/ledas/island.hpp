#pragma once
/// \file
/// One island's working data inside the LEDAS resolver (private: not installed, not for tests): its rows
/// (local row i is the resolver's row rows[i]), A of eq. 7 over them, targets, restitution and the
/// impulses accumulated over the rounds.

#include "impetus/core/body.hpp"
#include "impetus/resolution/common/impulse_rows.hpp"
#include "impetus/resolution/common/incidence.hpp"
#include "impetus/resolution/ledas/constraint_rows.hpp"
#include "impetus/resolution/ledas/frictional_solver.hpp"
#include "impetus/resolution/ledas/island_solver.hpp"

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace impetus::ledas {

/// Relative rounding below which a negative impulse is not counted as pulling, and an energy rise not
/// counted as a gain.
inline constexpr double kRoundoff = 1e-12;

/// One island's working data. A lane keeps its islands' from step to step (lane.hpp); make_island sets
/// every field.
struct Island {
  std::vector<std::uint32_t> rows;    ///< the resolver's rows, increasing
  SparseMatrix a;                     ///< A of eq. 7 over the rows (both triangles)
  std::vector<BodyIndex> bodies;      ///< movable bodies, increasing (their slots in `incidence`)
  resolution::Incidence incidence;    ///< rows ↔ movable bodies
  std::vector<char> equality;         ///< joint rows
  /// Per row: a joint row, a contact's normal row or one of its tangent rows (friction); μ per normal
  /// row. Filled for every island; tangent rows exist only for contacts with μ > 0.
  std::vector<RowRole> role;
  std::vector<double> mu;
  bool frictional = false;            ///< some contact of the island has μ > 0 (and so tangent rows)
  Vector target;                      ///< v_n⁺ bound (m/s): min(0, depth)/dt for contacts, RowInfo::target for joints, 0 for tangent rows
  Vector restitution;                 ///< effective e per row (0 for joint rows)
  Vector impulse_inelastic;           ///< Σ p over rounds (N·s)
  Vector impulse_total;               ///< Σ (1 + e) p over rounds (N·s)
  std::vector<char> entered;          ///< the row took part in a system
  double complementarity = 0.0;       ///< max |Σ p · (v_n − target)| after the last inelastic phase
  std::uint64_t rounds = 0;
  double dt = 0.0;                    ///< the step (s)
  double joint_gap = std::numeric_limits<double>::infinity();  ///< last predicted position-joint gap (m)

  /// Every row's v_n at the bodies' velocities, valid while `velocity_current` (cleared by whatever
  /// changes the island's body velocities without recomputing it).
  Vector velocity;
  bool velocity_current = false;
  std::vector<int> scratch;  ///< assemble_matrix's

  /// The complementarity problems of the impact (complementary mode) and of the position correction,
  /// with their solves' buffers, the impact's targets and the solutions: rebuilt in place each step, so
  /// that an island whose size does not change is solved without allocating (Eigen reallocates a vector
  /// whose size changes).
  ComplementarityProblem impact, correction;
  ComplementarityWorkspace impact_work, correction_work;
  Vector impact_target, impact_solution, correction_solution;
  std::vector<RowIndex> kept;  ///< a frictional island's correction rows (all but tangent rows)
  BodySpace body_space;        ///< A's factored form for an impact that suits the interior point
  BodySpace correction_body_space;  ///< ... for a position correction (solved alongside the impact)
  bool correction_refused = false;  ///< the correction's solver refused its answer (zero returned)
  std::vector<const resolution::ImpulseRow*> correction_rows;  ///< apply_correction's rows
  SparseMatrix restricted;     ///< and A over them

  /// A frictional island's impact (frictional_impact.cpp), in buffers kept the same way: the problem
  /// (role, μ and q copied into it), the solve's workspace, the warm start and a phase's impulse, the
  /// rows' velocities before the impact (v₀), after its inelastic phase (v₁) and before an impulse is
  /// applied, the restitution phase's targets, and A r.
  FrictionalProblem friction;
  FrictionalWorkspace friction_work;
  Vector friction_start, friction_impulse;
  Vector velocity_start, velocity_inelastic, velocity_before;
  Vector bounce_target, product;

  /// Sets `complementarity` = max over contact normal rows of |Σ p · (v_n − target)| at velocities v (after
  /// an inelastic phase).
  void measure_complementarity(const Vector& v, const Vector& target_now);
  /// Whether row i is a contact's normal row (not a joint row, not a tangent row).
  bool normal_row(std::size_t i) const { return role[i] == RowRole::normal; }
  /// Whether any row bounces (e > 0).
  bool bouncing() const { return restitution.size() > 0 && restitution.maxCoeff() > 0.0; }
};

/// A of eq. 7 over the rows `island` of `rows` (local indices), both triangles stored, exactly symmetric,
/// into `a` (its storage reused); `below` is scratch.
void assemble_matrix(std::span<const resolution::ImpulseRow> rows, std::span<const std::uint32_t> island,
                     const resolution::Incidence& incidence, SparseMatrix& a, std::vector<int>& below);

/// Whether a problem over `rows` rows of the island may go to the body-space interior point
/// (SolverSettings::interior_point_rows; body_space.hpp decides finally): worth assembling its G and M.
bool wants_body_space(const Island& island, std::size_t rows, const SolverSettings& settings);

/// G and M of A = G M⁻¹ Gᵀ (BodySpace) for the island's local rows `local` (all rows if empty), into `out`.
void assemble_body_space(std::span<const resolution::ImpulseRow> rows, const Island& island,
                         std::span<const RowIndex> local, std::span<const RigidBody> bodies, BodySpace& out);

/// Kinetic energy of the bodies `which` (J).
double kinetic_energy(std::span<const RigidBody> bodies, std::span<const BodyIndex> which);

/// Sets the target of the island's position-level joint rows (eqs. 9–10) from the gap predicted at the
/// rows' velocities v (m/s); returns whether another round is worth it (the gap, in m, is above 1e-9 and
/// fell by half at least since the last call).
bool retarget_joints(Island& island, std::span<const resolution::ImpulseRow> rows, std::span<const RowInfo> info,
                     const Vector& v, std::span<const RigidBody> bodies);

/// The target a row is solved for this round. A gap contact that closes within the step and bounces
/// (e > 0) is an impact now: target 0, so (1 + e) p returns its full energy.
inline double solve_target(double base_target, bool closing, double restitution) {
  return closing && restitution > 0.0 ? 0.0 : base_target;
}

}  // namespace impetus::ledas
