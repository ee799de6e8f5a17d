#pragma once
/// \file
/// LDLᵀ of a principal submatrix A_FF of a symmetric positive semi-definite matrix A (the paper's eq. 7
/// matrix of one island), for a set F of rows that changes from call to call while A's sparsity pattern
/// does not. Rows outside F are replaced by identity rows, so one symbolic analysis (fill-reducing order,
/// elimination tree, column counts) of A's full pattern serves every F of an active-set loop, and every
/// step while the contact graph is unchanged.
///
/// Rank: a row whose pivot is ≤ rank_tolerance · A_kk is (to that tolerance) a linear combination of the
/// rows of F eliminated before it — a redundant contact (the paper's Figure 2, a pyramid's horizontal
/// contacts). It is *dropped*: treated as an identity row, so A_FF z = c is solved on an independent
/// subset B ⊆ F with z = 0 on the dropped rows (a basic solution). When c_F is in the range of A_FF
/// (always for contacts with zero targets: c = −G v⁻), that is an exact solution of A_FF z = c_F, and
/// every solution gives the same A z (the same velocities); only the split of the impulse among
/// redundant rows differs from the minimum-norm one.
///
/// Up-looking sparse LDLᵀ (T. Davis, "Algorithm 849: a concise sparse Cholesky factorization package").
/// No allocation after analyze(); deterministic.
///
/// Threads: row k of L depends only on the rows of its elimination subtree, so disjoint subtrees are
/// factorized in parallel (oneTBB, in the caller's task arena), and the rows above them after them.
/// Each row is computed by the same operations in the same order whichever thread runs it and however
/// the tree is split, so the factor's bits do not depend on the thread count.

#include <Eigen/SparseCore>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

namespace impetus::ledas {

/// The index type of the sparse kernels: Eigen's storage index of SparseMatrix<double> (int). Rows,
/// columns, entries of L and elimination-tree links all use it, so no kernel converts between index types.
using SparseIndex = int;

/// A std::vector indexed by SparseIndex: the kernels' one conversion to the vector's size type is here.
template <class T>
class IndexVector {
 public:
  IndexVector() = default;
  IndexVector(SparseIndex n, const T& value) : data_(static_cast<std::size_t>(n), value) {}
  template <class It>
    requires(!std::is_integral_v<It>)
  IndexVector(It first, It last) : data_(first, last) {}

  T& operator[](SparseIndex i) { return data_[static_cast<std::size_t>(i)]; }
  const T& operator[](SparseIndex i) const { return data_[static_cast<std::size_t>(i)]; }
  SparseIndex size() const { return static_cast<SparseIndex>(data_.size()); }
  bool empty() const { return data_.empty(); }
  void assign(SparseIndex n, const T& value) { data_.assign(static_cast<std::size_t>(n), value); }
  template <class It>
    requires(!std::is_integral_v<It>)
  void assign(It first, It last) { data_.assign(first, last); }
  void resize(SparseIndex n) { data_.resize(static_cast<std::size_t>(n)); }
  void clear() { data_.clear(); }
  void push_back(const T& value) { data_.push_back(value); }
  T& back() { return data_.back(); }
  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  auto begin() { return data_.begin(); }
  auto end() { return data_.end(); }
  auto begin() const { return data_.begin(); }
  auto end() const { return data_.end(); }

 private:
  std::vector<T> data_;
};

class MaskedLdlt {
 public:
  using Matrix = Eigen::SparseMatrix<double>;

  /// Symbolic analysis of the pattern of `a` (square, both triangles and the diagonal stored, compressed),
  /// for the rows `rows` (non-zero; empty: every row) — only they may be in a later F (covers()). The
  /// order is approximate minimum degree on their pattern, the other rows after them as identity rows:
  /// an active-set search's likely rows (its start set) are factorized with their own fill, and rows
  /// that mostly stay out of F (a pyramid's horizontal contacts) add nothing to the pattern.
  ///
  /// `groups`, optional (one per row of `a`): A's pattern is that of G Gᵀ, where row k of G has its
  /// entries in the columns groups[k][0] and groups[k][1] (−1: none), as an island's matrix couples two
  /// rows exactly where they share a movable body. Up to 2,000 analysed rows the order is then column
  /// approximate minimum degree on G (COLAMD on Gᵀ), which reads G's two entries per row instead of A's
  /// clique of d² entries around each body of d rows; above, where its orders cost up to 1.5× AMD's
  /// multiply-adds, AMD on A. Only the order depends on it: the analysis is of A's own pattern.
  void analyze(const Matrix& a, std::span<const char> rows = {},
               std::span<const std::array<std::int32_t, 2>> groups = {});
  /// Whether every row of F = {k : on[k] != 0} was analysed (else analyze again with them).
  bool covers(std::span<const char> on) const;
  /// Whether row k was analysed.
  bool analysed(std::size_t k) const { return analysed_[static_cast<SparseIndex>(k)] != 0; }
  /// Whether `a` has the pattern analyze() was given.
  bool same_pattern(const Matrix& a) const;
  /// Forgets that pattern (same_pattern() is false until the next analyze()), keeping the storage.
  void forget_pattern() {
    outer_.clear();
    inner_.clear();
  }

  /// Numeric factorization of A_FF, F = {k : on[k] != 0} (rows analysed: covers(on)); returns the number
  /// of dropped rows (see the file comment). A row with A_kk ≤ floor (nothing movable behind it) is dropped too.
  /// With `shift` > 0 it factorizes A_FF + shift·I instead (positive definite: only rows with
  /// A_kk ≤ floor are dropped).
  std::size_t factorize(const Matrix& a, std::span<const char> on, double rank_tolerance, double floor,
                        double shift = 0.0);

  /// Solves A_FF x_F = b_F in place (original row order, size n): on exit x is 0 outside F and on the
  /// dropped rows.
  void solve(Eigen::Ref<Eigen::VectorXd> x) const;

  /// solve() in two halves, so that an update (a bordered system, complementarity.cpp) can correct the
  /// intermediate vector: forward() gives t = L⁻¹ P b on the rows of the factorization (elimination
  /// order, size rows(), zero elsewhere); backward() gives x = Pᵀ L⁻ᵀ D⁻¹ t, overwriting t.
  void forward(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::VectorXd& t) const;
  void backward(Eigen::VectorXd& t, Eigen::Ref<Eigen::VectorXd> x) const;
  /// The forward half for a right-hand side u with few non-zeros (pairs (original row, value); rows
  /// outside the factorization are ignored): w = L⁻¹ P u as its non-zeros (elimination order,
  /// increasing). It visits only the elimination-tree ancestors of u's rows (every entry L_ij lies on
  /// the path from j to the root), about the tree's height in columns instead of all of them.
  void forward_sparse(std::span<const std::pair<SparseIndex, double>> u, std::vector<SparseIndex>& index,
                      std::vector<double>& value) const;
  /// 1/d_i of row i in elimination order: 0 off the factorization and on dropped rows.
  double pivot_inverse(SparseIndex i) const { return d_inverse_[i]; }
  /// Flops (multiply-adds) of the last factorize(): the cost an update is weighed against.
  double factorization_work() const { return work_; }
  /// factorize() calls so far (with analyze() calls, which invalidate the factor): a caller that
  /// remembers the number of its own last factorization knows whether the factor is still that one.
  std::uint64_t factorizations() const { return factorizations_; }

  /// Rows of the last (shifted) factorization whose pivot is at most √(shift·A_kk): the rows (nearly)
  /// dependent on the rows eliminated before them (A_FF is singular if there is one).
  std::size_t redundant_rows(double shift) const;
  /// Whether row k (original index) was dropped by the last factorize().
  bool dropped(std::size_t k) const { return state_[new_of_old_[static_cast<SparseIndex>(k)]] == kDropped; }
  std::size_t rows() const { return static_cast<std::size_t>(order_.size()); }
  /// Entries of L the full pattern allows (work per solve ~ 2× this).
  std::size_t capacity() const { return static_cast<std::size_t>(l_index_.size()); }
  /// Groups of subtrees factorize() runs in parallel (0: one serial pass), planned by analyze() for the
  /// calling task arena's threads.
  std::size_t parallel_groups() const { return schedule_.empty() ? 0 : static_cast<std::size_t>(group_outer_.size() - 2); }

 private:
  static constexpr char kOff = 0, kOn = 1, kDropped = 2;
  static IndexVector<SparseIndex> minimum_degree(const Matrix& a);
  // The steps of analyze(): order_ and new_of_old_; the upper triangle of P A Pᵀ; the elimination tree,
  // column counts and column starts of L with the pattern of each row of L.
  void order_rows(const Matrix& a, std::span<const std::array<std::int32_t, 2>> groups);
  bool order_by_groups(std::span<const std::array<std::int32_t, 2>> groups);
  void upper_triangle();
  void symbolic();
  // The split of the elimination tree into subtrees factorized in parallel (see the file comment).
  void plan_subtrees(SparseIndex parts);
  // factorize() on the rows rows[0..count) in that order, with `stored` as the scratch of their entries;
  // adds the work, returns the rows dropped.
  std::size_t factorize_rows(const SparseIndex* rows, SparseIndex count, const Matrix& a, std::span<const char> on,
                             double rank_tolerance, double floor, double shift, SparseIndex* stored, double& work);

  IndexVector<SparseIndex> outer_, inner_;       // the pattern of A
  IndexVector<char> analysed_;                   // per row: in the analysed pattern (may be in F)
  IndexVector<SparseIndex> order_, new_of_old_;  // order_[new] = old
  IndexVector<SparseIndex> kept_, groups_start_, groups_index_;  // order_by_groups: Gᵀ on the analysed rows
  // Upper triangle of P A Pᵀ by columns (rows i ≤ k), each entry pointing into A's value array.
  IndexVector<SparseIndex> c_outer_, c_row_, c_value_;
  IndexVector<SparseIndex> parent_, l_outer_;    // elimination tree; column starts of L
  IndexVector<SparseIndex> l_count_, l_index_;
  IndexVector<SparseIndex> row_outer_, row_index_;  // pattern of each row of L for the full pattern (topological)
  IndexVector<double> l_value_, d_, d_inverse_, diag_;  // d_inverse_: 1/d on rows of F kept, else 0
  IndexVector<char> state_;
  // The parallel schedule (plan_subtrees): group g's rows are schedule_[group_outer_[g] .. group_outer_[g+1]),
  // increasing, each group a union of disjoint subtrees; the last group holds the rows above them and runs
  // after the others. Empty: one serial pass over every row.
  IndexVector<SparseIndex> schedule_, group_outer_;
  IndexVector<double> group_work_;            // per group of the last factorize()
  IndexVector<std::size_t> group_dropped_;
  IndexVector<SparseIndex> split_count_;      // per column: its entries in its own group's rows (0 above)
  struct PlanScratch {  // plan_subtrees()'s, kept so that a new analysis of a large island reuses it
    IndexVector<double> own, subtree;             // a row's multiply-adds; its subtree's
    IndexVector<SparseIndex> count, first_child, next_sibling, label;
    std::vector<std::pair<double, SparseIndex>> heap;
    std::vector<double> load;
  } plan_;
  // Workspace.
  mutable IndexVector<double> y_;
  IndexVector<SparseIndex> flag_, pattern_;
  mutable Eigen::VectorXd scratch_;                      // solve()'s intermediate vector
  mutable IndexVector<SparseIndex> reach_, visited_;     // forward_sparse: the ancestors, a visit stamp per row
  mutable SparseIndex stamp_ = 0;
  double work_ = 0.0;
  std::uint64_t factorizations_ = 0;
};

}  // namespace impetus::ledas
