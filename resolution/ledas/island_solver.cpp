// The island solver's set-up: construction, principal submatrices and the caches of symbolic
// analyses. The solves themselves: equality_solve.cpp (the paper mode's rounds), complementarity.cpp
// (the complementary mode and the position correction), complementarity_fallback.cpp.
#include "ledas/island_solver.hpp"
#include "ledas/masked_ldlt.hpp"
#include "ledas/solver_internal.hpp"

#include <algorithm>

namespace impetus::ledas {

namespace {
// Factorizations kept for reuse of their symbolic analysis (distinct sparsity patterns).
constexpr std::size_t kCacheCapacity = 16;
}  // namespace

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

std::unique_ptr<MaskedLdlt> IslandSolver::checkout_masked(const SparseMatrix& m, std::span<const char> likely,
                                                         SolverStats& stats) {
  for (auto it = masked_cache_.begin(); it != masked_cache_.end(); ++it) {
    if ((*it)->same_pattern(m)) {
      std::unique_ptr<MaskedLdlt> f = std::move(*it);
      masked_cache_.erase(it);
      ++stats.symbolic_reused;
      return f;
    }
  }
  auto f = std::make_unique<MaskedLdlt>();
  f->analyze(m, likely);
  ++stats.symbolic_analyses;
  return f;
}

void IslandSolver::checkin_masked(std::unique_ptr<MaskedLdlt> factor) {
  masked_cache_.push_back(std::move(factor));  // most recently used last
  if (masked_cache_.size() > kCacheCapacity) masked_cache_.erase(masked_cache_.begin());
}

}  // namespace impetus::ledas
