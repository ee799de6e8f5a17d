#pragma once
/// \file
/// The complementarity solves of island_solver.hpp (private): the proximal active set on a masked
/// factorization (complementarity.cpp), its exact refinement of a candidate free set, and the two
/// minimum-norm pieces around it (complementarity_fallback.cpp).

#include "body_space.hpp"
#include "equality_solver.hpp"
#include "impetus/resolution/ledas/island_solver.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace impetus::ledas {

class MaskedLdlt;

/// Solves complementarity problems (IslandSolver::solve_complementarity). Holds the cache of masked
/// factorizations by pattern; uses `equalities` for the fallback's and the polish's exact solves.
class ComplementaritySolver {
 public:
  ComplementaritySolver(const SolverSettings& settings, EqualitySolver& equalities);
  ~ComplementaritySolver();
  ComplementaritySolver(const ComplementaritySolver&) = delete;
  ComplementaritySolver& operator=(const ComplementaritySolver&) = delete;

  /// IslandSolver::solve_complementarity, into p.
  void solve(const ComplementarityProblem& problem, SolverStats& stats, Vector& p);

 private:
  struct ActiveLoop;  // one active-set loop's factorization and update (solver_internal.hpp)
  struct Search;      // one proximal active-set search's state (complementarity.cpp)
  enum class Refinement { exact, infeasible, not_converged };

  void iterate(Search& search, std::uint64_t iteration, SolverStats& stats);
  void settle(Search& search, SolverStats& stats);
  void factorize_loop(ActiveLoop& loop, const SparseMatrix& a, const std::vector<char>& rows, double shift,
                      SolverStats& stats);
  void solve_active(const SparseMatrix& a, double shift, const Vector& r, const std::vector<char>& active,
                    ActiveLoop& loop, SolverStats& stats, Vector& z);
  Refinement refine_on_free_set(const SparseMatrix& a, const Vector& c, double shift, const std::vector<char>& free_rows,
                                ActiveLoop& loop, const ComplementarityProblem& problem, Vector& x, SolverStats& stats);
  bool prepare_preconditioner(const SparseMatrix& a, double shift, const std::vector<char>& free_rows, ActiveLoop& loop,
                              SolverStats& stats);
  static void precondition(ActiveLoop& loop, bool by_update, const Vector& v, Vector& out);
  void mark_solved_rows(const std::vector<char>& free_rows, const ActiveLoop& loop);
  void restrict_to_solved(Vector& v) const;
  bool sharpening_pays(double reduction, double remaining, double step_cost, const ActiveLoop& loop) const;
  Refinement accept_refined(const SparseMatrix& a, const Vector& c, const ComplementarityProblem& problem, Vector& x);
  Vector solve_min_norm(const ComplementarityProblem& problem, SolverStats& stats);
  void polish_minimum_norm(const SparseMatrix& a, const Vector& c, std::vector<char>& rows,
                           const ComplementarityProblem& problem, Vector& p, SolverStats& stats);
  /// A masked factorization of m's pattern: the cached one if there is one (analysed for the rows of an
  /// earlier start set: factorize_loop widens it when a free set needs more), else a new analysis for
  /// the rows `likely` to be free (the start set; MaskedLdlt::analyze).
  std::unique_ptr<MaskedLdlt> checkout_masked(const SparseMatrix& m, std::span<const char> likely,
                                              std::span<const std::array<std::int32_t, 2>> groups, SolverStats& stats);
  void checkin_masked(std::unique_ptr<MaskedLdlt> factor);

  using Workspace = ComplementarityWorkspace;
  const SolverSettings& settings_;
  EqualitySolver& equalities_;
  std::vector<std::unique_ptr<MaskedLdlt>> masked_cache_;  // by pattern, least recently used first
  BodySpaceWorkspace body_space_;  // the interior point's buffers
  Workspace own_;               // the buffers of a problem that brings none
  Workspace* work_ = &own_;     // the current solve's: the problem's workspace, or own_
};

}  // namespace impetus::ledas
