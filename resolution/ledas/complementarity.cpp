// Complementarity problems (the complementary mode's impact, the position correction): the proximal
// active set on the masked factorization, with Schur-complement updates and an exact refinement of
// each candidate free set. README.md, "Complementary mode and position correction", derives it.
#include "complementarity_solver.hpp"
#include "impetus/resolution/ledas/masked_ldlt.hpp"
#include "primal_step.hpp"
#include "solver_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus::ledas {

namespace {
// Primal additions: rows approaching at least this share of the fastest approach join at once.
constexpr double kJoinShare = 0.5;
// After a free set that is not the answer, the search shift falls by this factor (to the final one).
constexpr double kShiftReduction = 1e-3;
// Conjugate-gradient steps of one refinement at most (a few suffice: the preconditioner is the
// factorization of (A + εI)_FF).
constexpr int kMaxRefinementSteps = 100;
// The refinement's choice of preconditioner (refine_on_free_set): after kProbeSteps steps it predicts
// the steps still needed from their mean reduction of the residual; when those would cost more than a
// factorization at a smaller shift plus kStepsAfterSharpening steps, it refactors and restarts. A
// factorization's multiply-adds are weighed kFactorizationWeight times a solve's (scattered updates and
// short columns against streaming ones).
constexpr int kProbeSteps = 2;
constexpr double kStepsAfterSharpening = 3.0;
constexpr double kFactorizationWeight = 4.0;
// Masked factorizations kept for reuse of their symbolic analysis (distinct sparsity patterns).
constexpr std::size_t kCacheCapacity = 16;
}  // namespace

ComplementarityWorkspace::ComplementarityWorkspace() = default;
ComplementarityWorkspace::~ComplementarityWorkspace() = default;
ComplementarityWorkspace::ComplementarityWorkspace(ComplementarityWorkspace&&) noexcept = default;
ComplementarityWorkspace& ComplementarityWorkspace::operator=(ComplementarityWorkspace&&) noexcept = default;

ComplementaritySolver::ComplementaritySolver(const SolverSettings& settings, EqualitySolver& equalities)
    : settings_(settings), equalities_(equalities) {}
ComplementaritySolver::~ComplementaritySolver() = default;

std::unique_ptr<MaskedLdlt> ComplementaritySolver::checkout_masked(const SparseMatrix& m, std::span<const char> likely,
                                                                   std::span<const std::array<std::int32_t, 2>> groups,
                                                                   SolverStats& stats) {
  for (auto it = masked_cache_.begin(); it != masked_cache_.end(); ++it) {
    if ((*it)->same_pattern(m)) {
      std::unique_ptr<MaskedLdlt> f = std::move(*it);
      masked_cache_.erase(it);
      ++stats.symbolic_reused;
      return f;
    }
  }
  // A new pattern. With the cache full, its least recently used factorization is analysed again in
  // place: its buffers (L's pattern and values: megabytes for a large island) were sized and touched
  // before, so a scene whose pattern changes every step does not allocate and page in fresh ones.
  std::unique_ptr<MaskedLdlt> f;
  if (masked_cache_.size() >= kCacheCapacity) {
    f = std::move(masked_cache_.front());
    masked_cache_.erase(masked_cache_.begin());
  } else {
    f = std::make_unique<MaskedLdlt>();
  }
  f->analyze(m, likely, groups);
  ++stats.symbolic_analyses;
  return f;
}

void ComplementaritySolver::checkin_masked(std::unique_ptr<MaskedLdlt> factor) {
  masked_cache_.push_back(std::move(factor));  // most recently used last
  if (masked_cache_.size() > kCacheCapacity) masked_cache_.erase(masked_cache_.begin());
}

// Factorizes (A + εI)_FF for the free rows F into the loop. The symbolic analysis covers the rows the
// search was expected to need (its start set, MaskedLdlt::analyze); a free set beyond them is analysed
// again first, with every row (so at most one analysis more). Analysing the start set and the rows F
// adds, then every row (as until 2026-12-05), cost a large dynamic island three orderings per problem
// where two do: the 10,000-sphere heap's island of ~2,850 rows widened twice in each step.
void ComplementaritySolver::factorize_loop(ActiveLoop& loop, const SparseMatrix& a, const std::vector<char>& rows, double shift,
                                  SolverStats& stats) {
  if (!loop.factor->covers(rows)) {
    loop.factor->analyze(a, {}, loop.groups);
    ++stats.symbolic_analyses;
  }
  ++stats.sparse;
  loop.factor->factorize(a, rows, settings_.rank_tolerance, loop.floor, shift);
  loop.factored = true;
  loop.update->forget();
  for (std::size_t k = 0; k < rows.size(); ++k) loop.in_base[k] = rows[k] && !loop.factor->dropped(k);
}

// Solves (A + εI)_FF z = r_F for the free rows F: by the current factorization when F is the one it
// holds, by an update when only a few rows changed, else by a new masked factorization (same symbolic
// analysis). A + εI is positive definite, so every free set has exactly one solution.
void ComplementaritySolver::solve_active(const SparseMatrix& a, double shift, const Vector& r,
                                         const std::vector<char>& active, ActiveLoop& loop, SolverStats& stats,
                                         Vector& z) {
  if (loop.factored) {
    std::size_t changes = 0;
    for (std::size_t k = 0; k < active.size(); ++k) changes += (active[k] != 0) != (loop.in_base[k] != 0);
    if (changes == 0) {
      z = r;
      loop.factor->solve(z);
      return;
    }
    const std::size_t limit = settings_.update_limit > 0
                                  ? settings_.update_limit
                                  : std::max<std::size_t>(8, static_cast<std::size_t>(std::sqrt(static_cast<double>(active.size()))));
    if (changes <= limit && loop.update->solve(*loop.factor, loop.in_base, a, shift, r, active, settings_.rank_tolerance, z)) {
      ++stats.updated;
      return;
    }
  }
  factorize_loop(loop, a, active, shift, stats);
  loop.singular = loop.singular || loop.factor->redundant_rows(shift) > 0;
  z = r;
  loop.factor->solve(z);
}

// The state of one proximal active-set search (solve()): the free set F, the iterate p, the proximal
// center p̄ and shift ε, and where the search stands.
struct ComplementaritySolver::Search {
  enum class Outcome { running, converged, not_finite, stalled };

  // The vectors and the free set are the workspace's (`free_rows` filled by the caller); the loop borrows
  // its base set's storage from it until the search ends.
  Search(const ComplementarityProblem& problem_in, const SolverSettings& settings, double scale_in, Workspace& work)
      : problem(problem_in), scale(scale_in), final_shift(settings.regularization * scale_in),
        search_shift(std::max(final_shift, settings.search_regularization * scale_in)), shift(final_shift),
        workspace(work), free_rows(work.free_rows), p(work.p), center(work.center), r(work.r), w(work.w), z(work.z),
        fewest_infeasible(free_rows.size() + 1) {
    const Eigen::Index m = problem_in.matrix->rows();
    p.setZero(m);
    center.setZero(m);
    r = problem_in.rhs;
    w.resize(m);
    loop.floor = settings.rank_tolerance * scale;
    loop.in_base.swap(work.in_base);
    loop.in_base.assign(free_rows.size(), 0);
    if (!work.update) work.update = std::make_unique<BorderedUpdate>();
    loop.update = work.update.get();
    loop.update->forget();  // a new loop: nothing factorized yet
  }
  ~Search() { loop.in_base.swap(workspace.in_base); }
  Search(const Search&) = delete;
  Search& operator=(const Search&) = delete;
  bool done() const { return outcome != Outcome::running; }
  // A free inequality row whose subproblem impulse z_k is negative (below rounding).
  bool negative(std::size_t k, double roundoff) const {
    return free_rows[k] && !problem.equality[k] && z(static_cast<Eigen::Index>(k)) < -roundoff;
  }
  // The subproblem's gradient w_k − ε p̄_k on a row at zero.
  double gradient(std::size_t k) const {
    return w(static_cast<Eigen::Index>(k)) - shift * center(static_cast<Eigen::Index>(k));
  }
  // A row at zero that would approach (its gradient below −tolerance).
  bool approaching(std::size_t k) const { return !free_rows[k] && gradient(k) < -problem.tolerance; }
  // Block principal pivoting (Júdice & Pires): exchange every infeasible row at once.
  void exchange(double roundoff, SolverStats& stats) {
    for (std::size_t k = 0; k < free_rows.size(); ++k) {
      if (negative(k, roundoff)) free_rows[k] = 0, ++stats.released;
      else if (approaching(k)) free_rows[k] = 1, ++stats.added;
    }
  }
  // Primal step at a feasible z: the rows at zero that approach at least kJoinShare as fast as the
  // fastest join F (all of them at once over-fills a redundant set and releases most again).
  void join_fastest(SolverStats& stats) {
    double worst = 0.0;
    for (std::size_t k = 0; k < free_rows.size(); ++k)
      if (approaching(k)) worst = std::min(worst, gradient(k));
    for (std::size_t k = 0; k < free_rows.size(); ++k)
      if (approaching(k) && gradient(k) <= kJoinShare * worst) free_rows[k] = 1, ++stats.added;
  }

  const ComplementarityProblem& problem;
  const double scale;         // max A_kk
  const double final_shift;   // ε of the first and the last solve (regularization · scale)
  const double search_shift;  // ε while the active set is searched (search_regularization · scale)
  double shift;               // the current ε
  ActiveLoop loop;
  Workspace& workspace;
  std::vector<char>& free_rows;      // F
  Vector &p, &center, &r, &w, &z;    // iterate, p̄, c + ε p̄, A z − c, the subproblem's solution on F
  Outcome outcome = Outcome::running;
  double last_change = std::numeric_limits<double>::infinity();  // ε |p − p̄| of the last outer iteration
  int slow = 0;                      // outer iterations in a row that shrank it by less than 10 %
  std::size_t fewest_infeasible;     // block pivoting goes on while the infeasible rows fall below this
  bool pivoting = true;              // block principal pivoting while it helps, then the primal method
};

// The complementarity problem is the optimality condition of the convex QP
//   minimize ½ pᵀA p − cᵀp  subject to p_k ≥ 0 on inequality rows   (gradient A p − c = w),
// the exact inelastic impact of the paper's eqs. 6–8 with p ≥ 0 (README.md, "Complementary mode").
// A is only positive semi-definite (redundant contacts: the paper's Figure 2, a pyramid's horizontal
// contacts), so it is solved by a proximal-point iteration: each outer iteration solves the strictly
// convex problem
//   minimize ½ pᵀ(A + εI) p − (c + ε p̄)ᵀp,  p ≥ 0,   p̄ = the previous outer solution.
// Its free rows F are solved as equalities by one exact solve ((A + εI)_FF is positive definite: no
// rank test, no null space). Its active set: block principal pivoting (Júdice & Pires: every infeasible
// row exchanged at once — free rows with a negative impulse leave F, rows at zero that would approach
// join it) while the number of infeasible rows falls; then the primal active-set method from p = 0, or
// in a later outer iteration from the last subproblem's solution p̄ (an
// infeasible minimizer is approached until the first free row reaches zero, the rows at zero are
// released; a feasible one becomes p and the rows approaching fastest join), whose objective strictly
// decreases between feasible minimizers, so it terminates.
//
// Two shifts. The first solve uses the final ε = regularization · max A_kk: when the start set is the
// answer (a line of spheres, a box on its face) that one solve is exact. Otherwise the search goes on
// with ε = search_regularization · max A_kk: with the tiny shift the subproblem is as ill-conditioned
// as A itself and block pivoting stalls on redundant rows, stepping one row at a time; with the larger
// one it settles in a few exchanges. Each
// solved subproblem's free set is then tried on the problem itself (refine_on_free_set: conjugate
// gradients on A_FF p = c_F preconditioned by the factorization in hand); if that is not the answer, ε
// falls by kShiftReduction towards the final one and the proximal iteration goes on from p.
//
// Without the exact jump, on F w = A p − c = −ε (p − p̄), which shrinks by a factor ε/(λ + ε) per
// outer iteration for every non-zero eigenvalue λ of A_FF; the iteration stops when
// ε |p − p̄| ≤ 1e-3 · tolerance (or rounding): p ≥ 0, w ≥ −tolerance everywhere, |w| ≤ 1e-3 tolerance on
// F. Started from p̄ = 0, the impulses' component in the null space of A (a self-equilibrated split
// among redundant contacts, which moves nothing) stays near zero, i.e. near the minimum-norm split. If
// the outer residual stops shrinking short of the tolerance (conflicting targets: no exact solution),
// solve_min_norm (the fallback) takes over.
void ComplementaritySolver::solve(const ComplementarityProblem& problem, SolverStats& stats, Vector& p) {
  work_ = problem.workspace ? problem.workspace : &own_;
  const SparseMatrix& a = *problem.matrix;
  const auto m = static_cast<std::size_t>(a.rows());
  std::vector<char>& free_rows = work_->free_rows;
  free_rows.resize(m);
  for (std::size_t k = 0; k < m; ++k) free_rows[k] = problem.equality[k] || problem.start[k];
  p.setZero(a.rows());
  if (m == 0) return;
  work_->diagonal = a.diagonal();
  const double scale = work_->diagonal.maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) {  // nothing movable behind any row
    ++stats.singular;
    if (!std::isfinite(scale) || problem.rhs.lpNorm<Eigen::Infinity>() > 0.0) ++stats.inconsistent;
    return;
  }
  if (m == 1) {  // closed form: p = c / A_11, clamped at 0 for a contact (identical to the paper mode's)
    const double a11 = a.coeff(0, 0);
    ++stats.iterations;
    ++stats.closed_form;
    p(0) = a11 > settings_.rank_tolerance * scale ? problem.rhs(0) / a11 : 0.0;
    if (!problem.equality[0] && !(p(0) > 0.0)) {
      if (p(0) < 0.0) ++stats.released;
      p(0) = 0.0;
    }
    return;
  }
  if (suits_body_space(problem, settings_) &&
      solve_in_body_space(problem, settings_.interior_point_stall_excess, body_space_, stats, p))
    return;
  Search search(problem, settings_, scale, *work_);
  search.loop.groups = problem.groups;
  search.loop.factor =
      checkout_masked(a, problem.analyse_every_row ? std::span<const char>() : std::span<const char>(search.free_rows),
                      problem.groups, stats);
  const std::uint64_t budget = work_budget(m, settings_);
  for (std::uint64_t iteration = 0; iteration < budget && !search.done(); ++iteration)
    iterate(search, iteration, stats);
  if (!search.done() && budget < settings_.max_iterations) ++stats.work_limited;
  checkin_masked(std::move(search.loop.factor));
  // Redundant rows met in the search: solved (a redundant contact set) when the search converged; when
  // it stalled the minimum-norm fallback below counts its own systems; hitting the cap is a failure.
  if (search.loop.singular) {
    ++stats.singular;
    if (search.outcome != Search::Outcome::converged && search.outcome != Search::Outcome::stalled) ++stats.inconsistent;
  }
  if (search.outcome == Search::Outcome::stalled) {
    p = solve_min_norm(problem, stats);
    return;
  }
  if (search.outcome == Search::Outcome::running) ++stats.non_converged;
  if (search.outcome != Search::Outcome::converged)  // the last iterate may be infeasible
    clamp_to_free_set(search.p, search.free_rows, problem.equality);
  else
    polish_minimum_norm(a, problem.rhs, search.free_rows, problem, search.p, stats);
  p.swap(search.p);  // the caller's old storage becomes the workspace's
}

// One iteration of the search: solve the subproblem on F, then change F (block pivoting, or a primal
// step), or, once the subproblem is solved, try its free set and take the next proximal step.
void ComplementaritySolver::iterate(Search& s, std::uint64_t iteration, SolverStats& stats) {
  const SparseMatrix& a = *s.problem.matrix;
  ++stats.iterations;
  solve_active(a, s.shift, s.r, s.free_rows, s.loop, stats, s.z);
  if (!s.z.allFinite()) {
    ++stats.nan_caught;
    s.p.setZero();
    s.outcome = Search::Outcome::not_finite;
    return;
  }
  // w = A z − c; the subproblem's gradient is w + ε (z − p̄), = w − ε p̄ on rows at zero.
  s.w.noalias() = a * s.z;
  s.w -= s.problem.rhs;
  const double roundoff = kImpulseRoundoff * s.z.lpNorm<Eigen::Infinity>();
  std::size_t negatives = 0, approaches = 0;
  for (std::size_t k = 0; k < s.free_rows.size(); ++k) negatives += s.negative(k, roundoff), approaches += s.approaching(k);
  if (iteration == 0 && negatives + approaches > 0 && s.shift < s.search_shift) {
    // The start set is not the answer: search the active set on the better-conditioned subproblem.
    // p̄ = 0 still, so only the matrix changes (the factorization is redone at the new shift).
    s.shift = s.search_shift;
    s.loop.factored = false;
  }
  if (s.pivoting && negatives + approaches > 0 && negatives + approaches < s.fewest_infeasible) {
    s.fewest_infeasible = negatives + approaches;
    s.exchange(roundoff, stats);
    return;
  }
  if (s.pivoting && negatives + approaches > 0) {  // pivoting stopped helping: the primal method
    s.pivoting = false;
    if (s.center.any()) {
      // From p̄, the last subproblem's solution (p̄ ≥ 0: feasible), with its support free: most of its
      // rows stay free, where from p = 0 the method would join them again a few at a time.
      s.p = s.center;
      for (std::size_t k = 0; k < s.free_rows.size(); ++k)
        s.free_rows[k] = s.problem.equality[k] || s.p(static_cast<Eigen::Index>(k)) > 0.0;
      return;
    }
    s.p.setZero();
  }
  if (negatives > 0) {
    // Primal step: towards z until the first free row reaches zero; release the rows at zero.
    Vector& direction = s.workspace.direction;  // free here: the refinement's, between refinements
    direction = s.z - s.p;
    const RatioTest test = ratio_test(s.p, direction, s.free_rows, s.problem.equality, 1.0);
    step_and_release(s.p, direction, test, s.z, roundoff, s.free_rows, s.problem.equality, stats);
    return;
  }
  s.p = s.z;
  if (approaches > 0) {
    s.join_fastest(stats);
    return;
  }
  clamp_to_free_set(s.p, s.free_rows, s.problem.equality);
  settle(s, stats);
}

// The proximal subproblem is solved. Is its free set the answer? Solve the problem itself on it; if not,
// a smaller shift (a proximal step nearer the answer), and the convergence tests of the outer iteration.
void ComplementaritySolver::settle(Search& s, SolverStats& stats) {
  const ComplementarityProblem& problem = s.problem;
  const Vector& c = problem.rhs;
  {
    Vector& x = s.workspace.x;
    x = s.p;
    if (refine_on_free_set(*problem.matrix, c, s.shift, s.free_rows, s.loop, problem, x, stats) ==
        Refinement::exact) {
      s.p.swap(x);
      s.outcome = Search::Outcome::converged;
      return;
    }
    if (s.shift > s.final_shift) {
      s.shift = std::max(s.final_shift, kShiftReduction * s.shift);
      s.loop.factored = false;
      s.last_change = std::numeric_limits<double>::infinity();
      s.slow = 0;
    }
  }
  const double change = s.shift * (s.p - s.center).lpNorm<Eigen::Infinity>();
  bool violated = false;
  for (std::size_t k = 0; k < s.free_rows.size(); ++k)
    if (!s.free_rows[k] && s.w(static_cast<Eigen::Index>(k)) < -problem.tolerance) violated = true;
  // Rounding bounds how small w can get: a few ulps of the terms of A p − c.
  const double rounding = 1e-14 * (s.scale * s.p.lpNorm<Eigen::Infinity>() + c.lpNorm<Eigen::Infinity>());
  if (!violated && change <= std::max(1e-3 * problem.tolerance, rounding)) {
    s.outcome = Search::Outcome::converged;
    return;
  }
  s.slow = change > 0.9 * s.last_change ? s.slow + 1 : 0;
  if (s.slow >= 3) {  // no longer shrinking: exact to the tolerance, or conflicting targets
    s.outcome = !violated && change <= problem.tolerance ? Search::Outcome::converged : Search::Outcome::stalled;
    return;
  }
  s.last_change = change;
  s.center = s.p;
  s.r = c + s.shift * s.center;
  s.fewest_infeasible = s.free_rows.size() + 1;
  s.pivoting = true;
  ++stats.proximal;
}

// The free set F of a solved proximal subproblem is the answer if A_FF p_F = c_F (eq. 6 on F, no shift)
// has a solution p_F ≥ 0 that leaves no row outside F approaching (eq. 8: c = target − v⁻). That solution
// is found by conjugate gradients preconditioned with the factorization of (A + εI)_FF the loop already
// holds, started from the subproblem's p: the preconditioned matrix has the eigenvalues λ/(λ + ε) ∈ (0, 1]
// of A_FF, so it converges in a few steps where the proximal iteration p ← p + (A + εI)_FF⁻¹(c − A p)_F
// (iterated Tikhonov, the same preconditioner as a fixed-point step) takes many. A_FF may be singular
// (redundant rows in F); c_F is then in its range (contacts: c = −G v⁻), the iterates stay in the
// range, and the result is the solution nearest to the start. Stops at |A_FF p_F − c_F| ≤ 1e-3 ·
// tolerance (or rounding), as the proximal iteration does.
// The conjugate-gradient recurrence is kept in one function (about 60 lines): split, its state (x, the
// residual, the direction, rz) would have to travel between the pieces.
ComplementaritySolver::Refinement ComplementaritySolver::refine_on_free_set(const SparseMatrix& a, const Vector& c, double shift,
                                                          const std::vector<char>& free_rows, ActiveLoop& loop,
                                                          const ComplementarityProblem& problem, Vector& x,
                                                          SolverStats& stats) {
  const auto m = free_rows.size();
  bool by_update = prepare_preconditioner(a, shift, free_rows, loop, stats);
  mark_solved_rows(free_rows, loop);
  Vector& residual = work_->residual;
  Vector& preconditioned = work_->preconditioned;
  Vector& direction = work_->direction;
  Vector& product = work_->product;
  restrict_to_solved(x);
  residual.noalias() = a * x;
  residual = c - residual;  // c + (−A x), bit for bit
  restrict_to_solved(residual);
  precondition(loop, by_update, residual, preconditioned);
  direction = preconditioned;
  double rz = residual.dot(preconditioned);
  const double scale = work_->diagonal.maxCoeff();
  const double final_shift = settings_.regularization * scale;
  // Multiply-adds of one step: a solve (forward and backward over L), a product with A, vector updates.
  const double step_cost = 2.0 * static_cast<double>(loop.factor->capacity()) + static_cast<double>(a.nonZeros()) +
                           10.0 * static_cast<double>(m);
  double first_residual = 0.0;
  const double size_c = c.lpNorm<Eigen::Infinity>();
  bool solved = false;
  for (int step = 0; step <= kMaxRefinementSteps; ++step) {  // preconditioned conjugate gradients
    const double rounding = 1e-14 * (scale * x.lpNorm<Eigen::Infinity>() + size_c);
    const double goal = std::max(1e-3 * problem.tolerance, rounding);
    const double size = residual.lpNorm<Eigen::Infinity>();
    if (size <= goal) {
      solved = true;
      break;
    }
    if (step == kMaxRefinementSteps) break;
    if (step == 0) first_residual = size;
    if (settings_.sharpen_refinement && step == kProbeSteps && shift > final_shift &&
        sharpening_pays(size / first_residual, goal / size, step_cost, loop)) {
      // Refactor at a smaller shift and restart from x.
      shift = std::max(final_shift, kShiftReduction * shift);
      factorize_loop(loop, a, free_rows, shift, stats);
      loop.factored = false;  // at a shift the active-set loop is not using: refactor when it goes on
      by_update = false;
      ++stats.sharpened;
      precondition(loop, by_update, residual, preconditioned);
      direction = preconditioned;
      rz = residual.dot(preconditioned);
    }
    ++stats.refinements;
    product.noalias() = a * direction;
    restrict_to_solved(product);
    const double curvature = direction.dot(product);
    if (!(curvature > 0.0)) break;
    const double alpha = rz / curvature;
    x += alpha * direction;
    residual -= alpha * product;
    precondition(loop, by_update, residual, preconditioned);
    const double rz_next = residual.dot(preconditioned);
    direction = preconditioned + (rz_next / rz) * direction;
    rz = rz_next;
  }
  if (!solved) return Refinement::not_converged;
  return accept_refined(a, c, problem, x);
}

// The refinement's preconditioner (A + εI)_FF⁻¹: the factorization if it is of F, else the last update
// if that solves for F (returns true), else a new factorization.
bool ComplementaritySolver::prepare_preconditioner(const SparseMatrix& a, double shift, const std::vector<char>& free_rows,
                                                   ActiveLoop& loop, SolverStats& stats) {
  bool holds = loop.factored;
  for (std::size_t k = 0; holds && k < free_rows.size(); ++k)
    holds = free_rows[k] ? (loop.in_base[k] || loop.factor->dropped(k)) : !loop.in_base[k];
  const bool by_update = !holds && loop.factored && loop.update->solves_for(free_rows);
  if (!holds && !by_update) factorize_loop(loop, a, free_rows, shift, stats);
  return by_update;
}

// out = (A + εI)_FF⁻¹ v by the update or the factorization.
void ComplementaritySolver::precondition(ActiveLoop& loop, bool by_update, const Vector& v, Vector& out) {
  if (by_update) {
    loop.update->apply(*loop.factor, v, out);
  } else {
    out = v;
    loop.factor->solve(out);
  }
}

// The rows solved for: F without the rows nothing movable is behind (left at p = 0, as the
// factorization leaves them); the others listed, to be zeroed by index (no branch per row).
void ComplementaritySolver::mark_solved_rows(const std::vector<char>& free_rows, const ActiveLoop& loop) {
  const std::size_t m = free_rows.size();
  std::vector<char>& solved_rows = work_->solved_rows;
  solved_rows.resize(m);
  for (std::size_t k = 0; k < m; ++k)
    solved_rows[k] = free_rows[k] && work_->diagonal(static_cast<Eigen::Index>(k)) > loop.floor;
  std::vector<Eigen::Index>& unsolved = work_->unsolved_rows;
  unsolved.clear();
  for (std::size_t k = 0; k < m; ++k)
    if (!solved_rows[k]) unsolved.push_back(static_cast<Eigen::Index>(k));
}

void ComplementaritySolver::restrict_to_solved(Vector& v) const {
  for (const Eigen::Index k : work_->unsolved_rows) v(k) = 0.0;
}

// The preconditioned matrix has the eigenvalues λ/(λ + ε): many eigenvalues of A_FF below ε (a large,
// soft network) make many steps. After kProbeSteps steps that reduced the residual by `reduction` in
// all, predicts the steps still needed to reduce it by `remaining`; whether a factorization at a
// smaller shift plus kStepsAfterSharpening steps costs less.
bool ComplementaritySolver::sharpening_pays(double reduction, double remaining, double step_cost,
                                            const ActiveLoop& loop) const {
  const double rate = std::pow(reduction, 1.0 / kProbeSteps);
  const double steps = rate < 1.0 ? std::log(remaining) / std::log(rate) : kMaxRefinementSteps;
  return steps * step_cost > kFactorizationWeight * loop.factor->factorization_work() + kStepsAfterSharpening * step_cost;
}

// A converged refinement is the answer if p ≥ 0 on the rows solved for and no other row approaches;
// then the impulses are clamped at zero (rounding) on the inequality rows.
ComplementaritySolver::Refinement ComplementaritySolver::accept_refined(const SparseMatrix& a, const Vector& c,
                                                                        const ComplementarityProblem& problem,
                                                                        Vector& x) {
  const std::size_t m = work_->solved_rows.size();
  Vector& product = work_->product;
  product.noalias() = a * x;
  product -= c;  // w
  const double roundoff = kImpulseRoundoff * x.lpNorm<Eigen::Infinity>();
  for (std::size_t k = 0; k < m; ++k) {
    if (problem.equality[k]) continue;
    const auto i = static_cast<Eigen::Index>(k);
    if (work_->solved_rows[k] ? x(i) < -roundoff : product(i) < -problem.tolerance) return Refinement::infeasible;
  }
  for (std::size_t k = 0; k < m; ++k)
    if (!problem.equality[k]) x(static_cast<Eigen::Index>(k)) = std::max(0.0, x(static_cast<Eigen::Index>(k)));
  return Refinement::exact;
}

}  // namespace impetus::ledas
