#include "ledas/masked_ldlt.hpp"

#include <Eigen/OrderingMethods>

#include <algorithm>
#include <cassert>
#include <numeric>

namespace impetus::ledas {

// Approximate minimum degree (Eigen's port of AMD, as SimplicialLDLT uses): order[new] = old.
std::vector<int> MaskedLdlt::minimum_degree(const Matrix& a) {
  std::vector<int> order(static_cast<std::size_t>(a.cols()));
  if (a.cols() <= 2) {
    std::iota(order.begin(), order.end(), 0);
    return order;
  }
  Matrix symmetric = a;  // AMD needs both triangles and the diagonal; it destroys its input
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
  Eigen::internal::minimum_degree_ordering(symmetric, perm);
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = perm.indices()[static_cast<Eigen::Index>(k)];
  return order;
}

void MaskedLdlt::analyze(const Matrix& a, std::span<const char> rows) {
  const auto n = static_cast<int>(a.cols());
  outer_.assign(a.outerIndexPtr(), a.outerIndexPtr() + n + 1);
  inner_.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  analysed_.assign(static_cast<std::size_t>(n), 1);
  if (!rows.empty())
    for (int k = 0; k < n; ++k) analysed_[static_cast<std::size_t>(k)] = rows[static_cast<std::size_t>(k)] != 0;
  const bool all = std::all_of(analysed_.begin(), analysed_.end(), [](char c) { return c != 0; });

  // Fill-reducing order of the analysed rows (AMD on their pattern), the others after them.
  if (all) {
    order_ = minimum_degree(a);
  } else {
    std::vector<int> kept, position(static_cast<std::size_t>(n), -1);
    for (int k = 0; k < n; ++k)
      if (analysed_[static_cast<std::size_t>(k)]) {
        position[static_cast<std::size_t>(k)] = static_cast<int>(kept.size());
        kept.push_back(k);
      }
    const auto nk = static_cast<Eigen::Index>(kept.size());
    Matrix sub(nk, nk);  // A's pattern on the analysed rows
    std::vector<Eigen::Triplet<double>> entries;
    for (const int j : kept)
      for (int p = outer_[static_cast<std::size_t>(j)]; p < outer_[static_cast<std::size_t>(j) + 1]; ++p)
        if (const int i = position[static_cast<std::size_t>(inner_[static_cast<std::size_t>(p)])]; i >= 0)
          entries.emplace_back(i, position[static_cast<std::size_t>(j)], 1.0);
    sub.setFromTriplets(entries.begin(), entries.end());
    order_.clear();
    for (const int k : minimum_degree(sub)) order_.push_back(kept[static_cast<std::size_t>(k)]);
    for (int k = 0; k < n; ++k)
      if (!analysed_[static_cast<std::size_t>(k)]) order_.push_back(k);
  }
  new_of_old_.resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) new_of_old_[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])] = k;
  // Only entries between analysed rows enter the pattern (the others are identity rows, never in F).
  const auto entry = [&](int p, int j) {
    return analysed_[static_cast<std::size_t>(inner_[static_cast<std::size_t>(p)])] && analysed_[static_cast<std::size_t>(j)];
  };

  // Upper triangle of C = P A Pᵀ by columns: column k (new) holds rows i ≤ k.
  c_outer_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int p = outer_[static_cast<std::size_t>(j)]; p < outer_[static_cast<std::size_t>(j) + 1]; ++p) {
      const int i = new_of_old_[static_cast<std::size_t>(inner_[static_cast<std::size_t>(p)])];
      const int k = new_of_old_[static_cast<std::size_t>(j)];
      if (i <= k && entry(p, j)) ++c_outer_[static_cast<std::size_t>(k) + 1];
    }
  std::partial_sum(c_outer_.begin(), c_outer_.end(), c_outer_.begin());
  c_row_.resize(static_cast<std::size_t>(c_outer_.back()));
  c_value_.resize(c_row_.size());
  std::vector<int> next(c_outer_.begin(), c_outer_.end() - 1);
  for (int j = 0; j < n; ++j)
    for (int p = outer_[static_cast<std::size_t>(j)]; p < outer_[static_cast<std::size_t>(j) + 1]; ++p) {
      const int i = new_of_old_[static_cast<std::size_t>(inner_[static_cast<std::size_t>(p)])];
      const int k = new_of_old_[static_cast<std::size_t>(j)];
      if (i > k || !entry(p, j)) continue;
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

  // The pattern of every row of L (columns i < k, in a topological order of the elimination tree:
  // descendants first), found once here by the etree walk ldl_numeric does per row, so factorize() only
  // reads it.
  pattern_.assign(static_cast<std::size_t>(n), 0);
  row_outer_.assign(static_cast<std::size_t>(n) + 1, 0);
  row_index_.resize(l_index_.size());
  flag_.assign(static_cast<std::size_t>(n), -1);
  for (int k = 0, q = 0; k < n; ++k) {
    flag_[static_cast<std::size_t>(k)] = k;
    int top = n;
    for (int p = c_outer_[static_cast<std::size_t>(k)]; p < c_outer_[static_cast<std::size_t>(k) + 1]; ++p) {
      int len = 0;
      for (int i = c_row_[static_cast<std::size_t>(p)]; flag_[static_cast<std::size_t>(i)] != k; i = parent_[static_cast<std::size_t>(i)]) {
        pattern_[static_cast<std::size_t>(len++)] = i;
        flag_[static_cast<std::size_t>(i)] = k;
      }
      while (len > 0) pattern_[static_cast<std::size_t>(--top)] = pattern_[static_cast<std::size_t>(--len)];
    }
    for (; top < n; ++top) row_index_[static_cast<std::size_t>(q++)] = pattern_[static_cast<std::size_t>(top)];
    row_outer_[static_cast<std::size_t>(k) + 1] = q;
  }
  l_value_.resize(l_index_.size());
  d_.assign(static_cast<std::size_t>(n), 1.0);
  d_inverse_.assign(static_cast<std::size_t>(n), 0.0);
  diag_.assign(static_cast<std::size_t>(n), 0.0);
  state_.assign(static_cast<std::size_t>(n), kOff);
  y_.assign(static_cast<std::size_t>(n), 0.0);
  visited_.assign(static_cast<std::size_t>(n), 0);
  reach_.clear();
  stamp_ = 0;
}

bool MaskedLdlt::covers(std::span<const char> on) const {
  for (std::size_t k = 0; k < on.size(); ++k)
    if (on[k] && !analysed_[k]) return false;
  return true;
}

bool MaskedLdlt::same_pattern(const Matrix& a) const {
  return outer_.size() == static_cast<std::size_t>(a.cols()) + 1 &&
         inner_.size() == static_cast<std::size_t>(a.nonZeros()) &&
         std::equal(outer_.begin(), outer_.end(), a.outerIndexPtr()) &&
         std::equal(inner_.begin(), inner_.end(), a.innerIndexPtr());
}

// ldl_numeric, row by row (row k of L from a sparse triangular solve along the elimination tree, on
// the row pattern analyze() recorded), with rows off F skipped and rows with a vanishing pivot dropped.
// Entries that come out exactly zero (a row of the full pattern that F does not reach) are not stored.
std::size_t MaskedLdlt::factorize(const Matrix& a, std::span<const char> on, double rank_tolerance, double floor,
                                  double shift) {
  assert(covers(on) && "a row of F outside the analysed pattern would be factorized as if uncoupled");
  const auto n = static_cast<int>(order_.size());
  const double* value = a.valuePtr();
  const int* c_outer = c_outer_.data();
  const int* c_row = c_row_.data();
  const int* c_value = c_value_.data();
  const int* row_outer = row_outer_.data();
  const int* row_index = row_index_.data();
  const int* l_outer = l_outer_.data();
  int* l_count = l_count_.data();
  int* l_index = l_index_.data();
  double* l_value = l_value_.data();
  double* y = y_.data();
  double* d_inverse = d_inverse_.data();
  char* state = state_.data();
  int* stored = pattern_.data();  // the columns row k put an entry in
  std::size_t dropped = 0;
  double work = 0.0;
  for (int k = 0; k < n; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    l_count[uk] = 0;
    if (!on[static_cast<std::size_t>(order_[uk])]) {
      state[uk] = kOff;
      d_[uk] = 1.0;
      d_inverse[uk] = 0.0;
      continue;
    }
    // Scatter column k of C (rows i ≤ k that are in F).
    double diagonal = 0.0;
    for (int p = c_outer[uk]; p < c_outer[uk + 1]; ++p) {
      const auto i = static_cast<std::size_t>(c_row[p]);
      const double v = value[c_value[p]];
      if (i == uk) diagonal += v;
      else if (state[i] == kOn) y[i] += v;
    }
    double dk = diagonal + shift;
    int entries = 0;
    for (int t = row_outer[uk]; t < row_outer[uk + 1]; ++t) {
      const auto i = static_cast<std::size_t>(row_index[t]);
      const double yi = y[i];
      y[i] = 0.0;
      // Off or dropped (no entries in its column), or not reached from F's entries: nothing to eliminate.
      if (yi == 0.0 || state[i] != kOn) continue;
      const int begin = l_outer[i];
      const int end = begin + l_count[i];
      work += end - begin + 1;
      for (int p = begin; p < end; ++p) y[l_index[p]] -= l_value[p] * yi;
      const double lki = yi * d_inverse[i];
      dk -= lki * yi;
      l_index[end] = k;
      l_value[end] = lki;
      ++l_count[i];
      stored[entries++] = static_cast<int>(i);
    }
    diag_[uk] = diagonal;
    if (diagonal <= floor || dk <= rank_tolerance * (diagonal + shift)) {
      // Dependent on the rows before it: take back its entries (the last of each column) and make it an
      // identity row that later rows do not see.
      for (int t = 0; t < entries; ++t) --l_count[stored[t]];
      state[uk] = kDropped;
      d_[uk] = 1.0;
      d_inverse[uk] = 0.0;
      ++dropped;
      continue;
    }
    state[uk] = kOn;
    d_[uk] = dk;
    d_inverse[uk] = 1.0 / dk;
  }
  work_ = work;
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
  forward(x, scratch_);
  backward(scratch_, x);
}

}  // namespace impetus::ledas

namespace impetus::ledas {

void MaskedLdlt::forward(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::VectorXd& t) const {
  const auto n = order_.size();
  t.resize(static_cast<Eigen::Index>(n));
  const int* l_outer = l_outer_.data();
  const int* l_count = l_count_.data();
  const int* l_index = l_index_.data();
  const double* l_value = l_value_.data();
  double* y = t.data();
  for (std::size_t k = 0; k < n; ++k) y[k] = state_[k] == kOn ? b(order_[k]) : 0.0;
  for (std::size_t j = 0; j < n; ++j) {  // L t = P b
    const double yj = y[j];
    if (yj == 0.0) continue;
    const int end = l_outer[j] + l_count[j];
    for (int p = l_outer[j]; p < end; ++p) y[l_index[p]] -= l_value[p] * yj;
  }
}

void MaskedLdlt::backward(Eigen::VectorXd& t, Eigen::Ref<Eigen::VectorXd> x) const {
  const auto n = order_.size();
  const int* l_outer = l_outer_.data();
  const int* l_count = l_count_.data();
  const int* l_index = l_index_.data();
  const double* l_value = l_value_.data();
  const double* d_inverse = d_inverse_.data();
  double* y = t.data();
  for (std::size_t j = n; j-- > 0;) {  // D⁻¹, then Lᵀ x = y
    double yj = y[j] * d_inverse[j];
    const int end = l_outer[j] + l_count[j];
    for (int p = l_outer[j]; p < end; ++p) yj -= l_value[p] * y[l_index[p]];
    y[j] = yj;
  }
  for (std::size_t k = 0; k < n; ++k) x(order_[k]) = y[k];
}

void MaskedLdlt::forward_sparse(std::span<const std::pair<int, double>> u, std::vector<int>& index,
                                std::vector<double>& value) const {
  index.clear();
  value.clear();
  if (++stamp_ == 0) {  // the stamp wrapped: forget every visit
    std::fill(visited_.begin(), visited_.end(), 0);
    stamp_ = 1;
  }
  reach_.clear();
  double* y = y_.data();  // zero between calls
  for (const auto& [row, v] : u) {
    const int i = new_of_old_[static_cast<std::size_t>(row)];
    if (state_[static_cast<std::size_t>(i)] != kOn) continue;
    y[i] += v;
    for (int j = i; j != -1 && visited_[static_cast<std::size_t>(j)] != stamp_; j = parent_[static_cast<std::size_t>(j)]) {
      visited_[static_cast<std::size_t>(j)] = stamp_;
      reach_.push_back(j);
    }
  }
  std::sort(reach_.begin(), reach_.end());  // a child precedes its parent in the elimination order
  for (const int j : reach_) {
    const double yj = y[j];
    if (yj == 0.0) continue;
    const int end = l_outer_[static_cast<std::size_t>(j)] + l_count_[static_cast<std::size_t>(j)];
    for (int p = l_outer_[static_cast<std::size_t>(j)]; p < end; ++p)
      y[l_index_[static_cast<std::size_t>(p)]] -= l_value_[static_cast<std::size_t>(p)] * yj;
  }
  for (const int j : reach_) {
    if (y[j] != 0.0) {
      index.push_back(j);
      value.push_back(y[j]);
    }
    y[j] = 0.0;
  }
}

}  // namespace impetus::ledas
