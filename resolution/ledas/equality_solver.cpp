// The paper mode's rounds (sec. 3.2): eq. 6, A_SS p = c_S, as equalities on a subset of an island's
// rows, each independent block by the cheapest exact method (island_solver.hpp), the minimum-norm
// least-squares solution where a block is rank-deficient (the paper's Figure 2 and its SVD remark).
#include "equality_solver.hpp"
#include "solver_internal.hpp"

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>

namespace impetus::ledas {

namespace {
// Factorizations kept for reuse of their symbolic analysis (distinct sparsity patterns).
constexpr std::size_t kCacheCapacity = 16;
// The rounding allowed in the normal equations A (A p − c) = 0 of a minimum-norm answer, relative to
// n · max A_ii · (max A_ii ‖p‖∞ + ‖c‖∞) (minimum_norm_from_ldlt).
constexpr double kNormalEquationsRoundoff = 1e-12;

// A rank-deficient system is counted in `singular`; it is a real failure (`inconsistent`) only when the
// returned impulses do not satisfy it. Redundant contacts (a box on four corners) give a consistent
// system: the minimum-norm split meets every target, and nothing failed.
void count_singular(bool failed, SolverStats& stats) {
  ++stats.singular;
  if (failed) ++stats.inconsistent;
}

// Whether A p = c holds to well above the rank tolerance's rounding (relative to the targets), i.e. the
// targets were consistent and the minimum-norm solution met them.
bool satisfies(const Vector& ap, const Vector& c) {
  return (ap - c).lpNorm<Eigen::Infinity>() <= 1e-6 * c.lpNorm<Eigen::Infinity>();
}
}  // namespace

/// A sparse LDLᵀ (Eigen SimplicialLDLT, AMD ordering) with the pattern its symbolic analysis is for.
struct EqualitySolver::Factor {
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
  std::vector<int> outer, inner;  // the sparsity pattern the symbolic analysis belongs to
};

EqualitySolver::EqualitySolver(const SolverSettings& settings) : settings_(settings) {}
EqualitySolver::~EqualitySolver() = default;

// The subset's rows fall into connected components (rows coupled through A, i.e. through a shared
// movable body); A_SS is block diagonal in them, so each block is solved on its own by the cheapest
// exact method. In the paper's rounds most blocks are one or two rows.
void EqualitySolver::solve_subset(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset, Vector& p,
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
  if (solve_uncoupled(a, c, subset, p, stats)) {
    find_components(a, subset);
    for (int root = 0; root < n; ++root)
      if (w.parent[static_cast<std::size_t>(root)] == root) solve_component(a, c, subset, root, p, stats);
  }
  for (RowIndex k : subset) w.slot[k] = -1;
}

// Rows coupled to no other row of the subset: closed form at once (p = c / A_11, the single-contact
// impulse of the paper's ref. [4]); they leave the component search.
bool EqualitySolver::solve_uncoupled(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset,
                                     Vector& p, SolverStats& stats) {
  Workspace& w = work_;
  const auto n = static_cast<int>(subset.size());
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
      count_singular(c(k) != 0.0, stats);
      p(k) = 0.0;
    }
    w.parent[static_cast<std::size_t>(i)] = -1;
  }
  return coupled;
}

// Union-find over the coupled rows; members of each component in increasing order, components by their
// first row (deterministic).
void EqualitySolver::find_components(const SparseMatrix& a, std::span<const RowIndex> subset) {
  Workspace& w = work_;
  const auto n = static_cast<int>(subset.size());
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
  w.start.assign(subset.size() + 1, 0);
  for (int i = 0; i < n; ++i)
    if (w.parent[static_cast<std::size_t>(i)] >= 0) ++w.start[static_cast<std::size_t>(find(i)) + 1];
  for (std::size_t i = 0; i < subset.size(); ++i) w.start[i + 1] += w.start[i];
  w.members.resize(subset.size());
  w.fill.assign(w.start.begin(), w.start.end() - 1);
  for (int i = 0; i < n; ++i)
    if (w.parent[static_cast<std::size_t>(i)] >= 0) w.members[static_cast<std::size_t>(w.fill[static_cast<std::size_t>(w.parent[static_cast<std::size_t>(i)])]++)] = i;
}

void EqualitySolver::solve_component(const SparseMatrix& a, const Vector& c, std::span<const RowIndex> subset,
                                     int root, Vector& p, SolverStats& stats) {
  Workspace& w = work_;
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

// Chooses the cheapest exact method for one system (see the header).
Vector EqualitySolver::solve_system(const SparseMatrix& m, const Vector& rhs, SolverStats& stats) {
  const Eigen::Index n = m.rows();
  if (n == 0) return Vector();
  const double scale = Vector(m.diagonal()).maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) {  // no movable body behind any row: nothing can change
    count_singular(!std::isfinite(scale) || rhs.lpNorm<Eigen::Infinity>() > 0.0, stats);
    return Vector::Zero(n);
  }
  const double pivot_floor = settings_.rank_tolerance * scale;
  if (n == 1) {  // closed form: p = c / A_11 (the single-contact impulse of the paper's ref. [4])
    ++stats.closed_form;
    const double a11 = m.coeff(0, 0);
    if (a11 > pivot_floor) return Vector::Constant(1, rhs(0) / a11);
    count_singular(rhs(0) != 0.0, stats);
    return Vector::Zero(1);
  }
  if (static_cast<std::size_t>(n) <= settings_.dense_limit) return solve_dense_matrix(Eigen::MatrixXd(m), rhs, stats);
  return solve_sparse(m, rhs, pivot_floor, stats);
}

Vector EqualitySolver::solve_dense_matrix(const Eigen::MatrixXd& a, const Vector& rhs, SolverStats& stats) {
  Eigen::LDLT<Eigen::MatrixXd> ldlt;
  Vector p;
  solve_dense_matrix(a, rhs, stats, ldlt, p);
  return p;
}

void EqualitySolver::solve_dense_matrix(const Eigen::MatrixXd& a, const Vector& rhs, SolverStats& stats,
                                        Eigen::LDLT<Eigen::MatrixXd>& ldlt, Vector& p) {
  ++stats.dense;
  const double scale = a.diagonal().maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) {  // no movable body behind any row
    count_singular(!std::isfinite(scale) || rhs.lpNorm<Eigen::Infinity>() > 0.0, stats);
    p.setZero(a.rows());
    return;
  }
  const double pivot_floor = settings_.rank_tolerance * scale;
  // LDLᵀ with diagonal pivoting reveals the rank of a PSD matrix: a dependent row leaves a ~0 pivot.
  ldlt.compute(a);
  if (ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > pivot_floor).all()) {
    p = ldlt.solve(rhs);
    return;
  }
  // Its info() need not be Success: Eigen reports an exact zero pivot over a column that is not exactly
  // zero, a pivot the rank factorization drops anyway (and its answer is checked).
  if (minimum_norm_from_ldlt(a, ldlt, rhs, pivot_floor, p)) {
    count_singular(!satisfies(a * p, rhs), stats);
    return;
  }
  // Minimum-norm least squares through the eigen-decomposition (the SVD of a symmetric PSD matrix).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(a);
  const Vector& lambda = eigen.eigenvalues();
  Vector y = eigen.eigenvectors().transpose() * rhs;
  for (Eigen::Index i = 0; i < y.size(); ++i) y(i) = lambda(i) > pivot_floor ? y(i) / lambda(i) : 0.0;
  p = eigen.eigenvectors() * y;
  count_singular(!satisfies(a * p, rhs), stats);
}

// p = A⁺ c from the pivoted LDLᵀ A = Pᵀ L D Lᵀ P of a PSD matrix: with R the r pivots above the floor
// (Eigen pivots on the diagonal as it was, so they need not come first) and the others dropped,
// A = B D_R Bᵀ with B = Pᵀ L_R, L's columns in R (independent: L is unit lower triangular), and
//     A⁺ = B (BᵀB)⁻¹ D_R⁻¹ (BᵀB)⁻¹ Bᵀ,    BᵀB = L_Rᵀ L_R,
// two r × r Cholesky solves in place of an eigen-decomposition (a tridiagonal reduction and a QR
// iteration): the dense solve, mostly that eigen-decomposition, was 14% of a run of the pile of 100
// primitives in `perf` (a box resting on a face has four corner rows of rank three). Dropping the small pivots is the eigen-decomposition's rank decision made on the pivots, so
// the answer is checked: A (A p − c) must vanish to rounding (the normal equations of least squares),
// else false, p untouched, and the caller takes the eigen-decomposition.
bool EqualitySolver::minimum_norm_from_ldlt(const Eigen::MatrixXd& a, const Eigen::LDLT<Eigen::MatrixXd>& ldlt,
                                            const Vector& rhs, double pivot_floor, Vector& p) {
  const Vector& d = ldlt.vectorD();
  const Eigen::Index n = d.size();
  Eigen::Index r = 0;
  for (Eigen::Index k = 0; k < n; ++k) r += d(k) > pivot_floor;
  if (r == 0) {  // nothing above the floor: A is zero to the rank tolerance
    p.setZero(n);
    return true;
  }
  Eigen::MatrixXd& l = work_.rank_factor;
  l.setZero(n, r);
  const Eigen::MatrixXd& compact = ldlt.matrixLDLT();
  Vector& pivots = work_.pivots;
  pivots.resize(r);
  for (Eigen::Index j = 0, column = 0; j < n; ++j) {
    if (!(d(j) > pivot_floor)) continue;
    l(j, column) = 1.0;
    for (Eigen::Index i = j + 1; i < n; ++i) l(i, column) = compact(i, j);
    pivots(column++) = d(j);
  }
  Eigen::LLT<Eigen::MatrixXd>& gram = work_.gram;
  work_.gram_matrix.noalias() = l.transpose() * l;
  gram.compute(work_.gram_matrix);
  if (gram.info() != Eigen::Success) return false;
  Vector& permuted = work_.permuted;
  permuted = ldlt.transpositionsP() * rhs;  // P c
  Vector& reduced = work_.reduced;
  reduced.noalias() = l.transpose() * permuted;
  gram.solveInPlace(reduced);
  reduced.array() /= pivots.array();
  gram.solveInPlace(reduced);
  permuted.noalias() = l * reduced;
  Vector& candidate = work_.candidate;
  candidate = ldlt.transpositionsP().transpose() * permuted;
  Vector& residual = work_.residual;
  residual.noalias() = a * candidate;
  residual -= rhs;
  const double size = a.diagonal().maxCoeff();
  const double rounding = kNormalEquationsRoundoff * static_cast<double>(n) * size *
                          (size * candidate.lpNorm<Eigen::Infinity>() + rhs.lpNorm<Eigen::Infinity>());
  Vector& normal = work_.normal;
  normal.noalias() = a * residual;
  if (!candidate.allFinite() || !(normal.lpNorm<Eigen::Infinity>() <= rounding)) return false;
  p.swap(candidate);
  return true;
}

namespace {
// Orthonormal basis of the columns of x (thin Q of a Householder QR).
Eigen::MatrixXd orthonormal_columns(const Eigen::MatrixXd& x) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(x);
  return qr.householderQ() * Eigen::MatrixXd::Identity(x.rows(), x.cols());
}
}  // namespace

Vector EqualitySolver::solve_sparse(const SparseMatrix& m, const Vector& rhs, double pivot_floor,
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
  count_singular(!satisfies(m * p, rhs), stats);
  return p;
}

EqualitySolver::FactorPtr EqualitySolver::checkout(const SparseMatrix& m, SolverStats& stats) {
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

void EqualitySolver::checkin(FactorPtr factor) {
  cache_.push_back(std::move(factor));  // most recently used last
  if (cache_.size() > kCacheCapacity) cache_.erase(cache_.begin());
}

}  // namespace impetus::ledas
