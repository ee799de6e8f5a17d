#pragma once
// The convex relaxation of a frictional problem (frictional_solver.hpp, `FrictionalProblem::convex`) as
// the cone program it is,
//
//   minimize ½ rᵀ W r + qᵀ r  over r with  ‖r_t‖ ≤ μ r_n (frictional contacts), r ≥ 0 (frictionless
//   contacts), r free (joint rows);
//
// its optimality conditions are exactly the relaxation's: u = W r + q in the dual cones, r ⊥ u. Solved by
// a primal–dual interior-point method (Mehrotra's predictor–corrector with Nesterov–Todd scaling, the
// scheme of Vandenberghe's CVXOPT cone QP solver): about 15–30 steps of one sparse LDLᵀ each, whatever
// the redundancy of the contacts (W singular: the iterates approach the centre of the solution set, so a
// symmetric problem gets a symmetric answer), where Newton on the natural map stalls.
#include "impetus/resolution/ledas/frictional_solver.hpp"

#include <cstdint>

namespace impetus::ledas {

struct ConeQpReport {
  std::uint64_t iterations = 0;  // interior-point steps (one factorization each)
  bool converged = false;        // the duality measure and the velocity residual fell below the tolerance
};

/// The relaxation's impulses r (size m): the iterate with the smallest natural-map residual of the
/// relaxation, stopping when it is ≤ `target` or after `max_iterations` steps (the caller then polishes it
/// with Newton on the natural map).
Vector solve_cone_qp(const FrictionalProblem& problem, double target, std::uint64_t max_iterations,
                     ConeQpReport& report);

}  // namespace impetus::ledas
