#pragma once
/// \file
/// The equality solves of island_solver.hpp (private): A_SS p = c_S on a subset, each independent block
/// by the cheapest exact method, the minimum-norm solution where a block is rank-deficient. The paper
/// mode's rounds call it through IslandSolver::solve_subset; the complementarity fallback and polish call
/// solve_system and solve_dense_matrix.

#include "impetus/resolution/ledas/island_solver.hpp"

#include <Eigen/Dense>

#include <memory>
#include <span>
#include <vector>

namespace impetus::ledas {

/// Exact solves of A p = c restricted to row subsets. Holds the cache of sparse symbolic analyses.
class EqualitySolver {
 public:
  explicit EqualitySolver(const SolverSettings& settings);
  ~EqualitySolver();
  EqualitySolver(const EqualitySolver&) = delete;
  EqualitySolver& operator=(const EqualitySolver&) = delete;

  /// IslandSolver::solve_subset into `p`: writes the subset's entries only.
  void solve_subset(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset, Vector& p,
                    SolverStats& stats);
  /// Solves one system m p = rhs by the cheapest exact method: closed form, dense, or sparse LDLᵀ;
  /// minimum-norm least squares when m is rank-deficient.
  Vector solve_system(const SparseMatrix& m, const Vector& rhs, SolverStats& stats);
  /// Dense LDLᵀ with diagonal pivoting; minimum-norm least squares when singular (from that LDLᵀ's rank
  /// factorization, or by the eigen-decomposition where that answer fails its check).
  Vector solve_dense_matrix(const Eigen::MatrixXd& a, const Vector& rhs, SolverStats& stats);
  /// The same into `p`, factorizing in `ldlt`: with both sized by an earlier call of the same size, the
  /// regular case allocates nothing (the singular one does).
  void solve_dense_matrix(const Eigen::MatrixXd& a, const Vector& rhs, SolverStats& stats,
                          Eigen::LDLT<Eigen::MatrixXd>& ldlt, Vector& p);

 private:
  struct Factor;  // a sparse LDLᵀ with the pattern its analysis is for (equality_solve.cpp)
  using FactorPtr = std::shared_ptr<Factor>;

  // The rows of `subset` coupled to no other row of it: closed form at once; returns whether any row is
  // coupled (work_.parent[i] = i for those, −1 for the solved ones).
  bool solve_uncoupled(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset, Vector& p,
                       SolverStats& stats);
  // Groups the coupled rows of `subset` into components (work_.start, work_.members, work_.parent).
  void find_components(const SparseMatrix& a, std::span<const RowIndex> subset);
  // Solves the component of root `root` into p.
  void solve_component(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset, int root, Vector& p,
                       SolverStats& stats);
  Vector solve_sparse(const SparseMatrix& m, const Vector& rhs, double pivot_floor, SolverStats& stats);
  bool minimum_norm_from_ldlt(const Eigen::MatrixXd& a, const Eigen::LDLT<Eigen::MatrixXd>& ldlt, const Vector& rhs,
                              double pivot_floor, Vector& p);
  FactorPtr checkout(const SparseMatrix& m, SolverStats& stats);
  void checkin(FactorPtr factor);

  struct Workspace {  // reused buffers (no allocation per round once warm)
    std::vector<int> slot, parent, start, fill, members;  // subset components
    Eigen::MatrixXd dense;
    Vector rhs;
    Eigen::MatrixXd rank_factor, gram_matrix;  // solve_dense_matrix's minimum-norm solve: L_R, L_Rᵀ L_R
    Eigen::LLT<Eigen::MatrixXd> gram;           // and its Cholesky factor
    Vector pivots, permuted, reduced, candidate, residual, normal;
  };
  const SolverSettings& settings_;
  std::vector<FactorPtr> cache_;  // sparse factorizations by pattern, least recently used first
  Workspace work_;
};

}  // namespace impetus::ledas
