#pragma once
// Sparse LU of the frictional Newton's non-symmetric Jacobians (frictional_solver.cpp), by KLU
// (SuiteSparse; T. Davis and E. Palamadai Natarajan, "Algorithm 907: KLU, a direct sparse solver for
// circuit simulation problems", ACM TOMS 37(3), 2010): a fill-reducing order and symbolic analysis kept
// while the pattern holds, a left-looking numeric factorization with partial pivoting, and a
// refactorization that reuses the last pivot sequence, allocation-free, for the next matrix of the
// pattern. KLU is deterministic: the same matrices in the same order give the same bits.
//
// The matrix is stored by rows (the Newton's assembly fills a block's rows, frictional_solver.cpp):
// KLU, which reads compressed columns, sees Aᵀ, factorizes it, and solves with its transpose.
#include "impetus/resolution/ledas/frictional_solver.hpp"

#include <klu.h>

namespace impetus::ledas {

using RowMajorMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

class SparseLu {
 public:
  SparseLu();
  ~SparseLu();
  SparseLu(const SparseLu&) = delete;
  SparseLu& operator=(const SparseLu&) = delete;

  /// Orders and analyses the pattern of `a` (square, compressed); forgets any factorization.
  /// False if KLU refuses the pattern (then factorize() fails too).
  bool analyze(const RowMajorMatrix& a);
  /// Factorizes `a` (the pattern analyze() was given): with the last pivot sequence when `reuse_pivots`
  /// and there is one (refactorization), else with partial pivoting. False if singular to KLU.
  bool factorize(const RowMajorMatrix& a, bool reuse_pivots);
  /// x ← A⁻¹ x for the last factorization. False if KLU failed.
  bool solve(Vector& x);

 private:
  void free_numeric();
  klu_common common_;
  klu_symbolic* symbolic_ = nullptr;
  klu_numeric* numeric_ = nullptr;
};

}  // namespace impetus::ledas
