#include "impetus/resolution/ledas/masked_ldlt.hpp"

#include <Eigen/OrderingMethods>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cassert>
#include <numeric>

namespace impetus::ledas {

namespace {
// Analysed rows up to which the order is taken from the rows' groups (COLAMD) rather than from A (AMD).
// Measured on the dropped pyramids' start sets (impetus resolve, K = 10 … 100): COLAMD's orders need
// 0.9–1.05× AMD's multiply-adds up to K = 40 (1,600 rows), 1.18× at K = 50, 1.4× at K = 70 and 1.5× at
// K = 100 (10,000 rows), while it takes a fraction of AMD's time; above a few thousand rows the
// factorizations, repeated, outweigh the ordering, done once.
constexpr SparseIndex kGroupOrderRows = 2000;
}  // namespace

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

void MaskedLdlt::analyze(const Matrix& a, std::span<const char> rows,
                         std::span<const std::array<std::int32_t, 2>> groups) {
  const auto n = static_cast<SparseIndex>(a.cols());
  outer_.assign(a.outerIndexPtr(), a.outerIndexPtr() + n + 1);
  inner_.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  analysed_.assign(n, 1);
  if (!rows.empty())
    for (SparseIndex k = 0; k < n; ++k) analysed_[k] = rows[static_cast<std::size_t>(k)] != 0;
  order_rows(a, groups);
  upper_triangle();
  symbolic();
  plan_subtrees(static_cast<SparseIndex>(std::min(tbb::this_task_arena::max_concurrency(), 16)));
  l_value_.resize(l_index_.size());
  d_.assign(n, 1.0);
  d_inverse_.assign(n, 0.0);
  diag_.assign(n, 0.0);
  state_.assign(n, kOff);
  y_.assign(n, 0.0);
  visited_.assign(n, 0);
  reach_.clear();
  stamp_ = 0;
  ++factorizations_;  // the factor is gone
}

// Fill-reducing order of the analysed rows (COLAMD on their groups up to kGroupOrderRows of them, else
// AMD on their pattern), the others after them.
void MaskedLdlt::order_rows(const Matrix& a, std::span<const std::array<std::int32_t, 2>> groups) {
  const SparseIndex n = analysed_.size();
  if (static_cast<SparseIndex>(groups.size()) == n && order_by_groups(groups)) {
    // order_ is set
  } else if (std::all_of(analysed_.begin(), analysed_.end(), [](char c) { return c != 0; })) {
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

// order_ by COLAMD on Gᵀ restricted to the analysed rows (its columns; G's columns, the groups, are its
// rows), the others after them. COLAMD orders the columns of a matrix for the fill of the Cholesky
// factor of its normal matrix, here (G Gᵀ)_KK, A's pattern on the kept rows, without forming it.
// Returns false (order_ unset) if COLAMD refuses the input.
bool MaskedLdlt::order_by_groups(std::span<const std::array<std::int32_t, 2>> groups) {
  namespace colamd = Eigen::internal::Colamd;
  const SparseIndex n = analysed_.size();
  kept_.clear();
  SparseIndex group_count = 0, entries = 0;
  for (SparseIndex k = 0; k < n; ++k)
    if (analysed_[k]) {
      kept_.push_back(k);
      const auto& g = groups[static_cast<std::size_t>(k)];
      group_count = std::max({group_count, g[0] + 1, g[1] + 1});
      entries += (g[0] >= 0) + (g[1] >= 0 && g[1] != g[0]);
    }
  const SparseIndex nk = kept_.size();
  if (nk <= 2 || nk > kGroupOrderRows || group_count == 0) return false;
  // COLAMD's input: each column's row indices, increasing, no duplicates; it needs room beyond them.
  groups_index_.resize(colamd::recommended(entries, group_count, nk));
  groups_start_.resize(nk + 1);
  SparseIndex q = 0;
  for (SparseIndex c = 0; c < nk; ++c) {
    groups_start_[c] = q;
    const auto& g = groups[static_cast<std::size_t>(kept_[c])];
    const SparseIndex lo = std::min(g[0], g[1]), hi = std::max(g[0], g[1]);
    if (lo >= 0) groups_index_[q++] = lo;
    if (hi >= 0 && hi != lo) groups_index_[q++] = hi;
  }
  groups_start_[nk] = q;
  double knobs[colamd::NKnobs];
  SparseIndex stats[colamd::NStats];
  colamd::set_defaults(knobs);
  if (!colamd::compute_ordering(group_count, nk, groups_index_.size(), groups_index_.data(), groups_start_.data(),
                                knobs, stats))
    return false;
  order_.clear();
  for (SparseIndex c = 0; c < nk; ++c) order_.push_back(kept_[groups_start_[c]]);  // colamd: start[new] = old
  for (SparseIndex k = 0; k < n; ++k)
    if (!analysed_[k]) order_.push_back(k);
  return true;
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

// The parallel schedule for `parts` threads: the elimination tree split into disjoint subtrees, dealt
// to `parts` groups, and the rows above them. Row k costs one multiply-add per entry already in each
// column of its pattern (plus one): counted exactly on the full pattern. The heaviest subtree is split
// (its root moved above the others) while that lowers the estimated time, the rows above plus the larger
// of the heaviest subtree and an even share; the subtrees then go heaviest first to the least loaded
// group. Small trees, and trees whose rows above would take most of the time (AMD's orderings often end
// in a long chain of dense rows), stay serial. Which split is taken changes only the speed, never the
// factor (see the file comment), so it may depend on the arena's size.
void MaskedLdlt::plan_subtrees(SparseIndex parts) {
  schedule_.clear();
  group_outer_.clear();
  const SparseIndex n = order_.size();
  constexpr SparseIndex kParallelRows = 500;  // below, a factorization takes tens of µs: too little to share
  if (parts < 2 || n < kParallelRows) return;
  // The scratch is the plan's own, kept between analyses (assign() reuses its storage).
  PlanScratch& t = plan_;
  t.own.assign(n, 0.0);
  t.subtree.assign(n, 0.0);
  t.count.assign(n, 0);
  double total = 0.0;
  for (SparseIndex k = 0; k < n; ++k) {
    double work = 1.0;
    for (SparseIndex q = row_outer_[k]; q < row_outer_[k + 1]; ++q) work += ++t.count[row_index_[q]];
    t.own[k] = work;
    total += work;
    t.subtree[k] += work;  // its children, all before it, have added theirs
    if (parent_[k] >= 0) t.subtree[parent_[k]] += t.subtree[k];
  }
  constexpr double kParallelWork = 100'000.0;  // multiply-adds: about 100 µs
  if (total < kParallelWork) return;
  t.first_child.assign(n, -1);
  t.next_sibling.assign(n, -1);
  for (SparseIndex k = n; k-- > 0;)
    if (parent_[k] >= 0) {
      t.next_sibling[k] = t.first_child[parent_[k]];
      t.first_child[parent_[k]] = k;
    }
  // Candidates: a heap of (subtree weight, root), the heaviest (then the highest root) on top.
  std::vector<std::pair<double, SparseIndex>>& heap = t.heap;
  t.label.assign(n, -1);  // -2: above the subtrees; else its group once dealt
  const auto split = [&](bool record) {  // the heaviest candidate's root goes above, its children in
    std::pop_heap(heap.begin(), heap.end());
    const SparseIndex root = heap.back().second;
    heap.pop_back();
    if (record) t.label[root] = -2;
    for (SparseIndex c = t.first_child[root]; c >= 0; c = t.next_sibling[c]) {
      heap.emplace_back(t.subtree[c], c);
      std::push_heap(heap.begin(), heap.end());
    }
    return t.own[root];
  };
  const auto start = [&] {
    heap.clear();
    for (SparseIndex k = 0; k < n; ++k)
      if (parent_[k] < 0) heap.emplace_back(t.subtree[k], k);
    std::make_heap(heap.begin(), heap.end());
  };
  const double share = 1.0 / parts;
  start();
  // The estimate with no split (a forest may be balanced as it is), then after each split.
  double above = 0.0, best = std::max(heap.front().first, total * share);
  SparseIndex best_splits = 0;
  for (SparseIndex splits = 1; !heap.empty() && above < best; ++splits) {
    above += split(false);
    if (heap.empty()) break;
    const double estimate = above + std::max(heap.front().first, (total - above) * share);
    if (estimate < best) {
      best = estimate;
      best_splits = splits;
    }
  }
  if (best > 0.8 * total) return;  // less than 1.25× to gain
  start();
  for (SparseIndex s = 0; s < best_splits; ++s) split(true);
  std::sort(heap.begin(), heap.end(), [](const auto& x, const auto& y) { return x.first > y.first || (x.first == y.first && x.second < y.second); });
  t.load.assign(static_cast<std::size_t>(parts), 0.0);
  for (const auto& [weight, root] : heap) {
    const auto g = static_cast<SparseIndex>(std::min_element(t.load.begin(), t.load.end()) - t.load.begin());
    t.load[static_cast<std::size_t>(g)] += weight;
    t.label[root] = g;
  }
  for (SparseIndex k = n; k-- > 0;)
    if (t.label[k] == -1) t.label[k] = t.label[parent_[k]];  // a subtree's rows join its root's group
  // Rows by group, each group increasing, the rows above last (group `parts`).
  const auto group_of = [&](SparseIndex k) { return t.label[k] < 0 ? parts : t.label[k]; };
  group_outer_.assign(parts + 2, 0);
  for (SparseIndex k = 0; k < n; ++k) ++group_outer_[group_of(k) + 1];
  std::partial_sum(group_outer_.begin(), group_outer_.end(), group_outer_.begin());
  schedule_.resize(n);
  t.count.assign(group_outer_.begin(), group_outer_.end() - 1);  // each group's next slot
  for (SparseIndex k = 0; k < n; ++k) schedule_[t.count[group_of(k)]++] = k;
  group_work_.assign(parts, 0.0);
  group_dropped_.assign(parts, 0);
  split_count_.assign(n, 0);
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

std::size_t MaskedLdlt::factorize(const Matrix& a, std::span<const char> on, double rank_tolerance, double floor,
                                  double shift) {
  assert(covers(on) && "a row of F outside the analysed pattern would be factorized as if uncoupled");
  ++factorizations_;
  double work = 0.0;
  std::size_t dropped = 0;
  if (schedule_.empty()) {
    dropped = factorize_rows(nullptr, order_.size(), a, on, rank_tolerance, floor, shift, pattern_.data(), work);
  } else {
    // The groups of subtrees in parallel, each with its own slice of the scratch (a row of a group has
    // fewer entries than the group has rows), then the rows above them. Sums in group order.
    const SparseIndex parts = group_outer_.size() - 2;
    tbb::parallel_for(SparseIndex{0}, parts, [&](SparseIndex g) {
      const SparseIndex first = group_outer_[g];
      group_work_[g] = 0.0;
      group_dropped_[g] = factorize_rows(schedule_.data() + first, group_outer_[g + 1] - first, a, on,
                                         rank_tolerance, floor, shift, pattern_.data() + first, group_work_[g]);
    });
    for (SparseIndex g = 0; g < parts; ++g) {
      work += group_work_[g];
      dropped += group_dropped_[g];
    }
    // Each column's entries from its own group (all of them before the rows above add theirs): the
    // solves' parallel phase applies only those.
    const SparseIndex first = group_outer_[parts];
    for (SparseIndex r = 0; r < first; ++r) split_count_[schedule_[r]] = l_count_[schedule_[r]];
    dropped += factorize_rows(schedule_.data() + first, group_outer_[parts + 1] - first, a, on, rank_tolerance, floor,
                              shift, pattern_.data(), work);
  }
  work_ = work;
  return dropped;
}

// ldl_numeric, row by row (row k of L from a sparse triangular solve along the elimination tree, on
// the row pattern analyze() recorded), with rows off F skipped and rows with a vanishing pivot dropped.
// Entries that come out exactly zero (a row of the full pattern that F does not reach) are not stored.
// Kept in one piece: it is the hot loop of the complementary mode, and Davis's kernel reads best whole.
std::size_t MaskedLdlt::factorize_rows(const SparseIndex* rows, SparseIndex count, const Matrix& a,
                                       std::span<const char> on, double rank_tolerance, double floor, double shift,
                                       SparseIndex* stored, double& work) {
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
  std::size_t dropped = 0;
  double flops = 0.0;
  for (SparseIndex r = 0; r < count; ++r) {
    const SparseIndex k = rows != nullptr ? rows[r] : r;
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
      flops += end - begin + 1;
      for (SparseIndex p = begin; p < end; ++p) y[l_index[p]] -= l_value[p] * yi;
      const double lki = yi * d_inverse[i];
      dk -= lki * yi;
      l_index[end] = k;
      l_value[end] = lki;
      ++l_count[i];
      stored[entries++] = i;  // the columns row k put an entry in
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
  work += flops;
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

// With a parallel schedule, forward() applies each column's entries within its own group in parallel
// (a group's rows receive only from its own columns), then every column's entries in the rows above, in
// column order; backward() does the rows above first, then the groups in parallel. Every entry of t and
// x gets the same operations in the same order as in the serial sweeps, so the same bits.
void MaskedLdlt::forward(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::VectorXd& t) const {
  const SparseIndex n = order_.size();
  t.resize(n);
  const SparseIndex* l_outer = l_outer_.data();
  const SparseIndex* l_count = l_count_.data();
  const SparseIndex* l_index = l_index_.data();
  const double* l_value = l_value_.data();
  double* y = t.data();
  for (SparseIndex k = 0; k < n; ++k) y[k] = state_[k] == kOn ? b(order_[k]) : 0.0;
  // L t = P b: column j's entries [first, last) applied.
  const auto apply = [&](SparseIndex j, SparseIndex first, SparseIndex last) {
    const double yj = y[j];
    if (yj == 0.0) return;
    for (SparseIndex p = first; p < last; ++p) y[l_index[p]] -= l_value[p] * yj;
  };
  if (schedule_.empty()) {
    for (SparseIndex j = 0; j < n; ++j) apply(j, l_outer[j], l_outer[j] + l_count[j]);
    return;
  }
  const SparseIndex parts = group_outer_.size() - 2;
  const SparseIndex* split = split_count_.data();
  tbb::parallel_for(SparseIndex{0}, parts, [&](SparseIndex g) {
    for (SparseIndex r = group_outer_[g]; r < group_outer_[g + 1]; ++r) {
      const SparseIndex j = schedule_[r];
      apply(j, l_outer[j], l_outer[j] + split[j]);
    }
  });
  for (SparseIndex j = 0; j < n; ++j) apply(j, l_outer[j] + split[j], l_outer[j] + l_count[j]);
}

void MaskedLdlt::backward(Eigen::VectorXd& t, Eigen::Ref<Eigen::VectorXd> x) const {
  const SparseIndex n = order_.size();
  const SparseIndex* l_outer = l_outer_.data();
  const SparseIndex* l_count = l_count_.data();
  const SparseIndex* l_index = l_index_.data();
  const double* l_value = l_value_.data();
  const double* d_inverse = d_inverse_.data();
  double* y = t.data();
  const auto row = [&](SparseIndex j) {  // D⁻¹, then Lᵀ x = y
    double yj = y[j] * d_inverse[j];
    const SparseIndex end = l_outer[j] + l_count[j];
    for (SparseIndex p = l_outer[j]; p < end; ++p) yj -= l_value[p] * y[l_index[p]];
    y[j] = yj;
  };
  if (schedule_.empty()) {
    for (SparseIndex j = n; j-- > 0;) row(j);
  } else {
    const SparseIndex parts = group_outer_.size() - 2;
    for (SparseIndex r = group_outer_[parts + 1]; r-- > group_outer_[parts];) row(schedule_[r]);
    tbb::parallel_for(SparseIndex{0}, parts, [&](SparseIndex g) {
      for (SparseIndex r = group_outer_[g + 1]; r-- > group_outer_[g];) row(schedule_[r]);
    });
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
