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
#include "impetus/resolution/ledas/masked_ldlt.hpp"
#include "body_space.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace impetus::ledas {

struct ConeQpReport {
  std::uint64_t iterations = 0;  // interior-point steps (one factorization each)
  bool converged = false;        // the duality measure and the velocity residual fell below the tolerance
  std::uint64_t body_space_steps = 0;  // of the steps, those whose system was solved in body space
};

/// The interior point's buffers, kept by the caller (FrictionalWorkspace): solving problems whose W has
/// the pattern of the last one, with the same cones, allocates nothing.
struct ConeQpWorkspace {
  // One cone: rows first .. first + size − 1 of x.
  struct Cone {
    Eigen::Index first = 0;
    int size = 1;       // 1: ℝ₊ (or ℝ when free), 3: Q
    bool free = false;  // a joint row: no cone, z = 0
  };
  // Per cone and step: Nesterov–Todd's scaling T (symmetric), T², T⁻¹ and λ = T x.
  struct Scaling {
    Eigen::Matrix3d t, t2, inverse;
    Eigen::Vector3d lambda;
  };
  std::vector<Cone> cones;
  std::vector<Scaling> scaling;
  std::vector<Eigen::Vector3d> eta;
  // P + T² on the pattern of W with every cone's diagonal block; where W's entry e and cone n's entry
  // (a, b) are stored in it (`from_w`, `block`: size² per cone, row-major), for W's pattern `outer`, `inner`.
  SparseMatrix h;
  std::vector<SparseIndex> from_w, block, outer, inner;
  std::vector<char> every_row;
  Vector d, c, x, z, r, best, rd, u, dx_aff, dz_aff, dx, dz;  // u = W r + q of the iterate r
  // In body space (FrictionalProblem::body_space, more rows than body coordinates): (P + T²) Δx = b
  // through M + Bᵀ H B by 6 × 6 blocks (B = D⁻¹ G, H = (T² + δ I)⁻¹ per cone), its pattern and factor
  // in `body`; H per cone, and the solve's vectors.
  BodySpaceWorkspace body;
  std::vector<Eigen::Matrix3d> h_cone;
  Vector hb, y, gy;
};

/// Into r (size m): the relaxation's impulses, the iterate with the smallest natural-map residual of the
/// relaxation (`problem` is the relaxation: `convex`), stopping when it is ≤ `target` or after
/// `max_iterations` steps (the caller then polishes it with Newton on the natural map). With
/// `problem.body_space` and more rows than body coordinates, each step's system is solved in body space
/// (cone_qp.cpp) and `ldlt` is left as it was; else `ldlt` factorizes
/// P + T², analysed afresh only when its pattern changed: when every cone's block lies in W's pattern
/// (a contact's rows share W's pattern), that is W's pattern, so the caller's Newton steps on W
/// (frictional_solver.cpp, `symmetric_direction`) share its analysis.
void solve_cone_qp(const FrictionalProblem& problem, double target, std::uint64_t max_iterations,
                   ConeQpWorkspace& workspace, MaskedLdlt& ldlt, Vector& r, ConeQpReport& report);

}  // namespace impetus::ledas
