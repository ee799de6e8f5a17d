#pragma once
/// \file
/// A complementarity problem with redundant rows solved in body space by a primal–dual interior point
/// (private; resolution/ledas/README.md, "Redundant islands: an interior point in body space").

#include "impetus/resolution/ledas/island_solver.hpp"
#include "impetus/resolution/ledas/block_ldlt.hpp"

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace impetus::ledas {

/// The interior point's buffers, kept by the complementarity solver between calls: with them a problem
/// whose sizes and pattern repeat is solved without allocating, and its symbolic analysis is reused.
struct BodySpaceWorkspace {
  std::vector<BlockLdlt::Block> system;  ///< M + Gᵀ D G by 6 × 6 blocks, on the pattern `neighbours`
  BlockLdlt factor;                      ///< its LDLᵀ; analysed again only when the pattern changes
  bool analysed = false;
  std::vector<SparseIndex> neighbour_start, neighbours;  ///< per block column: the blocks it shares a row with (and itself)
  std::vector<std::array<SparseIndex, 4>> offsets;     ///< per row: its blocks aa, ab, ba, bb in `system`
  std::vector<SparseIndex> diagonal_offsets;           ///< per body: its own block
  std::vector<std::pair<SparseIndex, SparseIndex>> pairs;  ///< build_pattern's scratch
  Vector u, p, s, dual, primal, ratio, rhs, du, ds, dp, du_aff, ds_aff, dp_aff, target, complement, candidate, w,
      check;
  Vector best;  ///< the best iterate within reach of a stall's acceptance (body_space.cpp)
};

/// out = G u (one entry per row) and out = Gᵀ p (6 per block), from the rows' blocks.
void multiply_g(const BodySpace& body, const Vector& u, Vector& out);
void multiply_g_transpose(const BodySpace& body, const Vector& p, Vector& out);

/// The block pattern of M + Gᵀ D G into `work` (neighbour_start, neighbours; `system` sized to it), and
/// where each row's four blocks and each body's diagonal block lie in it (offsets, diagonal_offsets).
void build_body_pattern(const BodySpace& body, BodySpaceWorkspace& work);

/// `work.system` (on build_body_pattern's pattern) set to M: each body's diag(m I₃, J), zero elsewhere.
void mass_blocks(const BodySpace& body, BodySpaceWorkspace& work);

/// Whether `problem` goes to the interior point first: it brings its body-space form, has no equality
/// row, at least settings.interior_point_rows rows (0: never) and more rows than body coordinates (so A
/// is singular: redundant contacts, where the active-set search releases a face's rows one by one).
bool suits_body_space(const ComplementarityProblem& problem, const SolverSettings& settings);

/// Solves the problem's convex QP min ½ uᵀM u s.t. G u ≥ c (u = M⁻¹Gᵀp, the velocity change) by
/// Mehrotra's predictor–corrector; its multipliers are p. Returns true, with p, once p ≥ 0 and
/// w = A p − c meet the ε-complementarity rule: w ≥ −tolerance on every row and p_k w_k ≤
/// max(1e-4 · tolerance, rounding) · max p (rows separating by more than the tolerance then let go of
/// their impulses if the rule still holds without them). At a stall (no better iterate in 10 steps, or
/// 10 steps that do not halve the best), its best iterate if no row approaches there and its products
/// are within `stall_excess` of that bound (SolverStats::interior_point_loose). Otherwise (its step cap,
/// a stall, a pivot ≤ 0) false, p untouched.
bool solve_in_body_space(const ComplementarityProblem& problem, double stall_excess, BodySpaceWorkspace& work,
                         SolverStats& stats, Vector& p);

}  // namespace impetus::ledas
