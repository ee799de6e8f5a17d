#pragma once
/// \file
/// A complementarity problem with redundant rows solved in body space by a primal–dual interior point
/// (private; resolution/ledas/README.md, "Redundant islands: an interior point in body space").

#include "impetus/resolution/ledas/island_solver.hpp"

#include <Eigen/SparseCholesky>

namespace impetus::ledas {

/// The interior point's buffers, kept by the complementarity solver between calls.
struct BodySpaceWorkspace {
  SparseMatrix jacobian_t;  ///< Gᵀ
  SparseMatrix system;      ///< M + Gᵀ D G
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> factor;
  Vector u, p, s, dual, primal, ratio, rhs, du, ds, dp, du_aff, ds_aff, dp_aff, target, complement, candidate, w, check;
};

/// Whether `problem` goes to the interior point first: it brings its body-space form, has no equality
/// row, at least settings.interior_point_rows rows (0: never) and more rows than body coordinates (so A
/// is singular: redundant contacts, where the active-set search releases a face's rows one by one).
bool suits_body_space(const ComplementarityProblem& problem, const SolverSettings& settings);

/// Solves the problem's convex QP min ½ uᵀM u s.t. G u ≥ c (u = M⁻¹Gᵀp, the velocity change) by
/// Mehrotra's predictor–corrector; its multipliers are p. Returns true, with p, once p ≥ 0 and
/// w = A p − c meet the ε-complementarity rule: w ≥ −tolerance on every row and p_k w_k ≤ 1e-4 ·
/// tolerance · max p (rows separating by more than the tolerance then let go of their impulses if the
/// rule still holds without them). Otherwise (no convergence within its step cap) false, p untouched.
bool solve_in_body_space(const ComplementarityProblem& problem, BodySpaceWorkspace& work, SolverStats& stats,
                         Vector& p);

}  // namespace impetus::ledas
