// Complementarity problems (the complementary mode's impact, the position correction): the proximal
// active set on the masked factorization, with Schur-complement updates and an exact refinement of
// each candidate free set. README.md, "Complementary mode and position correction", derives it.
#include "ledas/island_solver.hpp"
#include "ledas/masked_ldlt.hpp"
#include "ledas/solver_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus::ledas {

namespace {
// Primal additions: rows approaching at least this share of the fastest approach join at once.
constexpr double kJoinShare = 0.5;
// After a free set that is not the answer, the search shift falls by this factor (to the final one).
constexpr double kShiftReduction = 1e-3;
// Conjugate-gradient steps of one refinement (pyramid K = 100: 6 in all, 19 without the sharper
// preconditioner below; a chain: 1).
constexpr int kMaxRefinementSteps = 100;
// The refinement's choice of preconditioner (refine_on_free_set): after kProbeSteps steps it predicts
// the steps still needed from their mean reduction of the residual; when those would cost more than a
// factorization at a smaller shift plus kStepsAfterSharpening steps, it refactors and restarts. A
// factorization's multiply-adds are weighed kFactorizationWeight times a solve's (scattered updates and
// short columns against streaming ones: measured 1–2 ns against 0.35–0.4 ns on the pyramids).
constexpr int kProbeSteps = 2;
constexpr double kStepsAfterSharpening = 3.0;
constexpr double kFactorizationWeight = 4.0;
}  // namespace

// The active set changed from the rows B of the last factorization to W = (B \ R) ∪ D by a few rows.
// With F = Pᵀ L D Lᵀ P the factorization of (A + εI)_BB, p_R = 0 is imposed by multipliers μ on the rows
// R and the new rows D border the system:
//   (A + εI)_BB p_B + A_BD p_D + E_R μ = c_B,   A_DB p_B + (A + εI)_DD p_D = c_D,   E_Rᵀ p_B = 0.
// With U = [A_BD, E_R], p_B = F⁻¹(c_B − U y), and y = (p_D, μ) solves the small Schur system
//   S y = (c_D, 0) − Uᵀ F⁻¹ c_B,   S = [(A + εI)_DD 0; 0 0] − Uᵀ F⁻¹ U.
// With W = L⁻¹ P U, Uᵀ F⁻¹ U = Wᵀ D⁻¹ W: each column of W is a sparse forward solve along the
// elimination tree (MaskedLdlt::forward_sparse), kept with its Gram entries while the factorization
// is (the changes of an active-set search mostly grow), and one right-hand side costs one solve split
// in halves: t = L⁻¹ P c, y from Wᵀ D⁻¹ t, then p_B = Pᵀ L⁻ᵀ D⁻¹ (t − W y).
// Returns false (refactor) when S is (nearly) singular or the result does not hold the active rows to
// 1e-10 relative.
bool IslandSolver::solve_updated(ActiveLoop& loop, const SparseMatrix& a, double shift, const Vector& c,
                                 const std::vector<char>& active, Vector& p, SolverStats& stats) {
  if (loop.updated && loop.updated_for == active) {  // the same free set as the last update: reuse it
    apply_update(loop, c, p);
    ++stats.updated;
    return true;
  }
  loop.updated = false;
  std::vector<RowIndex>& added = loop.added;
  std::vector<RowIndex>& removed = loop.removed;
  added.clear();
  removed.clear();
  for (std::size_t k = 0; k < active.size(); ++k) {
    if (active[k] && !loop.in_base[k]) added.push_back(static_cast<RowIndex>(k));
    if (!active[k] && loop.in_base[k]) removed.push_back(static_cast<RowIndex>(k));
  }
  const auto nd = static_cast<Eigen::Index>(added.size());
  const auto size = nd + static_cast<Eigen::Index>(removed.size());
  if (size == 0) return false;
  loop.slots.clear();
  for (RowIndex d : added) loop.slots.push_back(border(loop, a, d));
  for (RowIndex r : removed) loop.slots.push_back(border(loop, a, r));
  Eigen::MatrixXd schur(size, size);
  for (Eigen::Index j = 0; j < size; ++j)
    for (Eigen::Index i = 0; i < size; ++i) schur(i, j) = -loop.gram(loop.slots[static_cast<std::size_t>(i)], loop.slots[static_cast<std::size_t>(j)]);
  for (Eigen::Index j = 0; j < nd; ++j) {
    schur(j, j) += shift;
    for (SparseMatrix::InnerIterator it(a, added[static_cast<std::size_t>(j)]); it; ++it)
      if (active[static_cast<std::size_t>(it.row())] && !loop.in_base[static_cast<std::size_t>(it.row())]) {
        const auto i = std::lower_bound(added.begin(), added.end(), static_cast<RowIndex>(it.row())) - added.begin();
        schur(i, j) += it.value();
      }
  }
  loop.schur.compute(schur);
  loop.schur.setThreshold(settings_.rank_tolerance);
  if (loop.schur.rank() < size) return false;  // numerically singular: refactor
  Vector out;
  apply_update(loop, c, out);
  // Accept only if the active rows hold to rounding (the update is as exact as a refactorization).
  const Vector residual = a * out + shift * out - c;
  double worst = 0.0, size_c = 0.0;
  for (std::size_t k = 0; k < active.size(); ++k)
    if (active[k]) {
      worst = std::max(worst, std::abs(residual(static_cast<Eigen::Index>(k))));
      size_c = std::max(size_c, std::abs(c(static_cast<Eigen::Index>(k))));
    }
  if (!(worst <= 1e-10 * size_c + std::numeric_limits<double>::min())) return false;
  loop.updated = true;
  loop.updated_for = active;
  p = std::move(out);
  ++stats.updated;
  return true;
}

// The entry of `borders` for a row that joins (u = A_B,row) or leaves (u = e_row) the factorization's
// rows B: computed on first use, with its Gram entries against the borders already there.
int IslandSolver::border(ActiveLoop& loop, const SparseMatrix& a, RowIndex row) {
  if (loop.border_of.size() != static_cast<std::size_t>(a.rows())) loop.border_of.assign(static_cast<std::size_t>(a.rows()), -1);
  if (const int known = loop.border_of[row]; known >= 0) return known;
  std::vector<std::pair<int, double>> u;
  if (loop.in_base[row]) {
    u.emplace_back(static_cast<int>(row), 1.0);
  } else {
    for (SparseMatrix::InnerIterator it(a, row); it; ++it)
      if (loop.in_base[static_cast<std::size_t>(it.row())]) u.emplace_back(static_cast<int>(it.row()), it.value());
  }
  ActiveLoop::Border w;
  loop.factor->forward_sparse(u, w.index, w.value);
  // G_jk = w_jᵀ D⁻¹ w_k against every earlier border, by scattering D⁻¹ w into a dense vector (zero
  // between calls: only w's entries are set, and cleared again below).
  const auto count = static_cast<Eigen::Index>(loop.borders.size());
  Vector& scattered = loop.scattered;
  if (scattered.size() != static_cast<Eigen::Index>(loop.factor->rows()))
    scattered.setZero(static_cast<Eigen::Index>(loop.factor->rows()));
  double self = 0.0;
  for (std::size_t q = 0; q < w.index.size(); ++q) {
    const double scaled = w.value[q] * loop.factor->pivot_inverse(w.index[q]);
    scattered(w.index[q]) = scaled;
    self += scaled * w.value[q];
  }
  loop.gram.conservativeResize(count + 1, count + 1);
  for (Eigen::Index j = 0; j < count; ++j) {
    const ActiveLoop::Border& other = loop.borders[static_cast<std::size_t>(j)];
    double dot = 0.0;
    for (std::size_t q = 0; q < other.index.size(); ++q) dot += other.value[q] * scattered(other.index[q]);
    loop.gram(j, count) = loop.gram(count, j) = dot;
  }
  loop.gram(count, count) = self;
  for (const int i : w.index) scattered(i) = 0.0;
  loop.borders.push_back(std::move(w));
  loop.border_of[row] = static_cast<int>(count);
  return static_cast<int>(count);
}

void IslandSolver::ActiveLoop::refactored() {
  for (std::size_t k = 0; k < border_of.size(); ++k) border_of[k] = -1;
  borders.clear();
  gram.resize(0, 0);
  updated = false;
}

// The solution of the bordered system above for the right-hand side c, from the stored update.
void IslandSolver::apply_update(ActiveLoop& loop, const Vector& c, Vector& out) {
  const auto nd = static_cast<Eigen::Index>(loop.added.size());
  const auto size = static_cast<Eigen::Index>(loop.slots.size());
  const MaskedLdlt& f = *loop.factor;
  Vector& t = loop.forward;
  f.forward(c, t);  // t = L⁻¹ P c_B
  Vector rhs(size);  // (c_D, 0) − Wᵀ D⁻¹ t
  for (Eigen::Index j = 0; j < size; ++j) {
    const ActiveLoop::Border& w = loop.borders[static_cast<std::size_t>(loop.slots[static_cast<std::size_t>(j)])];
    double dot = 0.0;
    for (std::size_t q = 0; q < w.index.size(); ++q) dot += w.value[q] * f.pivot_inverse(w.index[q]) * t(w.index[q]);
    rhs(j) = (j < nd ? c(loop.added[static_cast<std::size_t>(j)]) : 0.0) - dot;
  }
  const Vector y = loop.schur.solve(rhs);
  for (Eigen::Index j = 0; j < size; ++j) {  // t − W y
    const ActiveLoop::Border& w = loop.borders[static_cast<std::size_t>(loop.slots[static_cast<std::size_t>(j)])];
    for (std::size_t q = 0; q < w.index.size(); ++q) t(w.index[q]) -= w.value[q] * y(j);
  }
  out.resize(c.size());
  f.backward(t, out);  // p_B = Pᵀ L⁻ᵀ D⁻¹ (t − W y); zero off B
  for (RowIndex r : loop.removed) out(r) = 0.0;
  for (Eigen::Index j = 0; j < nd; ++j) out(loop.added[static_cast<std::size_t>(j)]) = y(j);
}

// Factorizes (A + εI)_FF for the free rows F into the loop. The symbolic analysis covers the rows the
// search was expected to need (its start set, MaskedLdlt::analyze); a free set beyond them is analysed
// again first, once with the rows it adds, after that with every row (so at most two analyses more).
void IslandSolver::factorize_loop(ActiveLoop& loop, const SparseMatrix& a, const std::vector<char>& rows, double shift,
                                  SolverStats& stats) {
  if (!loop.factor->covers(rows)) {
    std::vector<char> wider(rows.size(), 1);
    if (!loop.widened)
      for (std::size_t k = 0; k < rows.size(); ++k) wider[k] = rows[k] || loop.factor->analysed(k);
    loop.widened = true;
    loop.factor->analyze(a, wider);
    ++stats.symbolic_analyses;
  }
  ++stats.sparse;
  loop.factor->factorize(a, rows, settings_.rank_tolerance, loop.floor, shift);
  loop.factored = true;
  loop.refactored();
  for (std::size_t k = 0; k < rows.size(); ++k) loop.in_base[k] = rows[k] && !loop.factor->dropped(k);
}

// Solves (A + εI)_FF z = r_F for the free rows F: by the current factorization when F is the one it
// holds, by an update when only a few rows changed, else by a new masked factorization (same symbolic
// analysis). A + εI is positive definite, so every free set has exactly one solution.
Vector IslandSolver::solve_active(const SparseMatrix& a, double shift, const Vector& r, const std::vector<char>& active,
                                  ActiveLoop& loop, SolverStats& stats) {
  if (loop.factored) {
    std::size_t changes = 0;
    for (std::size_t k = 0; k < active.size(); ++k) changes += (active[k] != 0) != (loop.in_base[k] != 0);
    if (changes == 0) {
      Vector z = r;
      loop.factor->solve(z);
      return z;
    }
    Vector z;
    const std::size_t limit = settings_.update_limit > 0
                                  ? settings_.update_limit
                                  : std::max<std::size_t>(8, static_cast<std::size_t>(std::sqrt(static_cast<double>(active.size()))));
    if (changes <= limit && solve_updated(loop, a, shift, r, active, z, stats)) return z;
  }
  factorize_loop(loop, a, active, shift, stats);
  loop.singular = loop.singular || loop.factor->redundant_rows(shift) > 0;
  Vector z = r;
  loop.factor->solve(z);
  return z;
}

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
// join it) while the number of infeasible rows falls; then the primal active-set method from p = 0 (an
// infeasible minimizer is approached until the first free row reaches zero, the rows at zero are
// released; a feasible one becomes p and the rows approaching fastest join), whose objective strictly
// decreases between feasible minimizers, so it terminates.
//
// Two shifts. The first solve uses the final ε = regularization · max A_kk (1e-10): when the start set
// is the answer (a line of spheres, a box on its face) that one solve is exact. Otherwise the search
// goes on with ε = search_regularization · max A_kk (1e-3): with the tiny shift the subproblem is as
// ill-conditioned as A itself and block pivoting stalls on redundant rows (pyramid K = 50: after four
// exchanges, then 45 one-row primal steps); with the larger one it settles in a few exchanges. Each
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
// solve_complementarity_min_norm takes over.
Vector IslandSolver::solve_complementarity(const ComplementarityProblem& problem, SolverStats& stats) {
  const SparseMatrix& a = *problem.matrix;
  const auto m = static_cast<std::size_t>(a.rows());
  const Vector& c = problem.rhs;
  const auto inequality = [&](std::size_t k) { return !problem.equality[k]; };
  std::vector<char> free_rows(m);
  for (std::size_t k = 0; k < m; ++k) free_rows[k] = problem.equality[k] || problem.start[k];
  Vector p = Vector::Zero(a.rows());
  if (m == 0) return p;
  work_.diagonal = a.diagonal();
  const double scale = work_.diagonal.maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) {  // nothing movable behind any row
    ++stats.singular;
    return p;
  }
  if (m == 1) {  // closed form: p = c / A_11, clamped at 0 for a contact (identical to the paper mode's)
    const double a11 = a.coeff(0, 0);
    ++stats.iterations;
    ++stats.closed_form;
    p(0) = a11 > settings_.rank_tolerance * scale ? c(0) / a11 : 0.0;
    if (!problem.equality[0] && !(p(0) > 0.0)) {
      if (p(0) < 0.0) ++stats.released;
      p(0) = 0.0;
    }
    return p;
  }
  // ε: the final shift, and the larger one of the active-set search (see the comment above).
  const double final_shift = settings_.regularization * scale;
  const double search_shift = std::max(final_shift, settings_.search_regularization * scale);
  double shift = final_shift;
  ActiveLoop loop;
  loop.factor = checkout_masked(a, free_rows, stats);
  loop.floor = settings_.rank_tolerance * scale;
  loop.in_base.assign(m, 0);
  Vector center = Vector::Zero(a.rows());  // p̄
  Vector r = c;                              // c + ε p̄
  Vector w(a.rows());
  bool converged = false, not_finite = false, stalled = false;
  double last_change = std::numeric_limits<double>::infinity();
  int slow = 0;
  std::size_t fewest_infeasible = m + 1;
  bool pivoting = true;  // block principal pivoting while it helps, then the primal active-set method
  Vector z;
  for (std::uint64_t iteration = 0; iteration < settings_.max_iterations; ++iteration) {
    ++stats.iterations;
    z = solve_active(a, shift, r, free_rows, loop, stats);
    if (!z.allFinite()) {
      ++stats.nan_caught;
      p.setZero();
      not_finite = true;
      break;
    }
    // w = A z − c; the subproblem's gradient is w + ε (z − p̄), = w − ε p̄ on rows at zero.
    w.noalias() = a * z;
    w -= c;
    const double roundoff = kImpulseRoundoff * z.lpNorm<Eigen::Infinity>();
    const double join = problem.tolerance;
    const auto negative = [&](std::size_t k) { return free_rows[k] && inequality(k) && z(static_cast<Eigen::Index>(k)) < -roundoff; };
    const auto approaching = [&](std::size_t k) {
      return !free_rows[k] && w(static_cast<Eigen::Index>(k)) - shift * center(static_cast<Eigen::Index>(k)) < -join;
    };
    std::size_t negatives = 0, approaches = 0;
    for (std::size_t k = 0; k < m; ++k) negatives += negative(k), approaches += approaching(k);
    if (iteration == 0 && negatives + approaches > 0 && shift < search_shift) {
      // The start set is not the answer: search the active set on the better-conditioned subproblem.
      // p̄ = 0 still, so only the matrix changes (the factorization is redone at the new shift).
      shift = search_shift;
      loop.factored = false;
    }
    if (pivoting && negatives + approaches > 0 && negatives + approaches < fewest_infeasible) {
      // Block principal pivoting (Júdice & Pires): exchange every infeasible row at once, as long as
      // the number of infeasible rows keeps falling.
      fewest_infeasible = negatives + approaches;
      for (std::size_t k = 0; k < m; ++k) {
        if (negative(k)) free_rows[k] = 0, ++stats.released;
        else if (approaching(k)) free_rows[k] = 1, ++stats.added;
      }
      continue;
    }
    if (pivoting && negatives + approaches > 0) {  // pivoting stopped helping: the primal method from p = 0
      pivoting = false;
      p.setZero();
    }
    if (negatives > 0) {
      // Primal step: towards z until the first free row reaches zero; release the rows at zero.
      const Vector direction = z - p;
      double step = 1.0;
      std::size_t blocking = m;
      for (std::size_t k = 0; k < m; ++k) {
        const auto i = static_cast<Eigen::Index>(k);
        if (!free_rows[k] || !inequality(k) || !(direction(i) < 0.0)) continue;
        const double ratio = std::max(0.0, p(i)) / -direction(i);
        if (ratio < step) step = ratio, blocking = k;
      }
      p += step * direction;
      const double floor = kImpulseRoundoff * p.lpNorm<Eigen::Infinity>();
      for (std::size_t k = 0; k < m; ++k) {
        const auto i = static_cast<Eigen::Index>(k);
        if (free_rows[k] && inequality(k) && (k == blocking || (z(i) < -roundoff && p(i) <= floor))) {
          free_rows[k] = 0;
          p(i) = 0.0;
          ++stats.released;
        }
      }
      continue;
    }
    p = z;
    if (approaches > 0) {
      // Primal step: z is feasible; the rows at zero that approach at least half as fast as the fastest
      // join F (all of them at once over-fills a redundant set and releases most again).
      double worst = 0.0;
      for (std::size_t k = 0; k < m; ++k)
        if (approaching(k)) worst = std::min(worst, w(static_cast<Eigen::Index>(k)) - shift * center(static_cast<Eigen::Index>(k)));
      for (std::size_t k = 0; k < m; ++k)
        if (approaching(k) && w(static_cast<Eigen::Index>(k)) - shift * center(static_cast<Eigen::Index>(k)) <= kJoinShare * worst)
          free_rows[k] = 1, ++stats.added;
      continue;
    }
    for (std::size_t k = 0; k < m; ++k)
      if (inequality(k)) p(static_cast<Eigen::Index>(k)) = free_rows[k] ? std::max(p(static_cast<Eigen::Index>(k)), 0.0) : 0.0;
    // The proximal subproblem is solved. Is its free set the answer? Solve the problem itself on it.
    {
      Vector x = p;
      if (refine_on_free_set(a, c, shift, free_rows, loop, problem, x, stats) == Refinement::exact) {
        p = std::move(x);
        converged = true;
        break;
      }
      if (shift > final_shift) {  // not yet: go on with a smaller shift (a proximal step nearer the answer)
        shift = std::max(final_shift, kShiftReduction * shift);
        loop.factored = false;
        last_change = std::numeric_limits<double>::infinity();
        slow = 0;
      }
    }
    const double change = shift * (p - center).lpNorm<Eigen::Infinity>();
    bool violated = false;
    for (std::size_t k = 0; k < m; ++k)
      if (!free_rows[k] && w(static_cast<Eigen::Index>(k)) < -problem.tolerance) violated = true;
    // Rounding bounds how small w can get: a few ulps of the terms of A p − c.
    const double rounding = 1e-14 * (scale * p.lpNorm<Eigen::Infinity>() + c.lpNorm<Eigen::Infinity>());
    if (!violated && change <= std::max(1e-3 * problem.tolerance, rounding)) {
      converged = true;
      break;
    }
    slow = change > 0.9 * last_change ? slow + 1 : 0;
    if (slow >= 3) {  // no longer shrinking: exact to the tolerance, or conflicting targets
      if (!violated && change <= problem.tolerance) converged = true;
      else stalled = true;
      break;
    }
    last_change = change;
    center = p;
    r = c + shift * center;
    fewest_infeasible = m + 1;
    pivoting = true;
    ++stats.proximal;
  }
  checkin_masked(std::move(loop.factor));
  if (loop.singular) ++stats.singular;
  if (stalled) return solve_complementarity_min_norm(problem, stats);
  if (!converged && !not_finite) ++stats.non_converged;
  if (!converged)  // the last iterate may be infeasible: keep impulses ≥ 0
    for (std::size_t k = 0; k < m; ++k)
      if (inequality(k)) p(static_cast<Eigen::Index>(k)) = free_rows[k] ? std::max(p(static_cast<Eigen::Index>(k)), 0.0) : 0.0;
  if (converged) polish_minimum_norm(a, c, free_rows, problem, p, stats);
  return p;
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
IslandSolver::Refinement IslandSolver::refine_on_free_set(const SparseMatrix& a, const Vector& c, double shift,
                                                          const std::vector<char>& free_rows, ActiveLoop& loop,
                                                          const ComplementarityProblem& problem, Vector& x,
                                                          SolverStats& stats) {
  const auto m = free_rows.size();
  // The preconditioner (A + εI)_FF⁻¹: the factorization if it is of F, else the last update if that
  // solves for F, else a new factorization.
  bool holds = loop.factored;
  for (std::size_t k = 0; holds && k < m; ++k)
    holds = free_rows[k] ? (loop.in_base[k] || loop.factor->dropped(k)) : !loop.in_base[k];
  bool by_update = !holds && loop.factored && loop.updated && loop.updated_for == free_rows;
  if (!holds && !by_update) factorize_loop(loop, a, free_rows, shift, stats);
  Vector& residual = work_.residual;
  Vector& preconditioned = work_.preconditioned;
  Vector& direction = work_.direction;
  Vector& product = work_.product;
  const auto precondition = [&](const Vector& v, Vector& out) {
    if (by_update) {
      apply_update(loop, v, out);
    } else {
      out = v;
      loop.factor->solve(out);
    }
  };
  // F without the rows nothing movable is behind (left at p = 0, as the factorization leaves them).
  std::vector<char>& solved_rows = work_.solved_rows;
  solved_rows.resize(m);
  for (std::size_t k = 0; k < m; ++k)
    solved_rows[k] = free_rows[k] && work_.diagonal(static_cast<Eigen::Index>(k)) > loop.floor;
  std::vector<Eigen::Index>& unsolved = work_.unsolved_rows;  // zeroed by index: no branch per row
  unsolved.clear();
  for (std::size_t k = 0; k < m; ++k)
    if (!solved_rows[k]) unsolved.push_back(static_cast<Eigen::Index>(k));
  const auto restrict_to_base = [&](Vector& v) {
    for (const Eigen::Index k : unsolved) v(k) = 0.0;
  };
  restrict_to_base(x);
  residual.noalias() = -(a * x);
  residual += c;
  restrict_to_base(residual);
  precondition(residual, preconditioned);
  direction = preconditioned;
  double rz = residual.dot(preconditioned);
  const double scale = work_.diagonal.maxCoeff();
  const double final_shift = settings_.regularization * scale;
  // Multiply-adds of one step: a solve (forward and backward over L), a product with A, vector updates.
  const double step_cost = 2.0 * static_cast<double>(loop.factor->capacity()) + static_cast<double>(a.nonZeros()) +
                           10.0 * static_cast<double>(m);
  double first_residual = 0.0;
  const double size_c = c.lpNorm<Eigen::Infinity>();
  bool solved = false;
  for (int step = 0; step <= kMaxRefinementSteps; ++step) {
    const double rounding = 1e-14 * (scale * x.lpNorm<Eigen::Infinity>() + size_c);
    const double goal = std::max(1e-3 * problem.tolerance, rounding);
    const double size = residual.lpNorm<Eigen::Infinity>();
    if (size <= goal) {
      solved = true;
      break;
    }
    if (step == kMaxRefinementSteps) break;
    if (step == 0) first_residual = size;
    if (settings_.sharpen_refinement && step == kProbeSteps && shift > final_shift) {
      // The preconditioned matrix has the eigenvalues λ/(λ + ε): many eigenvalues of A_FF below ε (a
      // large, soft network: pyramid K = 100) make many steps. Predict them; if a factorization at a
      // smaller shift is cheaper, take it and restart from x.
      const double rate = std::pow(size / first_residual, 1.0 / kProbeSteps);
      const double remaining = rate < 1.0 ? std::log(goal / size) / std::log(rate) : kMaxRefinementSteps;
      if (remaining * step_cost >
          kFactorizationWeight * loop.factor->factorization_work() + kStepsAfterSharpening * step_cost) {
        shift = std::max(final_shift, kShiftReduction * shift);
        factorize_loop(loop, a, free_rows, shift, stats);
        loop.factored = false;  // at a shift the active-set loop is not using: refactor when it goes on
        by_update = false;
        ++stats.sharpened;
        precondition(residual, preconditioned);
        direction = preconditioned;
        rz = residual.dot(preconditioned);
      }
    }
    ++stats.refinements;
    product.noalias() = a * direction;
    restrict_to_base(product);
    const double curvature = direction.dot(product);
    if (!(curvature > 0.0)) break;
    const double alpha = rz / curvature;
    x += alpha * direction;
    residual -= alpha * product;
    precondition(residual, preconditioned);
    const double rz_next = residual.dot(preconditioned);
    direction = preconditioned + (rz_next / rz) * direction;
    rz = rz_next;
  }
  if (!solved) return Refinement::not_converged;
  product.noalias() = a * x;
  product -= c;  // w
  const double roundoff = kImpulseRoundoff * x.lpNorm<Eigen::Infinity>();
  for (std::size_t k = 0; k < m; ++k) {
    if (problem.equality[k]) continue;
    const auto i = static_cast<Eigen::Index>(k);
    if (solved_rows[k] ? x(i) < -roundoff : product(i) < -problem.tolerance) return Refinement::infeasible;
  }
  for (std::size_t k = 0; k < m; ++k)
    if (!problem.equality[k]) x(static_cast<Eigen::Index>(k)) = std::max(0.0, x(static_cast<Eigen::Index>(k)));
  return Refinement::exact;
}

}  // namespace impetus::ledas
