#pragma once
/// \file
/// LDLᵀ of a symmetric positive definite matrix made of 6 × 6 blocks, one block row and column per body
/// (internal): the body-space Newton system M + Gᵀ D G of body_space.cpp. The scalar masked LDLᵀ
/// (masked_ldlt.hpp) handles rows one at a time, with a mask, a rank test and an indirect index per
/// entry; here a body's six rows share their pattern, so the same up-looking algorithm (T. Davis,
/// "Algorithm 849") runs on the graph of bodies with dense 6 × 6 products: L unit lower triangular by
/// blocks, D block diagonal, each D_k factorized by Cholesky. Ordered by approximate minimum degree on
/// the bodies; serial and deterministic; no allocation after analyze().

#include "impetus/resolution/ledas/masked_ldlt.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <span>
#include <vector>

namespace impetus::ledas {

class BlockLdlt {
 public:
  using Block = Eigen::Matrix<double, 6, 6>;

  /// The pattern by block columns: column t's blocks are rows neighbours[start[t] .. start[t + 1]),
  /// increasing, t among them; symmetric (s in column t's list iff t in column s's).
  void analyze(std::span<const SparseIndex> start, std::span<const SparseIndex> neighbours);
  /// Whether analyze() was given this pattern.
  bool same_pattern(std::span<const SparseIndex> start, std::span<const SparseIndex> neighbours) const;

  /// Factorizes the matrix whose block (neighbours[e], t) is values[e] for e in column t's range (both
  /// triangles given; the lower one is read). False if a pivot block is not positive definite (or not
  /// finite): the matrix is not, to rounding.
  bool factorize(std::span<const Block> values);

  /// Solves A x = b in place (size 6 × blocks).
  void solve(Eigen::Ref<Eigen::VectorXd> x) const;

 private:
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  SparseIndex blocks_ = 0;
  std::vector<SparseIndex> start_, neighbours_;  // the pattern analysed (the key of same_pattern)
  std::vector<SparseIndex> order_, new_of_old_;  // order_[new] = old
  // Lower triangle of P A Pᵀ by block rows: row k's blocks (columns i ≤ k, new order) and where each is
  // in `values` (the block (old i, old k) of column old k, transposed on use).
  std::vector<SparseIndex> c_outer_, c_column_, c_value_;
  std::vector<SparseIndex> parent_, row_outer_, row_index_;  // elimination tree; row patterns (topological)
  std::vector<SparseIndex> l_outer_, l_count_, l_row_;       // L by block columns
  std::vector<Block> l_value_, y_;
  std::vector<Block> pivots_;  // D_k's Cholesky factors C (lower: D_k = C Cᵀ)
  std::vector<Vector6> pivot_inverse_diagonal_;
  void solve_pivot(SparseIndex k, double* x) const;
  void divide_by_pivot(SparseIndex k, const Block& z, Block& l) const;
  mutable std::vector<Vector6> work_;
};

}  // namespace impetus::ledas
