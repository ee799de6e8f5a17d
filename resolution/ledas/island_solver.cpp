#include "ledas/island_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus::ledas {

namespace {
// Factorizations kept for reuse of their symbolic analysis (distinct sparsity patterns).
constexpr std::size_t kCacheCapacity = 16;
// An impulse this far below zero, relative to the largest one, is rounding, not a pulling impulse.
constexpr double kImpulseRoundoff = 1e-12;

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
  const Vector part = solve_system(principal_submatrix(a, subset), gather(c, subset), stats, nullptr);
  Vector p = Vector::Zero(a.rows());
  for (std::size_t i = 0; i < subset.size(); ++i) p(subset[i]) = part(static_cast<Eigen::Index>(i));
  return p;
}

// Chooses the cheapest exact method for one system (see the header).
Vector IslandSolver::solve_system(const SparseMatrix& m, const Vector& rhs, SolverStats& stats, FactorPtr* keep) {
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
  if (static_cast<std::size_t>(n) <= settings_.dense_limit) return solve_dense(m, rhs, pivot_floor, stats);
  return solve_sparse(m, rhs, pivot_floor, stats, keep);
}

Vector IslandSolver::solve_dense(const SparseMatrix& m, const Vector& rhs, double pivot_floor, SolverStats& stats) {
  ++stats.dense;
  const Eigen::MatrixXd a(m);
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
                                  SolverStats& stats, FactorPtr* keep) {
  ++stats.sparse;
  FactorPtr f = checkout(m, stats);
  f->ldlt.setShift(0.0);
  f->ldlt.factorize(m);
  const Vector d = f->ldlt.info() == Eigen::Success ? Vector(f->ldlt.vectorD()) : Vector::Zero(1);
  const auto small_pivots = static_cast<Eigen::Index>((d.array() <= pivot_floor).count());
  if (small_pivots == 0) {
    Vector p = f->ldlt.solve(rhs);
    if (keep) *keep = f;
    else checkin(f);
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

// The active set changed from the base's rows B to W = (B \ R) ∪ D by a few rows. With the base
// factorization F of A_BB, p_R = 0 is imposed by multipliers μ on the rows R and the new rows D
// border the system:
//   A_BB p_B + A_BD p_D + E_R μ = c_B,   A_DB p_B + A_DD p_D = c_D,   E_Rᵀ p_B = 0.
// With U = [A_BD, E_R], p_B = F⁻¹(c_B − U y) for y = (p_D, μ), and y solves the small Schur system
//   ([A_DD 0; 0 0] − Uᵀ F⁻¹ U) y = (c_D, 0) − Uᵀ F⁻¹ c_B.
bool IslandSolver::solve_updated(const Factor& base, const std::vector<char>& in_base, const SparseMatrix& a,
                                 const Vector& c, const std::vector<char>& active, Vector& p,
                                 SolverStats& stats) const {
  std::vector<RowIndex> base_rows, added, removed;
  std::vector<Eigen::Index> in_b(active.size(), -1);
  for (std::size_t k = 0; k < active.size(); ++k) {
    if (in_base[k]) {
      in_b[k] = static_cast<Eigen::Index>(base_rows.size());
      base_rows.push_back(static_cast<RowIndex>(k));
    }
    if (active[k] && !in_base[k]) added.push_back(static_cast<RowIndex>(k));
    if (!active[k] && in_base[k]) removed.push_back(static_cast<RowIndex>(k));
  }
  const auto nb = static_cast<Eigen::Index>(base_rows.size());
  const auto nd = static_cast<Eigen::Index>(added.size());
  const auto size = nd + static_cast<Eigen::Index>(removed.size());
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(nb, size);
  for (Eigen::Index j = 0; j < nd; ++j)
    for (SparseMatrix::InnerIterator it(a, added[static_cast<std::size_t>(j)]); it; ++it)
      if (const Eigen::Index i = in_b[static_cast<std::size_t>(it.row())]; i >= 0) u(i, j) = it.value();
  for (std::size_t j = 0; j < removed.size(); ++j) u(in_b[removed[j]], nd + static_cast<Eigen::Index>(j)) = 1.0;

  const Eigen::MatrixXd y = base.ldlt.solve(u);
  const Vector z0 = base.ldlt.solve(gather(c, base_rows));
  Eigen::MatrixXd schur = -u.transpose() * y;
  for (Eigen::Index i = 0; i < nd; ++i)
    for (Eigen::Index j = 0; j < nd; ++j)
      schur(i, j) += a.coeff(added[static_cast<std::size_t>(i)], added[static_cast<std::size_t>(j)]);
  Vector rhs = -u.transpose() * z0;
  for (Eigen::Index i = 0; i < nd; ++i) rhs(i) += c(added[static_cast<std::size_t>(i)]);
  Eigen::FullPivLU<Eigen::MatrixXd> lu(schur);
  lu.setThreshold(settings_.rank_tolerance);
  if (lu.rank() < size) return false;  // W is (nearly) singular: refactor and take the minimum norm
  const Vector sol = lu.solve(rhs);
  const Vector pb = z0 - y * sol;

  Vector out = Vector::Zero(a.rows());
  for (Eigen::Index i = 0; i < nb; ++i) out(base_rows[static_cast<std::size_t>(i)]) = pb(i);
  for (RowIndex r : removed) out(r) = 0.0;
  for (Eigen::Index j = 0; j < nd; ++j) out(added[static_cast<std::size_t>(j)]) = sol(j);
  // Accept only if the active rows hold to rounding (the update is as exact as a refactorization).
  const Vector residual = a * out - c;
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

// Solves the active rows as equalities: by updating the last sparse factorization when only a few rows
// changed, else by the cheapest exact method (which may become the new base).
Vector IslandSolver::solve_active(const SparseMatrix& a, const Vector& c, const std::vector<char>& active,
                                  ActiveBase& base, SolverStats& stats) {
  if (base.factor) {
    std::size_t changes = 0;
    for (std::size_t k = 0; k < active.size(); ++k) changes += active[k] != base.rows[k];
    Vector z;
    if (changes <= settings_.update_limit && solve_updated(*base.factor, base.rows, a, c, active, z, stats)) return z;
  }
  const std::vector<RowIndex> rows = members(active);
  FactorPtr kept;
  const Vector part = solve_system(principal_submatrix(a, rows), gather(c, rows), stats, &kept);
  Vector z = Vector::Zero(a.rows());
  for (std::size_t i = 0; i < rows.size(); ++i) z(rows[i]) = part(static_cast<Eigen::Index>(i));
  if (kept) {
    if (base.factor) checkin(base.factor);
    base.factor = kept;
    base.rows = active;
  }
  return z;
}

// A primal active-set method for the convex QP whose optimality conditions are the problem:
//   minimize ½ pᵀA p − cᵀp  subject to p_k ≥ 0 on inequality rows   (gradient A p − c = w).
// The iterate p is always feasible. Each iteration minimizes over the free rows F (solved as
// equalities, minimum norm if singular); an infeasible minimizer z is approached until the first free
// row reaches zero, and the rows that reach zero are released; a feasible one becomes p, and every
// row at zero whose w is below −tolerance joins F at once. The objective never increases and strictly
// decreases between feasible minimizers, so no set of free rows repeats: it terminates (Lawson–Hanson
// style, with block additions), also for singular A where block pivoting can cycle. Starting from
// p = 0 with F = the start set, a first minimizer with negative entries releases all of them at once.
Vector IslandSolver::solve_complementarity(const ComplementarityProblem& problem, SolverStats& stats) {
  const SparseMatrix& a = *problem.matrix;
  const auto m = static_cast<std::size_t>(a.rows());
  const Vector& c = problem.rhs;
  const auto inequality = [&](std::size_t k) { return !problem.equality[k]; };
  std::vector<char> free_rows(m);
  for (std::size_t k = 0; k < m; ++k) free_rows[k] = problem.equality[k] || problem.start[k];
  Vector p = Vector::Zero(a.rows());
  ActiveBase base;
  bool converged = false, not_finite = false;
  for (std::uint64_t iteration = 0; iteration < settings_.max_iterations; ++iteration) {
    ++stats.iterations;
    const std::uint64_t singular_before = stats.singular;
    Vector z = solve_active(a, c, free_rows, base, stats);
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
      if (blocking == m) break;  // the objective falls without bound: the problem has no solution
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
  if (base.factor) checkin(base.factor);
  if (!converged && !not_finite) ++stats.non_converged;
  for (std::size_t k = 0; k < m; ++k)
    if (inequality(k)) p(static_cast<Eigen::Index>(k)) = free_rows[k] ? std::max(p(static_cast<Eigen::Index>(k)), 0.0) : 0.0;
  return p;
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

}  // namespace impetus::ledas
