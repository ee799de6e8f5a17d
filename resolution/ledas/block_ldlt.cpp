// LDLᵀ by 6 × 6 blocks (block_ldlt.hpp).
#include "impetus/resolution/ledas/block_ldlt.hpp"

#include <Eigen/Cholesky>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>

#include <algorithm>
#include <numeric>

namespace impetus::ledas {

void BlockLdlt::analyze(std::span<const SparseIndex> start, std::span<const SparseIndex> neighbours) {
  const auto n = static_cast<SparseIndex>(start.size()) - 1;
  blocks_ = n;
  start_.assign(start.begin(), start.end());
  neighbours_.assign(neighbours.begin(), neighbours.end());
  const auto at = [](SparseIndex i) { return static_cast<std::size_t>(i); };

  // Approximate minimum degree on the graph of bodies (Eigen's AMD, which destroys its input).
  order_.resize(at(n));
  if (n > 2) {
    Eigen::SparseMatrix<double, Eigen::ColMajor, SparseIndex> graph(n, n);
    graph.resizeNonZeros(static_cast<Eigen::Index>(neighbours.size()));
    std::copy(start.begin(), start.end(), graph.outerIndexPtr());
    std::copy(neighbours.begin(), neighbours.end(), graph.innerIndexPtr());
    std::fill(graph.valuePtr(), graph.valuePtr() + neighbours.size(), 1.0);
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, SparseIndex> permutation;
    Eigen::internal::minimum_degree_ordering(graph, permutation);
    std::copy(permutation.indices().data(), permutation.indices().data() + n, order_.begin());
  } else {
    std::iota(order_.begin(), order_.end(), 0);
  }
  new_of_old_.resize(at(n));
  for (SparseIndex k = 0; k < n; ++k) new_of_old_[at(order_[at(k)])] = k;

  // Row k of the permuted lower triangle: the blocks of old column order_[k] whose new row is ≤ k.
  c_outer_.assign(at(n) + 1, 0);
  c_column_.clear();
  c_value_.clear();
  for (SparseIndex k = 0; k < n; ++k) {
    const SparseIndex t = order_[at(k)];
    for (SparseIndex e = start[at(t)]; e < start[at(t) + 1]; ++e)
      if (const SparseIndex i = new_of_old_[at(neighbours[at(e)])]; i <= k) {
        c_column_.push_back(i);
        c_value_.push_back(e);
      }
    c_outer_[at(k) + 1] = static_cast<SparseIndex>(c_column_.size());
  }

  // The elimination tree, the column counts of L and every row's pattern (columns i < k, descendants
  // first): row k's pattern is the set of tree paths from its entries up to k (ldl_symbolic's walk).
  parent_.assign(at(n), -1);
  l_count_.assign(at(n), 0);
  row_outer_.assign(at(n) + 1, 0);
  row_index_.clear();
  std::vector<SparseIndex> flag(at(n), -1), path(at(n));
  for (SparseIndex k = 0; k < n; ++k) {
    flag[at(k)] = k;
    SparseIndex top = n;
    for (SparseIndex p = c_outer_[at(k)]; p < c_outer_[at(k) + 1]; ++p) {
      SparseIndex length = 0;
      for (SparseIndex i = c_column_[at(p)]; flag[at(i)] != k; i = parent_[at(i)]) {
        if (parent_[at(i)] == -1) parent_[at(i)] = k;
        ++l_count_[at(i)];
        path[at(length++)] = i;
        flag[at(i)] = k;
      }
      while (length > 0) path[at(--top)] = path[at(--length)];
    }
    row_index_.insert(row_index_.end(), path.begin() + top, path.end());
    row_outer_[at(k) + 1] = static_cast<SparseIndex>(row_index_.size());
  }
  l_outer_.assign(at(n) + 1, 0);
  std::partial_sum(l_count_.begin(), l_count_.end(), l_outer_.begin() + 1);
  l_row_.resize(at(l_outer_.back()));
  l_value_.resize(l_row_.size());
  pivots_.resize(at(n));
  pivot_inverse_diagonal_.resize(at(n));
  y_.assign(at(n), Block::Zero());
  work_.resize(at(n));
}

bool BlockLdlt::same_pattern(std::span<const SparseIndex> start, std::span<const SparseIndex> neighbours) const {
  return std::equal(start.begin(), start.end(), start_.begin(), start_.end()) &&
         std::equal(neighbours.begin(), neighbours.end(), neighbours_.begin(), neighbours_.end());
}

// x ← D_k⁻¹ x by D_k = C Cᵀ: forward C y = x, then back Cᵀ x = y (written out: Eigen's triangular solve
// of a fixed 6 × 6 goes through its general kernel).
void BlockLdlt::solve_pivot(SparseIndex k, double* x) const {
  const Block& c = pivots_[static_cast<std::size_t>(k)];
  const Vector6& inverse = pivot_inverse_diagonal_[static_cast<std::size_t>(k)];
  for (int i = 0; i < 6; ++i) {
    double sum = x[i];
    for (int j = 0; j < i; ++j) sum -= c(i, j) * x[j];
    x[i] = sum * inverse(i);
  }
  for (int i = 6; i-- > 0;) {
    double sum = x[i];
    for (int j = i + 1; j < 6; ++j) sum -= c(j, i) * x[j];
    x[i] = sum * inverse(i);
  }
}

// l = z D_k⁻¹ by D_k = C Cᵀ, a column at a time for all six rows at once (Y Cᵀ = z forward, then
// l C = Y back): substitution, not a product with an inverse, whose rounding the ill-conditioned pivots
// of the interior point's late steps do not survive.
void BlockLdlt::divide_by_pivot(SparseIndex k, const Block& z, Block& l) const {
  const Block& c = pivots_[static_cast<std::size_t>(k)];
  const Vector6& inverse = pivot_inverse_diagonal_[static_cast<std::size_t>(k)];
  for (int j = 0; j < 6; ++j) {
    Vector6 column = z.col(j);
    for (int i = 0; i < j; ++i) column -= c(j, i) * l.col(i);
    l.col(j) = column * inverse(j);
  }
  for (int j = 6; j-- > 0;) {
    Vector6 column = l.col(j);
    for (int i = j + 1; i < 6; ++i) column -= c(i, j) * l.col(i);
    l.col(j) = column * inverse(j);
  }
}

bool BlockLdlt::factorize(std::span<const Block> values) {
  const auto at = [](SparseIndex i) { return static_cast<std::size_t>(i); };
  std::fill(l_count_.begin(), l_count_.end(), 0);
  for (SparseIndex k = 0; k < blocks_; ++k) {
    // Scatter row k: A_ki = (block (old i, old k))ᵀ.
    Block pivot = Block::Zero();
    for (SparseIndex p = c_outer_[at(k)]; p < c_outer_[at(k) + 1]; ++p) {
      const Block& a = values[at(c_value_[at(p)])];
      if (const SparseIndex i = c_column_[at(p)]; i == k) pivot = a;
      else y_[at(i)] = a.transpose();
    }
    // Row k of L by the sparse triangular solve along the tree: Z_ki = L_ki D_i accumulates
    // A_ki − Σ_{j<i} Z_kj L_ijᵀ; then L_ki = Z_ki D_i⁻¹ and D_k = A_kk − Σ_i L_ki Z_kiᵀ.
    for (SparseIndex t = row_outer_[at(k)]; t < row_outer_[at(k) + 1]; ++t) {
      const SparseIndex i = row_index_[at(t)];
      const Block z = y_[at(i)];
      y_[at(i)].setZero();
      const SparseIndex first = l_outer_[at(i)], last = first + l_count_[at(i)];
      for (SparseIndex q = first; q < last; ++q) y_[at(l_row_[at(q)])].noalias() -= z * l_value_[at(q)].transpose();
      Block& l = l_value_[at(last)];
      divide_by_pivot(i, z, l);
      pivot.noalias() -= l * z.transpose();
      l_row_[at(last)] = k;
      ++l_count_[at(i)];
    }
    const Eigen::LLT<Block> cholesky(pivot);
    if (!pivot.allFinite() || cholesky.info() != Eigen::Success) return false;
    pivots_[at(k)] = cholesky.matrixLLT();
    pivot_inverse_diagonal_[at(k)] = pivots_[at(k)].diagonal().cwiseInverse();
  }
  return true;
}

void BlockLdlt::solve(Eigen::Ref<Eigen::VectorXd> x) const {
  const auto at = [](SparseIndex i) { return static_cast<std::size_t>(i); };
  for (SparseIndex k = 0; k < blocks_; ++k) work_[at(k)] = x.segment<6>(6 * order_[at(k)]);
  for (SparseIndex i = 0; i < blocks_; ++i)  // L y = P b
    for (SparseIndex q = l_outer_[at(i)]; q < l_outer_[at(i)] + l_count_[at(i)]; ++q)
      work_[at(l_row_[at(q)])].noalias() -= l_value_[at(q)] * work_[at(i)];
  for (SparseIndex i = blocks_; i-- > 0;) {  // D⁻¹, then Lᵀ x = y
    Vector6 v = work_[at(i)];
    solve_pivot(i, v.data());
    for (SparseIndex q = l_outer_[at(i)]; q < l_outer_[at(i)] + l_count_[at(i)]; ++q)
      v.noalias() -= l_value_[at(q)].transpose() * work_[at(l_row_[at(q)])];
    work_[at(i)] = v;
  }
  for (SparseIndex k = 0; k < blocks_; ++k) x.segment<6>(6 * order_[at(k)]) = work_[at(k)];
}

}  // namespace impetus::ledas
