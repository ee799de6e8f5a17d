// The bordered (Schur-complement) update of a masked factorization; bordered_update.hpp derives it.
#include "bordered_update.hpp"
#include "impetus/resolution/ledas/masked_ldlt.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace impetus::ledas {

void BorderedUpdate::forget() {
  for (std::size_t k = 0; k < border_of_.size(); ++k) border_of_[k] = -1;
  border_count_ = 0;  // the borders' storage is kept for the next ones
  updated_ = false;
}

bool BorderedUpdate::solve(const MaskedLdlt& factor, const std::vector<char>& in_base, const SparseMatrix& a,
                           double shift, const Vector& c, const std::vector<char>& active, double rank_tolerance,
                           Vector& p) {
  if (solves_for(active)) {  // the same active set as the last update: reuse it
    apply(factor, c, p);
    return true;
  }
  updated_ = false;
  added_.clear();
  removed_.clear();
  for (std::size_t k = 0; k < active.size(); ++k) {
    if (active[k] && !in_base[k]) added_.push_back(static_cast<RowIndex>(k));
    if (!active[k] && in_base[k]) removed_.push_back(static_cast<RowIndex>(k));
  }
  const auto nd = static_cast<Eigen::Index>(added_.size());
  const auto size = nd + static_cast<Eigen::Index>(removed_.size());
  if (size == 0) return false;
  slots_.clear();
  for (RowIndex d : added_) slots_.push_back(border(factor, in_base, a, d));
  for (RowIndex r : removed_) slots_.push_back(border(factor, in_base, a, r));
  const auto n = static_cast<std::size_t>(size);
  if (schur_.size() <= n) {
    schur_matrix_.resize(n + 1);
    schur_.resize(n + 1);
  }
  Eigen::MatrixXd& schur = schur_matrix_[n];  // S = [(A + εI)_DD 0; 0 0] − Wᵀ D⁻¹ W
  schur.resize(size, size);
  for (Eigen::Index j = 0; j < size; ++j)
    for (Eigen::Index i = 0; i < size; ++i) schur(i, j) = -gram_(slots_[static_cast<std::size_t>(i)], slots_[static_cast<std::size_t>(j)]);
  for (Eigen::Index j = 0; j < nd; ++j) {
    schur(j, j) += shift;
    for (SparseMatrix::InnerIterator it(a, added_[static_cast<std::size_t>(j)]); it; ++it)
      if (active[static_cast<std::size_t>(it.row())] && !in_base[static_cast<std::size_t>(it.row())]) {
        const auto i = std::lower_bound(added_.begin(), added_.end(), static_cast<RowIndex>(it.row())) - added_.begin();
        schur(i, j) += it.value();
      }
  }
  Eigen::FullPivLU<Eigen::MatrixXd>& lu = schur_[n];
  lu.compute(schur);
  lu.setThreshold(rank_tolerance);
  if (lu.rank() < size) return false;  // numerically singular: refactor
  Vector& out = out_;
  apply(factor, c, out);
  // Accept only if the active rows hold to rounding (the update is as exact as a refactorization).
  Vector& residual = residual_;
  residual.noalias() = a * out;
  residual += shift * out - c;
  double worst = 0.0, size_c = 0.0;
  for (std::size_t k = 0; k < active.size(); ++k)
    if (active[k]) {
      worst = std::max(worst, std::abs(residual(static_cast<Eigen::Index>(k))));
      size_c = std::max(size_c, std::abs(c(static_cast<Eigen::Index>(k))));
    }
  if (!(worst <= 1e-10 * size_c + std::numeric_limits<double>::min())) return false;
  updated_ = true;
  updated_for_ = active;
  p = out;
  return true;
}

int BorderedUpdate::border(const MaskedLdlt& factor, const std::vector<char>& in_base, const SparseMatrix& a,
                           RowIndex row) {
  if (border_of_.size() != static_cast<std::size_t>(a.rows())) border_of_.assign(static_cast<std::size_t>(a.rows()), -1);
  if (const int known = border_of_[row]; known >= 0) return known;
  std::vector<std::pair<int, double>>& u = column_;
  u.clear();
  if (in_base[row]) {
    u.emplace_back(static_cast<int>(row), 1.0);
  } else {
    for (SparseMatrix::InnerIterator it(a, row); it; ++it)
      if (in_base[static_cast<std::size_t>(it.row())]) u.emplace_back(static_cast<int>(it.row()), it.value());
  }
  if (borders_.size() == border_count_) borders_.emplace_back();
  Border& w = borders_[border_count_];
  factor.forward_sparse(u, w.index, w.value);
  // G_jk = w_jᵀ D⁻¹ w_k against every earlier border, by scattering D⁻¹ w into a dense vector (zero
  // between calls: only w's entries are set, and cleared again below).
  const auto count = static_cast<Eigen::Index>(border_count_);
  if (scattered_.size() != static_cast<Eigen::Index>(factor.rows()))
    scattered_.setZero(static_cast<Eigen::Index>(factor.rows()));
  double self = 0.0;
  for (std::size_t q = 0; q < w.index.size(); ++q) {
    const double scaled = w.value[q] * factor.pivot_inverse(w.index[q]);
    scattered_(w.index[q]) = scaled;
    self += scaled * w.value[q];
  }
  if (gram_.rows() <= count) gram_.conservativeResize(2 * count + 8, 2 * count + 8);  // capacity, doubling
  for (Eigen::Index j = 0; j < count; ++j) {
    const Border& other = borders_[static_cast<std::size_t>(j)];
    double dot = 0.0;
    for (std::size_t q = 0; q < other.index.size(); ++q) dot += other.value[q] * scattered_(other.index[q]);
    gram_(j, count) = gram_(count, j) = dot;
  }
  gram_(count, count) = self;
  for (const int i : w.index) scattered_(i) = 0.0;
  ++border_count_;
  border_of_[row] = static_cast<int>(count);
  return static_cast<int>(count);
}

void BorderedUpdate::apply(const MaskedLdlt& factor, const Vector& c, Vector& out) {
  const auto nd = static_cast<Eigen::Index>(added_.size());
  const auto size = static_cast<Eigen::Index>(slots_.size());
  Vector& t = forward_;
  factor.forward(c, t);  // t = L⁻¹ P c_B
  std::vector<double>& rhs = rhs_;  // (c_D, 0) − Wᵀ D⁻¹ t
  rhs.resize(static_cast<std::size_t>(size));
  for (Eigen::Index j = 0; j < size; ++j) {
    const Border& w = borders_[static_cast<std::size_t>(slots_[static_cast<std::size_t>(j)])];
    double dot = 0.0;
    for (std::size_t q = 0; q < w.index.size(); ++q) dot += w.value[q] * factor.pivot_inverse(w.index[q]) * t(w.index[q]);
    rhs[static_cast<std::size_t>(j)] = (j < nd ? c(added_[static_cast<std::size_t>(j)]) : 0.0) - dot;
  }
  std::vector<double>& y = y_;
  y.resize(static_cast<std::size_t>(size));
  solve_schur(rhs, y);
  for (Eigen::Index j = 0; j < size; ++j) {  // t − W y
    const Border& w = borders_[static_cast<std::size_t>(slots_[static_cast<std::size_t>(j)])];
    for (std::size_t q = 0; q < w.index.size(); ++q) t(w.index[q]) -= w.value[q] * y[static_cast<std::size_t>(j)];
  }
  out.resize(c.size());
  factor.backward(t, out);  // p_B = Pᵀ L⁻ᵀ D⁻¹ (t − W y); zero off B
  for (RowIndex r : removed_) out(r) = 0.0;
  for (Eigen::Index j = 0; j < nd; ++j) out(added_[static_cast<std::size_t>(j)]) = y[static_cast<std::size_t>(j)];
}

// S y = rhs with S = P⁻¹ L U Q⁻¹ (Eigen's FullPivLU, full rank: checked before use): y = Q U⁻¹ L⁻¹ P rhs,
// the triangular solves column by column, as Eigen's own solve() does them, but in the update's buffers.
void BorderedUpdate::solve_schur(std::span<const double> rhs, std::span<double> y) {
  const Eigen::FullPivLU<Eigen::MatrixXd>& lu = schur_[rhs.size()];
  const Eigen::MatrixXd& f = lu.matrixLU();
  const auto n = static_cast<Eigen::Index>(rhs.size());
  std::vector<double>& z = permuted_;
  z.resize(rhs.size());
  for (Eigen::Index i = 0; i < n; ++i) z[static_cast<std::size_t>(lu.permutationP().indices()(i))] = rhs[static_cast<std::size_t>(i)];
  for (Eigen::Index k = 0; k < n; ++k)  // L (unit diagonal)
    for (Eigen::Index i = k + 1; i < n; ++i) z[static_cast<std::size_t>(i)] -= z[static_cast<std::size_t>(k)] * f(i, k);
  for (Eigen::Index k = n; k-- > 0;) {  // U
    z[static_cast<std::size_t>(k)] /= f(k, k);
    for (Eigen::Index i = 0; i < k; ++i) z[static_cast<std::size_t>(i)] -= z[static_cast<std::size_t>(k)] * f(i, k);
  }
  for (Eigen::Index i = 0; i < n; ++i) y[static_cast<std::size_t>(lu.permutationQ().indices()(i))] = z[static_cast<std::size_t>(i)];
}

}  // namespace impetus::ledas
