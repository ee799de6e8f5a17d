#pragma once
/// \file
/// Exact solution of one island's system (the paper's eq. 6, A p = c) and of its complementarity
/// problem. Knows nothing of bodies or detectors: a symmetric positive semi-definite matrix A (eq. 7,
/// A = G M⁻¹ Gᵀ) and a right-hand side come in, impulses come out, so it is tested directly.
///
/// Equalities on a subset (the paper mode's rounds): the subset splits into independent blocks (rows
/// coupled through a shared movable body), each solved by the cheapest exact method:
///  - one row: closed form p = c / A_11;
///  - up to `dense_limit` rows: dense LDLᵀ with diagonal pivoting (rank-revealing for a PSD matrix);
///  - more rows: sparse LDLᵀ (Eigen SimplicialLDLT, AMD ordering; symbolic analysis cached by pattern);
///  - a rank-deficient block (a pivot ≤ rank_tolerance · max A_ii: redundant contacts, the paper's
///    Figure 2) gets the minimum-norm least-squares solution, as the paper prescribes: dense from the
///    pivoted LDLᵀ's rank factorization (checked; else the eigen-decomposition, the SVD of a symmetric
///    PSD matrix), sparse by projecting out a null-space basis found by shifted inverse iteration.
///
/// Complementarity (the complementary mode, the position correction): a proximal-point iteration whose
/// subproblems have the positive definite matrix A + εI, each solved by block principal pivoting then
/// the primal active-set method, on a masked sparse LDLᵀ (masked_ldlt.hpp) with one symbolic analysis
/// per pattern and Schur-complement updates for small changes; a larger ε while the active set is
/// searched, and each candidate free set tried on the problem itself by preconditioned conjugate
/// gradients; exact to 1e-3 · tolerance on the free rows.
///
/// Sources: equality_solver.cpp (the paper mode's subsets), complementarity.cpp (the proximal active
/// set), complementarity_fallback.cpp (minimum-norm fallback and polish), primal_step.cpp,
/// bordered_update.cpp, masked_ldlt.cpp. No minimum-norm solve inside the loop (the velocities are
/// unique, the impulses are not); a minimum-norm polish at the end where the system is small.
/// resolution/ledas/README.md derives it.

#include "impetus/settings/ledas.hpp"  // ledas::SolverSettings

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace impetus::ledas {

class EqualitySolver;
class ComplementaritySolver;

/// Column-major sparse matrix with both triangles stored (A is symmetric).
using SparseMatrix = Eigen::SparseMatrix<double>;
using Vector = Eigen::VectorXd;
/// Index of a row within an island's system.
using RowIndex = std::uint32_t;

/// What the solver did, accumulated over calls (reset by the caller).
struct SolverStats {
  std::uint64_t closed_form = 0;  ///< one-row systems
  std::uint64_t dense = 0;        ///< dense LDLᵀ factorizations
  std::uint64_t sparse = 0;       ///< sparse LDLᵀ factorizations
  std::uint64_t updated = 0;      ///< systems solved by a Schur-complement update (no refactoring)
  std::uint64_t singular = 0;     ///< rank-deficient systems (minimum-norm solution returned)
  /// Of `singular`, the systems the minimum-norm solution does not satisfy (conflicting targets, or a
  /// non-zero target with nothing movable behind it): real failures. The rest are redundant contact sets
  /// solved exactly (ResolverCounters::redundant_systems).
  std::uint64_t inconsistent = 0;
  std::uint64_t symbolic_analyses = 0;  ///< sparse symbolic analyses computed
  std::uint64_t symbolic_reused = 0;    ///< sparse factorizations that reused a cached analysis
  std::uint64_t iterations = 0;   ///< active-set iterations (one linear solve each)
  std::uint64_t released = 0;     ///< rows released because their impulse came out negative (pulling)
  std::uint64_t added = 0;        ///< rows added because they would have approached
  std::uint64_t non_converged = 0;  ///< complementarity problems that hit max_iterations or the work budget
  /// Of non_converged, the problems stopped by the work budget (work_budget(): linear solves bounded by
  /// the problem's size, whatever max_iterations allows): the best iterate is returned.
  std::uint64_t work_limited = 0;
  /// Of non_converged, the answers refused (zero returned) because their velocity changes A p exceeded
  /// 10⁶ × (‖c‖ + tolerance): rounding blown up along a null direction of conflicting targets.
  std::uint64_t refused = 0;
  /// Problems with no solution (conflicting targets, e.g. a position correction squeezing a body
  /// between fixed bodies): solved as far as the ratio test allows, counted here, not in non_converged.
  std::uint64_t infeasible = 0;
  std::uint64_t nan_caught = 0;   ///< systems whose solution was not finite (zero returned)
  std::uint64_t polished = 0;     ///< complementarity solutions replaced by the minimum-norm split
  std::uint64_t proximal = 0;     ///< proximal outer iterations after the first
  std::uint64_t refinements = 0;  ///< conjugate-gradient steps of exact solves on a candidate free set
  std::uint64_t sharpened = 0;    ///< refinements that refactored at a smaller shift (fewer steps)
  std::uint64_t interior_point_steps = 0;   ///< body-space interior-point steps (one factorization each)
  std::uint64_t interior_point_solved = 0;  ///< problems the body-space interior point solved
  /// Of those, the answers taken at a stall within 10× the stopping rule's complementarity bound
  /// (body_space.cpp, kStalledExcess) instead of falling back to the active-set search.
  std::uint64_t interior_point_loose = 0;
};

/// Adds the counts of `part` to `into`.
void add(SolverStats& into, const SolverStats& part);

/// One island's complementarity problem: find p with w = A p − c and
///   equality rows: w = 0, p free;   the other rows: p ≥ 0, w ≥ −tolerance, p·w = 0.
/// For the velocity phase p are impulses (N·s), c = target − v_n⁻ and w = v_n⁺ − target (m/s).
/// The buffers a complementarity solve works in. Eigen resizes a vector by reallocating it, so a caller
/// that solves problems of one size again and again (an island, step after step) keeps one workspace
/// per problem and hands it in (ComplementarityProblem::workspace): the solve then allocates nothing.
class BorderedUpdate;

struct ComplementarityWorkspace {
  ComplementarityWorkspace();
  ~ComplementarityWorkspace();
  ComplementarityWorkspace(ComplementarityWorkspace&&) noexcept;
  ComplementarityWorkspace& operator=(ComplementarityWorkspace&&) noexcept;

  Vector diagonal;                                  ///< A_kk
  Vector p, center, r, w, z;                        ///< the search's iterate, p̄, c + ε p̄, A z − c, subproblem solution
  Vector x;                                         ///< a refinement's iterate
  Vector residual, preconditioned, direction, product;  ///< the refinement's conjugate gradients
  Vector check;                                     ///< A p of the final check (IslandSolver)
  std::vector<char> free_rows, in_base, solved_rows;
  std::vector<Eigen::Index> unsolved_rows;
  // The minimum-norm polish: its rows, A over them (dense) and its factorization, right-hand side and
  // solution, the candidate impulses and their difference from the basic ones, and the row positions.
  std::vector<RowIndex> members;
  Eigen::MatrixXd dense;
  Eigen::LDLT<Eigen::MatrixXd> ldlt;
  Vector gathered, solution, candidate, difference, change;
  std::vector<int> position;
  std::unique_ptr<BorderedUpdate> update;           ///< the active-set loop's bordered update (private type)
};

/// A factored form of A = G M⁻¹ Gᵀ (eq. 7) in blocks of six coordinates (a movable body's linear, then
/// angular velocity): row k's v_n = G_k v touches the blocks of its two sides; M is block diagonal,
/// diag(m I₃, J) per block.
struct BodySpace {
  std::vector<std::array<std::int32_t, 2>> blocks;  ///< per row: the blocks of sides a and b (−1: none)
  std::vector<std::array<double, 12>> jacobian;     ///< per row: G on side a's six coordinates, then b's
  std::vector<double> mass;                         ///< per block: m (kg)
  std::vector<Eigen::Matrix3d> inertia;             ///< per block: J (kg·m², world frame)
};

struct ComplementarityProblem {
  const SparseMatrix* matrix = nullptr;  ///< A (m × m), symmetric PSD, both triangles stored
  Vector rhs;                            ///< c (m)
  std::vector<char> equality;            ///< per row: an equality row (constraint), never released
  std::vector<char> start;               ///< per row: in the first active set (approaching or touching)
  double tolerance = 1e-9;               ///< w below −tolerance is a violation (units of w)
  ComplementarityWorkspace* workspace = nullptr;  ///< buffers to solve in (null: the solver's own)
  /// A's factored form, optional: with it a large problem with more rows than body coordinates is
  /// solved by an interior point in body space first (SolverSettings::interior_point_rows).
  const BodySpace* body_space = nullptr;
  /// Per row, optional: the slots of its movable bodies (−1: fixed), whose sharing makes A's pattern;
  /// the factorization's ordering reads them instead of A (MaskedLdlt::analyze).
  std::vector<std::array<std::int32_t, 2>> groups = {};
  /// Analyse every row at once rather than the start set's (MaskedLdlt::analyze): for a problem whose
  /// free set usually grows to most rows (the position correction), one ordering instead of two.
  bool analyse_every_row = false;
};

/// Solves island systems exactly: two solvers behind one interface, the equality solver of the paper
/// mode (equality_solver.hpp) and the complementarity solver (complementarity_solver.hpp), which uses
/// the first for its fallback. Holds their caches of symbolic analyses, so one instance per resolver;
/// not thread-safe.
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
  /// The same into `p` (size a.rows()): writes the subset's entries only, allocates nothing for the
  /// one- and few-row blocks the paper's rounds are made of.
  void solve_subset(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset, Vector& p,
                    SolverStats& stats);

  /// Solves the complementarity problem (complementarity.cpp, resolution/ledas/README.md): proximal-point
  /// outer iterations on ½ pᵀ(A + εI) p − (c + ε p̄)ᵀp, ε = regularization · max A_kk for the first solve and
  /// search_regularization · max A_kk while the active set is searched, each subproblem by block
  /// principal pivoting while the number of infeasible rows falls, then the primal active-set method
  /// (monotone: it terminates), started from the given set; each solved subproblem's free set F is tried
  /// on the problem itself (A_FF p = c_F by preconditioned conjugate gradients). Returns p with p ≥ 0 on inequality rows, w ≥ −tolerance
  /// and |w| ≤ 1e-3 · tolerance on the rows with p ≠ 0; the minimum-norm split where the final system has
  /// at most polish_limit rows and that split is ≥ 0. Conflicting targets (no exact solution): the
  /// minimum-norm least-squares active set (complementarity_fallback.cpp).
  Vector solve_complementarity(const ComplementarityProblem& problem, SolverStats& stats);
  /// The same into `p` (its storage reused: with the problem's workspace, nothing is allocated when the
  /// sizes are those of the last call).
  void solve_complementarity(const ComplementarityProblem& problem, SolverStats& stats, Vector& p);

  const SolverSettings& settings() const { return settings_; }

 private:
  // solve_complementarity without the final check: diagonally scaled where A_kk spans too much.
  void solve_balanced(const ComplementarityProblem& problem, SolverStats& stats, Vector& p);
  SolverSettings settings_;
  std::unique_ptr<EqualitySolver> equalities_;               // solve_subset (equality_solver.cpp)
  Vector check_;  // solve_complementarity's A p without a workspace
  std::unique_ptr<ComplementaritySolver> complementarity_;  // solve_complementarity (complementarity.cpp)
};

/// The work budget of one complementarity problem of `rows` rows: at most this many active-set
/// iterations (one linear solve each) in the search and as many in the minimum-norm fallback, and never
/// more than `max_iterations`. A finite active-set method changes each row's state a few times; a problem
/// still running after kSolvesPerRow solves per row is cycling on rounding (a 10¹²:1 mass ratio), and
/// a million more solves would not finish it.
std::uint64_t work_budget(std::size_t rows, const SolverSettings& settings);

/// The principal submatrix A_SS of `a` for the rows `subset` (increasing).
SparseMatrix principal_submatrix(const SparseMatrix& a, std::span<const RowIndex> subset);
/// The same into `out`, its storage reused; `position` is scratch.
void principal_submatrix(const SparseMatrix& a, std::span<const RowIndex> subset, SparseMatrix& out,
                         std::vector<int>& position);

}  // namespace impetus::ledas
