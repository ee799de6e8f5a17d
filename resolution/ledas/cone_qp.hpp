#pragma once
// A frictional problem by a primal–dual interior-point method (Mehrotra's predictor–corrector with
// Nesterov–Todd scaling, the scheme of Vandenberghe's CVXOPT cone QP solver).
//
// Its convex relaxation (frictional_solver.hpp, `FrictionalProblem::convex`) is the cone program
//
//   minimize ½ rᵀ W r + qᵀ r  over r with  ‖r_t‖ ≤ μ r_n (frictional contacts), r ≥ 0 (frictionless
//   contacts), r free (joint rows);
//
// its optimality conditions are exactly the relaxation's: u = W r + q in the dual cones, r ⊥ u. About
// 15–30 steps of one sparse LDLᵀ each, whatever the redundancy of the contacts (W singular: the iterates
// approach the centre of the solution set, so a symmetric problem gets a symmetric answer), where Newton
// on the natural map stalls.
//
// Coulomb's problem itself (`convex` false) is the same complementarity with De Saxcé's modified velocity
// u + μ‖u_t‖ e_n in place of u: no longer a cone program (the shift depends on r), but the same
// interior-point steps apply to it as to a nonlinear complementarity problem, with the shift evaluated
// at each iterate and its derivative μ (u_t/‖u_t‖)ᵀ ∂u_t/∂r in the step's matrix, which is then not
// symmetric: factorized by KLU, in contact space. Nothing guarantees that it converges (the problem is
// not monotone), but where it does it takes 10–35 steps on problems where Newton's stages take hundreds
// (resolution/ledas/README.md, "Coulomb's problem by the interior point").
#include "impetus/resolution/ledas/frictional_solver.hpp"
#include "impetus/resolution/ledas/masked_ldlt.hpp"
#include "body_space.hpp"
#include "sparse_lu.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace impetus::ledas {

struct ConeQpReport {
  std::uint64_t iterations = 0;  // interior-point steps (one factorization each)
  bool converged = false;        // the natural-map residual fell to the target
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
  // Coulomb's problem: the step's matrix P + T² + E (E the shift's derivative) by rows on h's pattern,
  // and its LU, analysed once per pattern (`coulomb_analysed`, reset when h's pattern is rebuilt).
  RowMajorMatrix coulomb_matrix;
  SparseLu coulomb_lu;
  bool coulomb_analysed = false;
};

/// Into r (size m): the iterate with the smallest natural-map residual of `problem` (the relaxation's
/// if `problem.convex`, else Coulomb's), stopping when it is ≤ `target` or after `max_iterations` steps
/// (the caller then polishes it with Newton on the natural map).
///
/// The relaxation: with `problem.body_space` and more rows than body coordinates, each step's system is
/// solved in body space (cone_qp.cpp) and `ldlt` is left as it was; else `ldlt` factorizes P + T²,
/// analysed afresh only when its pattern changed: when every cone's block lies in W's pattern (a
/// contact's rows share W's pattern), that is W's pattern, so the caller's Newton steps on W
/// (frictional_solver.cpp, `symmetric_direction`) share its analysis.
///
/// Coulomb's problem: in contact space, by KLU (`ldlt` unused); only where a contact's three rows share
/// W's pattern, else nothing is done (`report.iterations` 0, r zero). It also ends when
/// kCoulombStall steps have not halved its best residual.
void solve_cone_qp(const FrictionalProblem& problem, double target, std::uint64_t max_iterations,
                   ConeQpWorkspace& workspace, MaskedLdlt& ldlt, Vector& r, ConeQpReport& report);

}  // namespace impetus::ledas
