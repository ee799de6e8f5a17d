#pragma once
/// \file
/// A frictional contact problem in local form, as the Frictional Contact Library (fclib) stores it, for a
/// resolver that can solve one directly (CollisionResolver::solve_contact_problem): `impetus fclib solve`,
/// benchmarks of published problems, and round trips of the problems Impetus exports.
///
/// With m = 3·contacts + equalities rows, find r and u (both size m) such that
///
///   u = W r + q,
///   per contact α (rows 3α, 3α+1, 3α+2: normal, t1, t2):  r_α ∈ K_α = {‖r_t‖ ≤ μ_α r_n},
///       û_α = u_α + (μ_α‖u_t‖, 0, 0) ∈ K_α*,  r_α ⊥ û_α   (Coulomb's law, De Saxcé's form);
///   the last `equalities` rows (fclib's mixed form, W = [W V; Vᵀ R], q = [q; s]):  u = 0, r free.
///
/// Views only: the caller owns every array, and they cross the plugin boundary by layout (layout word
/// LayoutType::local_contact_problem), so the struct holds plain pointers and sizes.

#include <cstdint>

namespace impetus {

struct LocalContactProblem {
  std::uint64_t contacts = 0;    ///< n_c: three rows each, first
  std::uint64_t equalities = 0;  ///< rows after the contacts' rows: u = 0 with r free
  /// W (m × m), compressed sparse columns, symmetric positive semi-definite with both triangles stored:
  /// column j's entries are w_values[k] at rows w_rows[k] for k in [w_columns[j], w_columns[j+1]).
  const std::int32_t* w_columns = nullptr;  ///< size m + 1
  const std::int32_t* w_rows = nullptr;     ///< size w_columns[m]
  const double* w_values = nullptr;         ///< size w_columns[m]
  const double* q = nullptr;                ///< size m (m/s)
  const double* mu = nullptr;               ///< size contacts, each ≥ 0
  /// The natural-map residual to reach (absolute; docs/conventions.md, "Which solution"): the 2-norm over
  /// rows of r − P_K(r − û) for contacts and u for equality rows.
  double tolerance = 1e-10;
};

/// What the resolver found; r and u point to caller-owned arrays of size m, overwritten.
struct LocalContactSolution {
  double* r = nullptr;        ///< impulses (N·s), per contact (r_n, r_t1, r_t2), then the equality rows'
  double* u = nullptr;        ///< velocities u = W r + q (m/s)
  double residual = 0.0;      ///< the natural-map residual of r (as defined above)
  std::uint64_t iterations = 0;  ///< the solver's own count of steps (each one factorization or sweep)
  bool converged = false;     ///< residual ≤ tolerance
};

}  // namespace impetus
