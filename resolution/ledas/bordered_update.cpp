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
  borders_.clear();
  gram_.resize(0, 0);
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
  Eigen::MatrixXd schur(size, size);  // S = [(A + εI)_DD 0; 0 0] − Wᵀ D⁻¹ W
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
  schur_.compute(schur);
  schur_.setThreshold(rank_tolerance);
  if (schur_.rank() < size) return false;  // numerically singular: refactor
  Vector out;
  apply(factor, c, out);
  // Accept only if the active rows hold to rounding (the update is as exact as a refactorization).
  const Vector residual = a * out + shift * out - c;
  double worst = 0.0, size_c = 0.0;
  for (std::size_t k = 0; k < active.size(); ++k)
    if (active[k]) {
      worst = std::max(worst, std::abs(residual(static_cast<Eigen::Index>(k))));
      size_c = std::max(size_c, std::abs(c(static_cast<Eigen::Index>(k))));
    }
  if (!(worst <= 1e-10 * size_c + std::numeric_limits<double>::min())) return false;
  updated_ = true;
  updated_for_ = active;
  p = std::move(out);
  return true;
}

int BorderedUpdate::border(const MaskedLdlt& factor, const std::vector<char>& in_base, const SparseMatrix& a,
                           RowIndex row) {
  if (border_of_.size() != static_cast<std::size_t>(a.rows())) border_of_.assign(static_cast<std::size_t>(a.rows()), -1);
  if (const int known = border_of_[row]; known >= 0) return known;
  std::vector<std::pair<int, double>> u;
  if (in_base[row]) {
    u.emplace_back(static_cast<int>(row), 1.0);
  } else {
    for (SparseMatrix::InnerIterator it(a, row); it; ++it)
      if (in_base[static_cast<std::size_t>(it.row())]) u.emplace_back(static_cast<int>(it.row()), it.value());
  }
  Border w;
  factor.forward_sparse(u, w.index, w.value);
  // G_jk = w_jᵀ D⁻¹ w_k against every earlier border, by scattering D⁻¹ w into a dense vector (zero
  // between calls: only w's entries are set, and cleared again below).
  const auto count = static_cast<Eigen::Index>(borders_.size());
  if (scattered_.size() != static_cast<Eigen::Index>(factor.rows()))
    scattered_.setZero(static_cast<Eigen::Index>(factor.rows()));
  double self = 0.0;
  for (std::size_t q = 0; q < w.index.size(); ++q) {
    const double scaled = w.value[q] * factor.pivot_inverse(w.index[q]);
    scattered_(w.index[q]) = scaled;
    self += scaled * w.value[q];
  }
  gram_.conservativeResize(count + 1, count + 1);
  for (Eigen::Index j = 0; j < count; ++j) {
    const Border& other = borders_[static_cast<std::size_t>(j)];
    double dot = 0.0;
    for (std::size_t q = 0; q < other.index.size(); ++q) dot += other.value[q] * scattered_(other.index[q]);
    gram_(j, count) = gram_(count, j) = dot;
  }
  gram_(count, count) = self;
  for (const int i : w.index) scattered_(i) = 0.0;
  borders_.push_back(std::move(w));
  border_of_[row] = static_cast<int>(count);
  return static_cast<int>(count);
}

void BorderedUpdate::apply(const MaskedLdlt& factor, const Vector& c, Vector& out) {
  const auto nd = static_cast<Eigen::Index>(added_.size());
  const auto size = static_cast<Eigen::Index>(slots_.size());
  Vector& t = forward_;
  factor.forward(c, t);  // t = L⁻¹ P c_B
  Vector rhs(size);      // (c_D, 0) − Wᵀ D⁻¹ t
  for (Eigen::Index j = 0; j < size; ++j) {
    const Border& w = borders_[static_cast<std::size_t>(slots_[static_cast<std::size_t>(j)])];
    double dot = 0.0;
    for (std::size_t q = 0; q < w.index.size(); ++q) dot += w.value[q] * factor.pivot_inverse(w.index[q]) * t(w.index[q]);
    rhs(j) = (j < nd ? c(added_[static_cast<std::size_t>(j)]) : 0.0) - dot;
  }
  const Vector y = schur_.solve(rhs);
  for (Eigen::Index j = 0; j < size; ++j) {  // t − W y
    const Border& w = borders_[static_cast<std::size_t>(slots_[static_cast<std::size_t>(j)])];
    for (std::size_t q = 0; q < w.index.size(); ++q) t(w.index[q]) -= w.value[q] * y(j);
  }
  out.resize(c.size());
  factor.backward(t, out);  // p_B = Pᵀ L⁻ᵀ D⁻¹ (t − W y); zero off B
  for (RowIndex r : removed_) out(r) = 0.0;
  for (Eigen::Index j = 0; j < nd; ++j) out(added_[static_cast<std::size_t>(j)]) = y(j);
}

}  // namespace impetus::ledas
