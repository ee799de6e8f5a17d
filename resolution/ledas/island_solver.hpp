#pragma once
/// \file
/// Exact solution of one island's system (the paper's eq. 6, A p = c) and of its complementarity
/// problem. Knows nothing of bodies or detectors: a symmetric positive semi-definite matrix A (eq. 7,
/// A = G M⁻¹ Gᵀ) and a right-hand side come in, impulses come out, so it is tested directly.
///
/// The cheapest exact method per system (shared/DESIGN.md, "Model no more than a scene needs"):
///  - one row: closed form p = c / A_11;
///  - up to `dense_limit` rows: dense LDLᵀ with diagonal pivoting (rank-revealing for a PSD matrix);
///  - more rows: sparse LDLᵀ (Eigen SimplicialLDLT, AMD ordering). Its symbolic analysis is cached by
///    sparsity pattern and reused while the pattern is unchanged (a resting stack step after step).
///    Inside an active-set loop, a change of at most `update_limit` rows is solved by a Schur-complement
///    update of the last factorization instead of refactoring;
///  - a rank-deficient A (a pivot ≤ rank_tolerance · max A_ii: redundant contacts, the paper's
///    Figure 2) gets the minimum-norm least-squares solution, as the paper prescribes: dense by the
///    eigen-decomposition (the SVD of a symmetric PSD matrix), sparse by projecting out a null-space
///    basis found by shifted inverse iteration. The rank test decides, never a failed factorization.

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace impetus::ledas {

/// Column-major sparse matrix with both triangles stored (A is symmetric).
using SparseMatrix = Eigen::SparseMatrix<double>;
using Vector = Eigen::VectorXd;
/// Index of a row within an island's system.
using RowIndex = std::uint32_t;

/// How systems are solved (configuration; read once from the resolver's options).
struct SolverSettings {
  std::size_t dense_limit = 64;   ///< systems of at most this many rows use the dense path
  double rank_tolerance = 1e-10;  ///< a pivot or eigenvalue ≤ this × max A_ii counts as zero
  std::size_t update_limit = 16;  ///< sparse path: largest active-set change solved by an update
  std::uint64_t max_iterations = 10000;  ///< active-set iterations per complementarity problem
};

/// What the solver did, accumulated over calls (reset by the caller).
struct SolverStats {
  std::uint64_t closed_form = 0;  ///< one-row systems
  std::uint64_t dense = 0;        ///< dense LDLᵀ factorizations
  std::uint64_t sparse = 0;       ///< sparse LDLᵀ factorizations
  std::uint64_t updated = 0;      ///< systems solved by a Schur-complement update (no refactoring)
  std::uint64_t singular = 0;     ///< rank-deficient systems (minimum-norm solution returned)
  std::uint64_t symbolic_analyses = 0;  ///< sparse symbolic analyses computed
  std::uint64_t symbolic_reused = 0;    ///< sparse factorizations that reused a cached analysis
  std::uint64_t iterations = 0;   ///< active-set iterations (one linear solve each)
  std::uint64_t released = 0;     ///< rows released because their impulse came out negative (pulling)
  std::uint64_t added = 0;        ///< rows added because they would have approached
  std::uint64_t non_converged = 0;  ///< complementarity problems that hit max_iterations
  std::uint64_t nan_caught = 0;   ///< systems whose solution was not finite (zero returned)
};

/// One island's complementarity problem: find p with w = A p − c and
///   equality rows: w = 0, p free;   the other rows: p ≥ 0, w ≥ −tolerance, p·w = 0.
/// For the velocity phase p are impulses (N·s), c = target − v_n⁻ and w = v_n⁺ − target (m/s).
struct ComplementarityProblem {
  const SparseMatrix* matrix = nullptr;  ///< A (m × m), symmetric PSD, both triangles stored
  Vector rhs;                            ///< c (m)
  std::vector<char> equality;            ///< per row: an equality row (constraint), never released
  std::vector<char> start;               ///< per row: in the first active set (approaching or touching)
  double tolerance = 1e-9;               ///< w below −tolerance is a violation (units of w)
};

/// Solves island systems exactly. Holds the cache of sparse symbolic analyses, so one instance per
/// resolver; not thread-safe.
class IslandSolver {
 public:
  explicit IslandSolver(SolverSettings settings = {});
  ~IslandSolver();
  IslandSolver(const IslandSolver&) = delete;
  IslandSolver& operator=(const IslandSolver&) = delete;

  /// Solves A_SS p_S = c_S (eq. 6) for the rows `subset` (increasing) of `a`; returns p over all rows
  /// of `a`, zero outside the subset. Minimum-norm least squares when A_SS is rank-deficient.
  Vector solve_subset(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset,
                      SolverStats& stats);

  /// Solves the complementarity problem by a primal active-set method started from the given set
  /// (island_solver.cpp): solve the free rows as equalities; step back from a minimizer with negative
  /// impulses and release the rows that reach zero; add every row that would approach. The QP objective
  /// ½ pᵀA p − cᵀp never increases, so it terminates also for singular A. Returns p with p ≥ 0 on
  /// inequality rows (the last feasible iterate if max_iterations is reached).
  Vector solve_complementarity(const ComplementarityProblem& problem, SolverStats& stats);

  const SolverSettings& settings() const { return settings_; }

 private:
  struct Factor;
  using FactorPtr = std::shared_ptr<Factor>;

  struct ActiveBase {  // the last sparse factorization of an active-set loop, for updates
    FactorPtr factor;
    std::vector<char> rows;
  };

  Vector solve_active(const SparseMatrix& a, const Vector& c, const std::vector<char>& active, ActiveBase& base,
                      SolverStats& stats);
  Vector solve_system(const SparseMatrix& m, const Vector& rhs, SolverStats& stats, FactorPtr* keep);
  Vector solve_dense(const SparseMatrix& m, const Vector& rhs, double pivot_floor, SolverStats& stats);
  Vector solve_sparse(const SparseMatrix& m, const Vector& rhs, double pivot_floor, SolverStats& stats,
                      FactorPtr* keep);
  bool solve_updated(const Factor& base, const std::vector<char>& in_base, const SparseMatrix& a,
                     const Vector& c, const std::vector<char>& active, Vector& p, SolverStats& stats) const;
  FactorPtr checkout(const SparseMatrix& m, SolverStats& stats);
  void checkin(FactorPtr factor);

  SolverSettings settings_;
  std::vector<FactorPtr> cache_;  // sparse factorizations by pattern, least recently used first
};

/// The principal submatrix A_SS of `a` for the rows `subset` (increasing).
SparseMatrix principal_submatrix(const SparseMatrix& a, std::span<const RowIndex> subset);

}  // namespace impetus::ledas
