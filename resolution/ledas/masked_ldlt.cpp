#include "impetus/resolution/ledas/masked_ldlt.hpp"

#include <Eigen/OrderingMethods>

#include <algorithm>
#include <cassert>
#include <numeric>

namespace impetus::ledas {

// Approximate minimum degree (Eigen's port of AMD, as SimplicialLDLT uses): order[new] = old.
IndexVector<SparseIndex> MaskedLdlt::minimum_degree(const Matrix& a) {
  IndexVector<SparseIndex> order(static_cast<SparseIndex>(a.cols()), 0);
  if (a.cols() <= 2) {
    std::iota(order.begin(), order.end(), 0);
    return order;
  }
  Matrix symmetric = a;  // AMD needs both triangles and the diagonal; it destroys its input
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, SparseIndex> perm;
  Eigen::internal::minimum_degree_ordering(symmetric, perm);
  for (SparseIndex k = 0; k < order.size(); ++k) order[k] = perm.indices()[k];
  return order;
}

void MaskedLdlt::analyze(const Matrix& a, std::span<const char> rows) {
  const auto n = static_cast<SparseIndex>(a.cols());
  outer_.assign(a.outerIndexPtr(), a.outerIndexPtr() + n + 1);
  inner_.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  analysed_.assign(n, 1);
  if (!rows.empty())
    for (SparseIndex k = 0; k < n; ++k) analysed_[k] = rows[static_cast<std::size_t>(k)] != 0;
  order_rows(a);
  upper_triangle();
  symbolic();
  l_value_.resize(l_index_.size());
  d_.assign(n, 1.0);
  d_inverse_.assign(n, 0.0);
  diag_.assign(n, 0.0);
  state_.assign(n, kOff);
  y_.assign(n, 0.0);
  visited_.assign(n, 0);
  reach_.clear();
  stamp_ = 0;
}

// Fill-reducing order of the analysed rows (AMD on their pattern), the others after them.
void MaskedLdlt::order_rows(const Matrix& a) {
  const SparseIndex n = analysed_.size();
  if (std::all_of(analysed_.begin(), analysed_.end(), [](char c) { return c != 0; })) {
    order_ = minimum_degree(a);
  } else {
    IndexVector<SparseIndex> kept, position(n, -1);
    for (SparseIndex k = 0; k < n; ++k)
      if (analysed_[k]) {
        position[k] = kept.size();
        kept.push_back(k);
      }
    const SparseIndex nk = kept.size();
    // A's pattern on the analysed rows, column by column (A's row indices are sorted and `position`
    // keeps their order, so each column comes out sorted).
    SparseIndex entries = 0;
    for (const SparseIndex j : kept)
      for (SparseIndex p = outer_[j]; p < outer_[j + 1]; ++p) entries += position[inner_[p]] >= 0 ? 1 : 0;
    Matrix sub(nk, nk);
    sub.resizeNonZeros(entries);
    SparseIndex* sub_outer = sub.outerIndexPtr();
    SparseIndex* sub_inner = sub.innerIndexPtr();
    std::fill(sub.valuePtr(), sub.valuePtr() + entries, 1.0);
    SparseIndex q = 0;
    for (SparseIndex c = 0; c < nk; ++c) {
      sub_outer[c] = q;
      const SparseIndex j = kept[c];
      for (SparseIndex p = outer_[j]; p < outer_[j + 1]; ++p)
        if (const SparseIndex i = position[inner_[p]]; i >= 0) sub_inner[q++] = i;
    }
    sub_outer[nk] = q;
    order_.clear();
    for (const SparseIndex k : minimum_degree(sub)) order_.push_back(kept[k]);
    for (SparseIndex k = 0; k < n; ++k)
      if (!analysed_[k]) order_.push_back(k);
  }
  new_of_old_.resize(n);
  for (SparseIndex k = 0; k < n; ++k) new_of_old_[order_[k]] = k;
}

// Upper triangle of C = P A Pᵀ by columns: column k (new) holds rows i ≤ k. Only entries between
// analysed rows enter the pattern (the others are identity rows, never in F).
void MaskedLdlt::upper_triangle() {
  const SparseIndex n = order_.size();
  const auto entry = [&](SparseIndex p, SparseIndex j) { return analysed_[inner_[p]] && analysed_[j]; };
  c_outer_.assign(n + 1, 0);
  for (SparseIndex j = 0; j < n; ++j)
    for (SparseIndex p = outer_[j]; p < outer_[j + 1]; ++p) {
      const SparseIndex i = new_of_old_[inner_[p]];
      const SparseIndex k = new_of_old_[j];
      if (i <= k && entry(p, j)) ++c_outer_[k + 1];
    }
  std::partial_sum(c_outer_.begin(), c_outer_.end(), c_outer_.begin());
  c_row_.resize(c_outer_.back());
  c_value_.resize(c_row_.size());
  IndexVector<SparseIndex> next(c_outer_.begin(), c_outer_.end() - 1);
  for (SparseIndex j = 0; j < n; ++j)
    for (SparseIndex p = outer_[j]; p < outer_[j + 1]; ++p) {
      const SparseIndex i = new_of_old_[inner_[p]];
      const SparseIndex k = new_of_old_[j];
      if (i > k || !entry(p, j)) continue;
      const SparseIndex q = next[k]++;
      c_row_[q] = i;
      c_value_[q] = p;
    }
}

// The elimination tree, the column counts and column starts of L (ldl_symbolic), and the pattern of
// every row of L (columns i < k, in a topological order of the elimination tree: descendants first), in
// one pass: row k's pattern is the set of tree paths from the entries of C's column k up to k, which is
// the walk ldl_symbolic makes to find the parents and counts, so factorize() only reads it.
void MaskedLdlt::symbolic() {
  const SparseIndex n = order_.size();
  parent_.assign(n, -1);
  flag_.assign(n, -1);
  l_count_.assign(n, 0);
  pattern_.assign(n, 0);
  row_outer_.assign(n + 1, 0);
  row_index_.clear();
  for (SparseIndex k = 0; k < n; ++k) {
    flag_[k] = k;
    SparseIndex top = n;
    for (SparseIndex p = c_outer_[k]; p < c_outer_[k + 1]; ++p) {
      SparseIndex len = 0;
      for (SparseIndex i = c_row_[p]; flag_[i] != k; i = parent_[i]) {
        if (parent_[i] == -1) parent_[i] = k;
        ++l_count_[i];
        pattern_[len++] = i;
        flag_[i] = k;
      }
      while (len > 0) pattern_[--top] = pattern_[--len];
    }
    for (; top < n; ++top) row_index_.push_back(pattern_[top]);
    row_outer_[k + 1] = row_index_.size();
  }
  l_outer_.assign(n + 1, 0);
  for (SparseIndex k = 0; k < n; ++k) l_outer_[k + 1] = l_outer_[k] + l_count_[k];
  l_index_.resize(l_outer_.back());
}

bool MaskedLdlt::covers(std::span<const char> on) const {
  for (std::size_t k = 0; k < on.size(); ++k)
    if (on[k] && !analysed(k)) return false;
  return true;
}

bool MaskedLdlt::same_pattern(const Matrix& a) const {
  return outer_.size() == a.cols() + 1 && inner_.size() == a.nonZeros() &&
         std::equal(outer_.begin(), outer_.end(), a.outerIndexPtr()) &&
         std::equal(inner_.begin(), inner_.end(), a.innerIndexPtr());
}

// ldl_numeric, row by row (row k of L from a sparse triangular solve along the elimination tree, on
// the row pattern analyze() recorded), with rows off F skipped and rows with a vanishing pivot dropped.
// Entries that come out exactly zero (a row of the full pattern that F does not reach) are not stored.
// Kept in one piece: it is the hot loop of the complementary mode, and Davis's kernel reads best whole.
std::size_t MaskedLdlt::factorize(const Matrix& a, std::span<const char> on, double rank_tolerance, double floor,
                                  double shift) {
  assert(covers(on) && "a row of F outside the analysed pattern would be factorized as if uncoupled");
  const SparseIndex n = order_.size();
  const double* value = a.valuePtr();
  const SparseIndex* c_outer = c_outer_.data();
  const SparseIndex* c_row = c_row_.data();
  const SparseIndex* c_value = c_value_.data();
  const SparseIndex* row_outer = row_outer_.data();
  const SparseIndex* row_index = row_index_.data();
  const SparseIndex* l_outer = l_outer_.data();
  SparseIndex* l_count = l_count_.data();
  SparseIndex* l_index = l_index_.data();
  double* l_value = l_value_.data();
  double* y = y_.data();
  double* d_inverse = d_inverse_.data();
  char* state = state_.data();
  SparseIndex* stored = pattern_.data();  // the columns row k put an entry in
  std::size_t dropped = 0;
  double work = 0.0;
  for (SparseIndex k = 0; k < n; ++k) {
    l_count[k] = 0;
    if (!on[order_[k]]) {
      state[k] = kOff;
      d_[k] = 1.0;
      d_inverse[k] = 0.0;
      continue;
    }
    // Scatter column k of C (rows i ≤ k that are in F).
    double diagonal = 0.0;
    for (SparseIndex p = c_outer[k]; p < c_outer[k + 1]; ++p) {
      const SparseIndex i = c_row[p];
      const double v = value[c_value[p]];
      if (i == k) diagonal += v;
      else if (state[i] == kOn) y[i] += v;
    }
    double dk = diagonal + shift;
    SparseIndex entries = 0;
    for (SparseIndex t = row_outer[k]; t < row_outer[k + 1]; ++t) {
      const SparseIndex i = row_index[t];
      const double yi = y[i];
      y[i] = 0.0;
      // Off or dropped (no entries in its column), or not reached from F's entries: nothing to eliminate.
      if (yi == 0.0 || state[i] != kOn) continue;
      const SparseIndex begin = l_outer[i];
      const SparseIndex end = begin + l_count[i];
      work += end - begin + 1;
      for (SparseIndex p = begin; p < end; ++p) y[l_index[p]] -= l_value[p] * yi;
      const double lki = yi * d_inverse[i];
      dk -= lki * yi;
      l_index[end] = k;
      l_value[end] = lki;
      ++l_count[i];
      stored[entries++] = i;
    }
    diag_[k] = diagonal;
    if (diagonal <= floor || dk <= rank_tolerance * (diagonal + shift)) {
      // Dependent on the rows before it: take back its entries (the last of each column) and make it an
      // identity row that later rows do not see.
      for (SparseIndex t = 0; t < entries; ++t) --l_count[stored[t]];
      state[k] = kDropped;
      d_[k] = 1.0;
      d_inverse[k] = 0.0;
      ++dropped;
      continue;
    }
    state[k] = kOn;
    d_[k] = dk;
    d_inverse[k] = 1.0 / dk;
  }
  work_ = work;
  return dropped;
}

std::size_t MaskedLdlt::redundant_rows(double shift) const {
  std::size_t count = 0;
  // A dependent row's pivot is shift·(1 + |its combination coefficients|²); an independent one's is of
  // the order of A_kk. The geometric mean separates them.
  for (SparseIndex k = 0; k < state_.size(); ++k)
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
  const SparseIndex n = order_.size();
  t.resize(n);
  const SparseIndex* l_outer = l_outer_.data();
  const SparseIndex* l_count = l_count_.data();
  const SparseIndex* l_index = l_index_.data();
  const double* l_value = l_value_.data();
  double* y = t.data();
  for (SparseIndex k = 0; k < n; ++k) y[k] = state_[k] == kOn ? b(order_[k]) : 0.0;
  for (SparseIndex j = 0; j < n; ++j) {  // L t = P b
    const double yj = y[j];
    if (yj == 0.0) continue;
    const SparseIndex end = l_outer[j] + l_count[j];
    for (SparseIndex p = l_outer[j]; p < end; ++p) y[l_index[p]] -= l_value[p] * yj;
  }
}

void MaskedLdlt::backward(Eigen::VectorXd& t, Eigen::Ref<Eigen::VectorXd> x) const {
  const SparseIndex n = order_.size();
  const SparseIndex* l_outer = l_outer_.data();
  const SparseIndex* l_count = l_count_.data();
  const SparseIndex* l_index = l_index_.data();
  const double* l_value = l_value_.data();
  const double* d_inverse = d_inverse_.data();
  double* y = t.data();
  for (SparseIndex j = n; j-- > 0;) {  // D⁻¹, then Lᵀ x = y
    double yj = y[j] * d_inverse[j];
    const SparseIndex end = l_outer[j] + l_count[j];
    for (SparseIndex p = l_outer[j]; p < end; ++p) yj -= l_value[p] * y[l_index[p]];
    y[j] = yj;
  }
  for (SparseIndex k = 0; k < n; ++k) x(order_[k]) = y[k];
}

void MaskedLdlt::forward_sparse(std::span<const std::pair<SparseIndex, double>> u, std::vector<SparseIndex>& index,
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
    const SparseIndex i = new_of_old_[row];
    if (state_[i] != kOn) continue;
    y[i] += v;
    for (SparseIndex j = i; j != -1 && visited_[j] != stamp_; j = parent_[j]) {
      visited_[j] = stamp_;
      reach_.push_back(j);
    }
  }
  std::sort(reach_.begin(), reach_.end());  // a child precedes its parent in the elimination order
  for (const SparseIndex j : reach_) {
    const double yj = y[j];
    if (yj == 0.0) continue;
    const SparseIndex end = l_outer_[j] + l_count_[j];
    for (SparseIndex p = l_outer_[j]; p < end; ++p)
      y[l_index_[p]] -= l_value_[p] * yj;
  }
  for (const SparseIndex j : reach_) {
    if (y[j] != 0.0) {
      index.push_back(j);
      value.push_back(y[j]);
    }
    y[j] = 0.0;
  }
}

}  // namespace impetus::ledas
