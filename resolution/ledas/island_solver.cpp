#include "ledas/island_solver.hpp"
#include "ledas/masked_ldlt.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus::ledas {

namespace {
// Factorizations kept for reuse of their symbolic analysis (distinct sparsity patterns).
constexpr std::size_t kCacheCapacity = 16;
// An impulse this far below zero, relative to the largest one, is rounding, not a pulling impulse.
constexpr double kImpulseRoundoff = 1e-12;
// Primal additions: rows approaching at least this share of the fastest approach join at once.
constexpr double kJoinShare = 0.5;

Vector gather(const Vector& v, std::span<const RowIndex> rows) {
  Vector out(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) out(static_cast<Eigen::Index>(i)) = v(rows[i]);
  return out;
}

std::vector<RowIndex> members(const std::vector<char>& flags) {
  std::vector<RowIndex> out;
  for (std::size_t k = 0; k < flags.size(); ++k)
    if (flags[k]) out.push_back(static_cast<RowIndex>(k));
  return out;
}
}  // namespace

struct IslandSolver::Factor {
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
  std::vector<int> outer, inner;  // the sparsity pattern the symbolic analysis belongs to
};

IslandSolver::IslandSolver(SolverSettings settings) : settings_(settings) {}
IslandSolver::~IslandSolver() = default;

SparseMatrix principal_submatrix(const SparseMatrix& a, std::span<const RowIndex> subset) {
  std::vector<int> position(static_cast<std::size_t>(a.rows()), -1);
  for (std::size_t i = 0; i < subset.size(); ++i) position[subset[i]] = static_cast<int>(i);
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t j = 0; j < subset.size(); ++j)
    for (SparseMatrix::InnerIterator it(a, subset[j]); it; ++it)
      if (const int i = position[static_cast<std::size_t>(it.row())]; i >= 0)
        entries.emplace_back(i, static_cast<int>(j), it.value());
  const auto n = static_cast<Eigen::Index>(subset.size());
  SparseMatrix out(n, n);
  out.setFromTriplets(entries.begin(), entries.end());
  out.makeCompressed();
  return out;
}

Vector IslandSolver::solve_subset(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset,
                                  SolverStats& stats) {
  Vector p = Vector::Zero(a.rows());
  solve_subset(a, c, subset, p, stats);
  return p;
}

// The subset's rows fall into connected components (rows coupled through A, i.e. through a shared
// movable body); A_SS is block diagonal in them, so each block is solved on its own by the cheapest
// exact method. In the paper's rounds most blocks are one or two rows.
void IslandSolver::solve_subset(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset, Vector& p,
                                SolverStats& stats) {
  Workspace& w = work_;
  const auto n = static_cast<int>(subset.size());
  if (n == 0) return;
  if (w.slot.size() < static_cast<std::size_t>(a.rows())) w.slot.assign(static_cast<std::size_t>(a.rows()), -1);
  w.parent.resize(subset.size());
  for (int i = 0; i < n; ++i) {
    w.slot[subset[static_cast<std::size_t>(i)]] = i;
    w.parent[static_cast<std::size_t>(i)] = i;
  }
  // Rows coupled to no other row of the subset: closed form at once (p = c / A_11, the single-contact
  // impulse of the paper's ref. [4]); they leave the component search.
  bool coupled = false;
  for (int i = 0; i < n; ++i) {
    const RowIndex k = subset[static_cast<std::size_t>(i)];
    double a11 = 0.0;
    bool alone = true;
    for (SparseMatrix::InnerIterator it(a, k); it; ++it) {
      if (it.row() == static_cast<Eigen::Index>(k)) a11 = it.value();
      else if (w.slot[static_cast<std::size_t>(it.row())] >= 0) alone = false;
    }
    if (!alone) {
      coupled = true;
      continue;
    }
    ++stats.closed_form;
    if (a11 > 0.0 && std::isfinite(a11)) {
      p(k) = c(k) / a11;
    } else {
      ++stats.singular;
      p(k) = 0.0;
    }
    w.parent[static_cast<std::size_t>(i)] = -1;
  }
  if (!coupled) {
    for (RowIndex k : subset) w.slot[k] = -1;
    return;
  }
  const auto find = [&](int x) {
    while (w.parent[static_cast<std::size_t>(x)] != x)
      x = w.parent[static_cast<std::size_t>(x)] = w.parent[static_cast<std::size_t>(w.parent[static_cast<std::size_t>(x)])];
    return x;
  };
  for (int i = 0; i < n; ++i)
    if (w.parent[static_cast<std::size_t>(i)] >= 0)
    for (SparseMatrix::InnerIterator it(a, subset[static_cast<std::size_t>(i)]); it; ++it)
      if (const int j = w.slot[static_cast<std::size_t>(it.row())]; j >= 0) {
        const int ri = find(i), rj = find(j);
        if (ri != rj) w.parent[static_cast<std::size_t>(std::max(ri, rj))] = std::min(ri, rj);
      }
  // Members of each component in increasing order, components by their first row (deterministic).
  w.start.assign(subset.size() + 1, 0);
  for (int i = 0; i < n; ++i)
    if (w.parent[static_cast<std::size_t>(i)] >= 0) ++w.start[static_cast<std::size_t>(find(i)) + 1];
  for (std::size_t i = 0; i < subset.size(); ++i) w.start[i + 1] += w.start[i];
  w.members.resize(subset.size());
  w.fill.assign(w.start.begin(), w.start.end() - 1);
  for (int i = 0; i < n; ++i)
    if (w.parent[static_cast<std::size_t>(i)] >= 0) w.members[static_cast<std::size_t>(w.fill[static_cast<std::size_t>(w.parent[static_cast<std::size_t>(i)])]++)] = i;

  for (int root = 0; root < n; ++root) {
    if (w.parent[static_cast<std::size_t>(root)] != root) continue;
    const int begin = w.start[static_cast<std::size_t>(root)], size = w.start[static_cast<std::size_t>(root) + 1] - begin;
    const auto row = [&](int local) { return subset[static_cast<std::size_t>(w.members[static_cast<std::size_t>(begin + local)])]; };
    for (int i = 0; i < size; ++i) w.slot[row(i)] = i;  // now: position within the component
    if (static_cast<std::size_t>(size) <= settings_.dense_limit) {
      w.dense.setZero(size, size);
      w.rhs.resize(size);
      for (int j = 0; j < size; ++j) {
        w.rhs(j) = c(row(j));
        for (SparseMatrix::InnerIterator it(a, row(j)); it; ++it)
          if (const int i = w.slot[static_cast<std::size_t>(it.row())]; i >= 0) w.dense(i, j) = it.value();
      }
      const Vector part = solve_dense_matrix(w.dense, w.rhs, stats);
      for (int i = 0; i < size; ++i) p(row(i)) = part(i);
    } else {
      std::vector<RowIndex> rows(static_cast<std::size_t>(size));
      for (int i = 0; i < size; ++i) rows[static_cast<std::size_t>(i)] = row(i);
      const Vector part = solve_system(principal_submatrix(a, rows), gather(c, rows), stats);
      for (int i = 0; i < size; ++i) p(row(i)) = part(i);
    }
  }
  for (RowIndex k : subset) w.slot[k] = -1;
}

// Chooses the cheapest exact method for one system (see the header).
Vector IslandSolver::solve_system(const SparseMatrix& m, const Vector& rhs, SolverStats& stats) {
  const Eigen::Index n = m.rows();
  if (n == 0) return Vector();
  const double scale = Vector(m.diagonal()).maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) {  // no movable body behind any row: nothing can change
    ++stats.singular;
    return Vector::Zero(n);
  }
  const double pivot_floor = settings_.rank_tolerance * scale;
  if (n == 1) {  // closed form: p = c / A_11 (the single-contact impulse of the paper's ref. [4])
    ++stats.closed_form;
    const double a11 = m.coeff(0, 0);
    if (a11 > pivot_floor) return Vector::Constant(1, rhs(0) / a11);
    ++stats.singular;
    return Vector::Zero(1);
  }
  if (static_cast<std::size_t>(n) <= settings_.dense_limit) return solve_dense_matrix(Eigen::MatrixXd(m), rhs, stats);
  return solve_sparse(m, rhs, pivot_floor, stats);
}

Vector IslandSolver::solve_dense_matrix(const Eigen::MatrixXd& a, const Vector& rhs, SolverStats& stats) {
  ++stats.dense;
  const double scale = a.diagonal().maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) {  // no movable body behind any row
    ++stats.singular;
    return Vector::Zero(a.rows());
  }
  const double pivot_floor = settings_.rank_tolerance * scale;
  // LDLᵀ with diagonal pivoting reveals the rank of a PSD matrix: a dependent row leaves a ~0 pivot.
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(a);
  if (ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > pivot_floor).all()) return ldlt.solve(rhs);
  ++stats.singular;
  // Minimum-norm least squares through the eigen-decomposition (the SVD of a symmetric PSD matrix).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(a);
  const Vector& lambda = eigen.eigenvalues();
  Vector y = eigen.eigenvectors().transpose() * rhs;
  for (Eigen::Index i = 0; i < y.size(); ++i) y(i) = lambda(i) > pivot_floor ? y(i) / lambda(i) : 0.0;
  return eigen.eigenvectors() * y;
}

namespace {
// Orthonormal basis of the columns of x (thin Q of a Householder QR).
Eigen::MatrixXd orthonormal_columns(const Eigen::MatrixXd& x) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(x);
  return qr.householderQ() * Eigen::MatrixXd::Identity(x.rows(), x.cols());
}
}  // namespace

Vector IslandSolver::solve_sparse(const SparseMatrix& m, const Vector& rhs, double pivot_floor,
                                  SolverStats& stats) {
  ++stats.sparse;
  FactorPtr f = checkout(m, stats);
  f->ldlt.setShift(0.0);
  f->ldlt.factorize(m);
  const Vector d = f->ldlt.info() == Eigen::Success ? Vector(f->ldlt.vectorD()) : Vector::Zero(1);
  const auto small_pivots = static_cast<Eigen::Index>((d.array() <= pivot_floor).count());
  if (small_pivots == 0) {
    Vector p = f->ldlt.solve(rhs);
    checkin(f);
    return p;
  }
  ++stats.singular;
  // Minimum norm: A + εI (ε = the pivot floor) is positive definite and shares A's eigenvectors.
  // Shifted inverse iteration converges to the null space of A (eigenvalues ≤ the floor); projecting
  // it out of the right-hand side and of every correction leaves p in the range of A, i.e. A⁺ c.
  f->ldlt.setShift(pivot_floor);
  f->ldlt.factorize(m);
  const Eigen::Index n = m.rows();
  Eigen::Index k = std::min(n, small_pivots + 2);  // a little oversampling: the pivot count is a guess
  Eigen::MatrixXd null_basis;
  for (;;) {
    Eigen::MatrixXd x(n, k);
    for (Eigen::Index j = 0; j < k; ++j)  // deterministic start: a fixed, well-spread pattern
      for (Eigen::Index i = 0; i < n; ++i) x(i, j) = std::sin(1.0 + 0.7 * static_cast<double>(i) + 1.3 * static_cast<double>(j * j + i * j));
    for (int pass = 0; pass < 4; ++pass) {
      const Eigen::MatrixXd y = f->ldlt.solve(x);
      x = orthonormal_columns(y);
    }
    const Eigen::MatrixXd ax = m * x;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz(x.transpose() * ax);
    const auto nullity = static_cast<Eigen::Index>((ritz.eigenvalues().array() <= pivot_floor).count());
    if (nullity < k || k == n) {  // the subspace held more than the null space: it is all found
      null_basis = x * ritz.eigenvectors().leftCols(nullity);
      break;
    }
    k = std::min(n, 2 * k);
  }
  const auto project = [&](Vector v) {
    if (null_basis.cols() > 0) v -= null_basis * (null_basis.transpose() * v);
    return v;
  };
  const Vector c = project(rhs);
  Vector p = project(f->ldlt.solve(c));
  for (int refine = 0; refine < 30; ++refine) {  // iterated Tikhonov on the range: error × ε/(λ+ε)
    const Vector r = c - m * p;
    if (r.norm() <= 1e-15 * c.norm()) break;
    const Vector dp = project(f->ldlt.solve(r));
    p += dp;
    if (dp.norm() <= 1e-16 * p.norm()) break;
  }
  checkin(f);
  return p;
}

// The active set changed from the rows B of the last factorization to W = (B \ R) ∪ D by a few rows.
// With F the factorization of A_BB, p_R = 0 is imposed by multipliers μ on the rows R and the new rows
// D border the system:
//   A_BB p_B + A_BD p_D + E_R μ = c_B,   A_DB p_B + A_DD p_D = c_D,   E_Rᵀ p_B = 0.
// With U = [A_BD, E_R], p_B = F⁻¹(c_B − U y) for y = (p_D, μ), and y solves the small Schur system
//   ([A_DD 0; 0 0] − Uᵀ F⁻¹ U) y = (c_D, 0) − Uᵀ F⁻¹ c_B.
// Returns false (refactor) when the Schur system is (nearly) singular or the result does not hold the
// active rows to 1e-10 relative.
bool IslandSolver::solve_updated(const ActiveLoop& loop, const SparseMatrix& a, double shift, const Vector& c,
                                 const std::vector<char>& active, Vector& p, SolverStats& stats) {
  std::vector<RowIndex>& added = work_.added;
  std::vector<RowIndex>& removed = work_.removed;
  added.clear();
  removed.clear();
  for (std::size_t k = 0; k < active.size(); ++k) {
    if (active[k] && !loop.in_base[k]) added.push_back(static_cast<RowIndex>(k));
    if (!active[k] && loop.in_base[k]) removed.push_back(static_cast<RowIndex>(k));
  }
  const auto n = a.rows();
  const auto nd = static_cast<Eigen::Index>(added.size());
  const auto size = nd + static_cast<Eigen::Index>(removed.size());
  if (size == 0) return false;
  Eigen::MatrixXd& y = work_.columns;
  y.setZero(n, size);
  for (Eigen::Index j = 0; j < nd; ++j)
    for (SparseMatrix::InnerIterator it(a, added[static_cast<std::size_t>(j)]); it; ++it)
      if (loop.in_base[static_cast<std::size_t>(it.row())]) y(it.row(), j) = it.value();
  for (std::size_t j = 0; j < removed.size(); ++j) y(removed[j], nd + static_cast<Eigen::Index>(j)) = 1.0;
  Eigen::MatrixXd& u = work_.borders;
  u = y;
  for (Eigen::Index j = 0; j < size; ++j) loop.factor->solve(y.col(j));
  Vector z0 = c;
  loop.factor->solve(z0);
  Eigen::MatrixXd schur = -u.transpose() * y;
  for (Eigen::Index i = 0; i < nd; ++i)
    for (Eigen::Index j = 0; j < nd; ++j)
      schur(i, j) += a.coeff(added[static_cast<std::size_t>(i)], added[static_cast<std::size_t>(j)]) + (i == j ? shift : 0.0);
  Vector rhs = -u.transpose() * z0;
  for (Eigen::Index i = 0; i < nd; ++i) rhs(i) += c(added[static_cast<std::size_t>(i)]);
  Eigen::FullPivLU<Eigen::MatrixXd> lu(schur);
  lu.setThreshold(settings_.rank_tolerance);
  if (lu.rank() < size) return false;  // numerically singular: refactor
  const Vector sol = lu.solve(rhs);
  Vector out = z0 - y * sol;
  for (RowIndex r : removed) out(r) = 0.0;
  for (Eigen::Index j = 0; j < nd; ++j) out(added[static_cast<std::size_t>(j)]) = sol(j);
  // Accept only if the active rows hold to rounding (the update is as exact as a refactorization).
  const Vector residual = a * out + shift * out - c;
  double worst = 0.0, size_c = 0.0;
  for (std::size_t k = 0; k < active.size(); ++k)
    if (active[k]) {
      worst = std::max(worst, std::abs(residual(static_cast<Eigen::Index>(k))));
      size_c = std::max(size_c, std::abs(c(static_cast<Eigen::Index>(k))));
    }
  if (!(worst <= 1e-10 * size_c + std::numeric_limits<double>::min())) return false;
  p = std::move(out);
  ++stats.updated;
  return true;
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
    if (changes <= settings_.update_limit && solve_updated(loop, a, shift, r, active, z, stats)) return z;
  }
  ++stats.sparse;
  loop.factor->factorize(a, active, settings_.rank_tolerance, loop.floor, shift);
  loop.factored = true;
  loop.singular = loop.singular || loop.factor->redundant_rows(shift) > 0;
  for (std::size_t k = 0; k < active.size(); ++k) loop.in_base[k] = active[k] && !loop.factor->dropped(k);
  Vector z = r;
  loop.factor->solve(z);
  return z;
}

// The complementarity problem is the optimality condition of the convex QP
//   minimize ½ pᵀA p − cᵀp  subject to p_k ≥ 0 on inequality rows   (gradient A p − c = w).
// A is only positive semi-definite (redundant contacts: the paper's Figure 2, a pyramid's horizontal
// contacts), so it is solved by a proximal-point iteration: each outer iteration solves the strictly
// convex problem
//   minimize ½ pᵀ(A + εI) p − (c + ε p̄)ᵀp,  p ≥ 0,   p̄ = the previous outer solution,
// ε = regularization · max A_kk. Its free rows F are solved as equalities by one exact solve
// ((A + εI)_FF is positive definite: no rank test, no null space). Its active set: block principal
// pivoting (Júdice & Pires: every infeasible row exchanged at once — free rows with a negative impulse
// leave F, rows at zero that would approach join it) while the number of infeasible rows falls; then
// the primal active-set method from p = 0 (an infeasible minimizer is approached until the first free
// row reaches zero, the rows at zero are released; a feasible one becomes p and the rows approaching
// fastest join), whose objective strictly decreases between feasible minimizers, so it terminates.
// Each outer iteration starts from the last F, so after the first one it is usually a single solve with
// the same factorization. On F, w = A p − c = −ε (p − p̄), which shrinks by a factor ε/(λ + ε) per
// outer iteration for every non-zero eigenvalue λ of A_FF; the iteration stops when
// ε |p − p̄| ≤ 1e-3 · tolerance (or rounding): p ≥ 0, w ≥ −tolerance everywhere, |w| ≤ 1e-3 tolerance on
// F. The impulses' component in the null space of A (a self-equilibrated split among redundant
// contacts, which moves nothing) stays near zero, i.e. near the minimum-norm split. If the outer
// residual stops shrinking short of the tolerance (conflicting targets: no exact solution),
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
  const double scale = Vector(a.diagonal()).maxCoeff();
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
  const double shift = settings_.regularization * scale;
  ActiveLoop loop;
  loop.factor = checkout_masked(a, stats);
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
    // The proximal subproblem is solved; is p exact for the problem itself?
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

// The earlier method, kept as the fallback for problems the proximal iteration cannot finish (an
// inconsistent singular system: conflicting targets, where the regularized iterates drift): each free
// set solved by minimum-norm least squares, whose residual is then a null direction followed to the
// first bound.
Vector IslandSolver::solve_complementarity_min_norm(const ComplementarityProblem& problem, SolverStats& stats) {
  const SparseMatrix& a = *problem.matrix;
  const auto m = static_cast<std::size_t>(a.rows());
  const Vector& c = problem.rhs;
  const auto inequality = [&](std::size_t k) { return !problem.equality[k]; };
  std::vector<char> free_rows(m);
  for (std::size_t k = 0; k < m; ++k) free_rows[k] = problem.equality[k] || problem.start[k];
  Vector p = Vector::Zero(a.rows());
  bool converged = false, not_finite = false, infeasible = false;
  for (std::uint64_t iteration = 0; iteration < settings_.max_iterations; ++iteration) {
    ++stats.iterations;
    const std::uint64_t singular_before = stats.singular;
    const std::vector<RowIndex> rows = members(free_rows);
    Vector z = Vector::Zero(a.rows());
    {
      const Vector part = solve_system(principal_submatrix(a, rows), gather(c, rows), stats);
      for (std::size_t i = 0; i < rows.size(); ++i) z(rows[i]) = part(static_cast<Eigen::Index>(i));
    }
    const bool singular = stats.singular != singular_before;
    if (!z.allFinite()) {
      ++stats.nan_caught;
      p.setZero();
      not_finite = true;
      break;
    }
    // A singular system with an inconsistent right-hand side has no minimizer on F: the objective falls
    // without bound along the residual d = c − A z (a null direction). Follow it to the first bound.
    Vector d = c - a * z;
    double inconsistency = 0.0;
    for (std::size_t k = 0; k < m; ++k)
      if (free_rows[k]) inconsistency = std::max(inconsistency, std::abs(d(static_cast<Eigen::Index>(k))));
      else d(static_cast<Eigen::Index>(k)) = 0.0;
    bool along_null = singular && inconsistency > 0.5 * problem.tolerance;
    if (along_null) {  // keep d's clear components; if none is on an inequality row, z is the answer on F
      along_null = false;
      for (std::size_t k = 0; k < m; ++k) {
        double& dk = d(static_cast<Eigen::Index>(k));
        if (std::abs(dk) < 1e-6 * inconsistency) dk = 0.0;
        along_null = along_null || (inequality(k) && dk != 0.0);
      }
    }
    Vector direction;  // p moves along `direction` by the ratio test, or p = z
    const double roundoff = kImpulseRoundoff * z.lpNorm<Eigen::Infinity>();
    if (along_null) {
      direction = d;
    } else {
      bool feasible = true;
      for (std::size_t k = 0; k < m; ++k)
        if (free_rows[k] && inequality(k) && z(static_cast<Eigen::Index>(k)) < -roundoff) feasible = false;
      if (!feasible) direction = z - p;
    }
    if (direction.size() > 0) {
      // Ratio test: the largest step keeping every free inequality row ≥ 0.
      double step = std::numeric_limits<double>::infinity();
      std::size_t blocking = m;
      for (std::size_t k = 0; k < m; ++k) {
        const auto i = static_cast<Eigen::Index>(k);
        if (!free_rows[k] || !inequality(k) || !(direction(i) < 0.0)) continue;
        const double ratio = std::max(0.0, p(i)) / -direction(i);
        if (ratio < step) step = ratio, blocking = k;
      }
      if (blocking == m) {  // the objective falls without bound: the problem has no solution
        infeasible = true;
        ++stats.infeasible;
        break;
      }
      if (!along_null) step = std::min(step, 1.0);
      p += step * direction;
      const double floor = kImpulseRoundoff * p.lpNorm<Eigen::Infinity>();
      for (std::size_t k = 0; k < m; ++k) {
        const auto i = static_cast<Eigen::Index>(k);
        const bool falling = along_null ? direction(i) < 0.0 : z(i) < -roundoff;
        if (free_rows[k] && inequality(k) && (k == blocking || (falling && p(i) <= floor))) {
          free_rows[k] = 0;
          p(i) = 0.0;
          ++stats.released;
        }
      }
      continue;
    }
    p = z;
    // Add every row at zero that would approach.
    const Vector w = a * p - c;
    bool added = false;
    for (std::size_t k = 0; k < m; ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      if (inequality(k) && free_rows[k]) p(i) = std::max(p(i), 0.0);  // rounding below zero
      if (!free_rows[k] && w(i) < -problem.tolerance) {
        free_rows[k] = 1;
        added = true;
        ++stats.added;
      }
    }
    if (!added) {
      converged = true;
      break;
    }
  }
  if (!converged && !not_finite && !infeasible) ++stats.non_converged;
  for (std::size_t k = 0; k < m; ++k)
    if (inequality(k)) p(static_cast<Eigen::Index>(k)) = free_rows[k] ? std::max(p(static_cast<Eigen::Index>(k)), 0.0) : 0.0;
  return p;
}

// The redundant rows' share of the impulse is not unique; where the system is small enough to afford
// it, take the minimum-norm one (the paper's choice for its Figure 2: the impulse shared equally among
// collinear contacts) if it keeps every impulse ≥ 0. It changes no velocity: p − p_min is a
// self-equilibrated impulse set (A (p − p_min) = 0).
void IslandSolver::polish_minimum_norm(const SparseMatrix& a, const Vector& c, std::vector<char> rows,
                                       const ComplementarityProblem& problem, Vector& p, SolverStats& stats) {
  for (std::size_t k = 0; k < rows.size(); ++k)  // rows at zero with w = 0 may share the impulse too
    if (!rows[k] && !problem.equality[k]) {
      double w = -c(static_cast<Eigen::Index>(k));
      for (SparseMatrix::InnerIterator it(a, static_cast<Eigen::Index>(k)); it; ++it) w += it.value() * p(it.row());
      rows[k] = std::abs(w) <= 0.5 * problem.tolerance;
    }
  const std::vector<RowIndex> members_f = members(rows);
  if (members_f.size() < 2 || members_f.size() > settings_.polish_limit) return;
  SolverStats ignored;
  const SparseMatrix sub = principal_submatrix(a, members_f);
  const Vector q = solve_dense_matrix(Eigen::MatrixXd(sub), gather(c, members_f), ignored);
  const double roundoff = kImpulseRoundoff * q.lpNorm<Eigen::Infinity>();
  for (std::size_t i = 0; i < members_f.size(); ++i)
    if (!problem.equality[members_f[i]] && q(static_cast<Eigen::Index>(i)) < -roundoff) return;
  if (!q.allFinite()) return;
  Vector candidate = p;
  for (std::size_t i = 0; i < members_f.size(); ++i)
    candidate(members_f[i]) = problem.equality[members_f[i]] ? q(static_cast<Eigen::Index>(i))
                                                            : std::max(0.0, q(static_cast<Eigen::Index>(i)));
  // Same velocities to rounding, or keep the basic solution.
  const Vector change = a * (candidate - p);
  if (change.lpNorm<Eigen::Infinity>() > 0.5 * problem.tolerance) return;
  p = std::move(candidate);
  ++stats.polished;
}

IslandSolver::FactorPtr IslandSolver::checkout(const SparseMatrix& m, SolverStats& stats) {
  const auto same_pattern = [&](const Factor& f) {
    return f.outer.size() == static_cast<std::size_t>(m.cols()) + 1 &&
           f.inner.size() == static_cast<std::size_t>(m.nonZeros()) &&
           std::equal(f.outer.begin(), f.outer.end(), m.outerIndexPtr()) &&
           std::equal(f.inner.begin(), f.inner.end(), m.innerIndexPtr());
  };
  for (auto it = cache_.begin(); it != cache_.end(); ++it) {
    if (same_pattern(**it)) {
      FactorPtr f = *it;
      cache_.erase(it);
      ++stats.symbolic_reused;
      return f;
    }
  }
  auto f = std::make_shared<Factor>();
  f->ldlt.analyzePattern(m);
  f->outer.assign(m.outerIndexPtr(), m.outerIndexPtr() + m.cols() + 1);
  f->inner.assign(m.innerIndexPtr(), m.innerIndexPtr() + m.nonZeros());
  ++stats.symbolic_analyses;
  return f;
}

void IslandSolver::checkin(FactorPtr factor) {
  cache_.push_back(std::move(factor));  // most recently used last
  if (cache_.size() > kCacheCapacity) cache_.erase(cache_.begin());
}

std::unique_ptr<MaskedLdlt> IslandSolver::checkout_masked(const SparseMatrix& m, SolverStats& stats) {
  for (auto it = masked_cache_.begin(); it != masked_cache_.end(); ++it) {
    if ((*it)->same_pattern(m)) {
      std::unique_ptr<MaskedLdlt> f = std::move(*it);
      masked_cache_.erase(it);
      ++stats.symbolic_reused;
      return f;
    }
  }
  auto f = std::make_unique<MaskedLdlt>();
  f->analyze(m);
  ++stats.symbolic_analyses;
  return f;
}

void IslandSolver::checkin_masked(std::unique_ptr<MaskedLdlt> factor) {
  masked_cache_.push_back(std::move(factor));  // most recently used last
  if (masked_cache_.size() > kCacheCapacity) masked_cache_.erase(masked_cache_.begin());
}

}  // namespace impetus::ledas
