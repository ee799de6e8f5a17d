#include "ledas/masked_ldlt.hpp"

#include <Eigen/OrderingMethods>

#include <algorithm>
#include <numeric>

namespace impetus::ledas {

void MaskedLdlt::analyze(const Matrix& a) {
  const auto n = static_cast<int>(a.cols());
  outer_.assign(a.outerIndexPtr(), a.outerIndexPtr() + n + 1);
  inner_.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());

  // Fill-reducing order: approximate minimum degree (Eigen's port of AMD), as SimplicialLDLT does.
  order_.resize(static_cast<std::size_t>(n));
  if (n > 2) {
    Matrix symmetric = a;  // AMD needs both triangles and the diagonal; it destroys its input
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
    Eigen::internal::minimum_degree_ordering(symmetric, perm);
    for (int k = 0; k < n; ++k) order_[static_cast<std::size_t>(k)] = perm.indices()[k];
  } else {
    std::iota(order_.begin(), order_.end(), 0);
  }
  new_of_old_.resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) new_of_old_[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])] = k;

  // Upper triangle of C = P A Pᵀ by columns: column k (new) holds rows i ≤ k.
  c_outer_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int p = outer_[static_cast<std::size_t>(j)]; p < outer_[static_cast<std::size_t>(j) + 1]; ++p) {
      const int i = new_of_old_[static_cast<std::size_t>(inner_[static_cast<std::size_t>(p)])];
      const int k = new_of_old_[static_cast<std::size_t>(j)];
      if (i <= k) ++c_outer_[static_cast<std::size_t>(k) + 1];
    }
  std::partial_sum(c_outer_.begin(), c_outer_.end(), c_outer_.begin());
  c_row_.resize(static_cast<std::size_t>(c_outer_.back()));
  c_value_.resize(c_row_.size());
  std::vector<int> next(c_outer_.begin(), c_outer_.end() - 1);
  for (int j = 0; j < n; ++j)
    for (int p = outer_[static_cast<std::size_t>(j)]; p < outer_[static_cast<std::size_t>(j) + 1]; ++p) {
      const int i = new_of_old_[static_cast<std::size_t>(inner_[static_cast<std::size_t>(p)])];
      const int k = new_of_old_[static_cast<std::size_t>(j)];
      if (i > k) continue;
      const auto q = static_cast<std::size_t>(next[static_cast<std::size_t>(k)]++);
      c_row_[q] = i;
      c_value_[q] = p;
    }

  // Elimination tree and column counts of L (ldl_symbolic).
  parent_.assign(static_cast<std::size_t>(n), -1);
  flag_.assign(static_cast<std::size_t>(n), -1);
  l_count_.assign(static_cast<std::size_t>(n), 0);
  for (int k = 0; k < n; ++k) {
    flag_[static_cast<std::size_t>(k)] = k;
    for (int p = c_outer_[static_cast<std::size_t>(k)]; p < c_outer_[static_cast<std::size_t>(k) + 1]; ++p) {
      for (int i = c_row_[static_cast<std::size_t>(p)]; i < k && flag_[static_cast<std::size_t>(i)] != k;
           i = parent_[static_cast<std::size_t>(i)]) {
        if (parent_[static_cast<std::size_t>(i)] == -1) parent_[static_cast<std::size_t>(i)] = k;
        ++l_count_[static_cast<std::size_t>(i)];
        flag_[static_cast<std::size_t>(i)] = k;
      }
    }
  }
  l_outer_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int k = 0; k < n; ++k)
    l_outer_[static_cast<std::size_t>(k) + 1] = l_outer_[static_cast<std::size_t>(k)] + l_count_[static_cast<std::size_t>(k)];
  l_index_.resize(static_cast<std::size_t>(l_outer_.back()));
  l_value_.resize(l_index_.size());
  d_.assign(static_cast<std::size_t>(n), 1.0);
  diag_.assign(static_cast<std::size_t>(n), 0.0);
  state_.assign(static_cast<std::size_t>(n), kOff);
  y_.assign(static_cast<std::size_t>(n), 0.0);
  pattern_.assign(static_cast<std::size_t>(n), 0);
}

bool MaskedLdlt::same_pattern(const Matrix& a) const {
  return outer_.size() == static_cast<std::size_t>(a.cols()) + 1 &&
         inner_.size() == static_cast<std::size_t>(a.nonZeros()) &&
         std::equal(outer_.begin(), outer_.end(), a.outerIndexPtr()) &&
         std::equal(inner_.begin(), inner_.end(), a.innerIndexPtr());
}

// ldl_numeric, row by row (row k of L from a sparse triangular solve along the elimination tree),
// with rows off F skipped and rows with a vanishing pivot dropped.
std::size_t MaskedLdlt::factorize(const Matrix& a, std::span<const char> on, double rank_tolerance, double floor,
                                  double shift) {
  const auto n = static_cast<int>(order_.size());
  const double* value = a.valuePtr();
  std::size_t dropped = 0;
  for (int k = 0; k < n; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    l_count_[uk] = 0;
    flag_[uk] = k;
    if (!on[static_cast<std::size_t>(order_[uk])]) {
      state_[uk] = kOff;
      d_[uk] = 1.0;
      continue;
    }
    // Scatter column k of C (rows i ≤ k that are in F) and find the pattern of row k of L.
    int top = n;
    double diagonal = 0.0;
    for (int p = c_outer_[uk]; p < c_outer_[uk + 1]; ++p) {
      int i = c_row_[static_cast<std::size_t>(p)];
      const double v = value[c_value_[static_cast<std::size_t>(p)]];
      if (i == k) {
        diagonal += v;
        continue;
      }
      if (state_[static_cast<std::size_t>(i)] != kOn) continue;
      y_[static_cast<std::size_t>(i)] += v;
      int len = 0;
      for (; flag_[static_cast<std::size_t>(i)] != k; i = parent_[static_cast<std::size_t>(i)]) {
        pattern_[static_cast<std::size_t>(len++)] = i;
        flag_[static_cast<std::size_t>(i)] = k;
      }
      while (len > 0) pattern_[static_cast<std::size_t>(--top)] = pattern_[static_cast<std::size_t>(--len)];
    }
    double dk = diagonal + shift;
    const int first = top;
    for (; top < n; ++top) {
      const auto i = static_cast<std::size_t>(pattern_[static_cast<std::size_t>(top)]);
      const double yi = y_[i];
      y_[i] = 0.0;
      if (state_[i] != kOn) continue;  // off or dropped: no entries in its column, nothing to eliminate
      const int end = l_outer_[i] + l_count_[i];
      for (int p = l_outer_[i]; p < end; ++p) y_[static_cast<std::size_t>(l_index_[static_cast<std::size_t>(p)])] -= l_value_[static_cast<std::size_t>(p)] * yi;
      const double lki = yi / d_[i];
      dk -= lki * yi;
      l_index_[static_cast<std::size_t>(end)] = k;
      l_value_[static_cast<std::size_t>(end)] = lki;
      ++l_count_[i];
    }
    diag_[uk] = diagonal;
    if (diagonal <= floor || dk <= rank_tolerance * (diagonal + shift)) {
      // Dependent on the rows before it: take back its entries (the last of each column) and make it an
      // identity row that later rows do not see.
      for (int t = first; t < n; ++t) {
        const auto i = static_cast<std::size_t>(pattern_[static_cast<std::size_t>(t)]);
        if (state_[i] == kOn) --l_count_[i];
      }
      state_[uk] = kDropped;
      d_[uk] = 1.0;
      ++dropped;
      continue;
    }
    state_[uk] = kOn;
    d_[uk] = dk;
  }
  return dropped;
}

std::size_t MaskedLdlt::redundant_rows(double shift) const {
  std::size_t count = 0;
  // A dependent row's pivot is shift·(1 + |its combination coefficients|²); an independent one's is of
  // the order of A_kk. The geometric mean separates them.
  for (std::size_t k = 0; k < state_.size(); ++k)
    count += state_[k] == kDropped || (state_[k] == kOn && d_[k] * d_[k] <= shift * (diag_[k] + shift));
  return count;
}

void MaskedLdlt::solve(Eigen::Ref<Eigen::VectorXd> x) const {
  const auto n = order_.size();
  std::vector<double>& y = y_;  // zero between calls
  for (std::size_t k = 0; k < n; ++k) y[k] = state_[k] == kOn ? x(order_[k]) : 0.0;
  for (std::size_t j = 0; j < n; ++j) {  // L y = b
    const double yj = y[j];
    if (yj == 0.0) continue;
    const int end = l_outer_[j] + l_count_[j];
    for (int p = l_outer_[j]; p < end; ++p) y[static_cast<std::size_t>(l_index_[static_cast<std::size_t>(p)])] -= l_value_[static_cast<std::size_t>(p)] * yj;
  }
  for (std::size_t j = 0; j < n; ++j) y[j] = state_[j] == kOn ? y[j] / d_[j] : 0.0;
  for (std::size_t j = n; j-- > 0;) {  // Lᵀ x = y
    if (state_[j] != kOn) continue;
    double yj = y[j];
    const int end = l_outer_[j] + l_count_[j];
    for (int p = l_outer_[j]; p < end; ++p) yj -= l_value_[static_cast<std::size_t>(p)] * y[static_cast<std::size_t>(l_index_[static_cast<std::size_t>(p)])];
    y[j] = yj;
  }
  for (std::size_t k = 0; k < n; ++k) {
    x(order_[k]) = y[k];
    y[k] = 0.0;
  }
}

}  // namespace impetus::ledas
