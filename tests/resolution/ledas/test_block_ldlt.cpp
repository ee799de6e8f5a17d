// The block LDLᵀ of the body-space interior point (block_ldlt.hpp), against Eigen's dense LDLᵀ of the
// same matrix.
#include "impetus/resolution/ledas/block_ldlt.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cstdint>
#include <set>
#include <utility>
#include <vector>

namespace impetus::ledas {
namespace {

using Block = BlockLdlt::Block;

// A random symmetric block pattern on `bodies` bodies (a chain plus `extra` seeded links) and values
// Σ_links g gᵀ (rank-one 12-wide rows, like contact rows) plus a positive diagonal of `diagonal`.
struct Problem {
  std::vector<SparseIndex> start, neighbours;
  std::vector<Block> values;
  Eigen::MatrixXd dense;
};

Problem random_problem(int bodies, int extra, double diagonal, std::uint64_t seed) {
  std::uint64_t state = seed;
  const auto uniform = [&state] {  // in [−1, 1)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / static_cast<double>(1ULL << 52) - 1.0;
  };
  std::set<std::pair<int, int>> links;
  for (int b = 0; b + 1 < bodies; ++b) links.emplace(b, b + 1);
  while (static_cast<int>(links.size()) < bodies - 1 + extra) {
    const int a = static_cast<int>((uniform() + 1.0) * 0.5 * bodies), b = static_cast<int>((uniform() + 1.0) * 0.5 * bodies);
    if (a != b) links.emplace(std::min(a, b), std::max(a, b));
  }
  Problem p;
  const int n = 6 * bodies;
  p.dense = diagonal * Eigen::MatrixXd::Identity(n, n);
  for (const auto& [a, b] : links)
    for (int row = 0; row < 3; ++row) {  // three rows per link
      Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
      for (int d = 0; d < 6; ++d) g(6 * a + d) = uniform(), g(6 * b + d) = uniform();
      p.dense += g * g.transpose();
    }
  std::vector<std::set<int>> columns(static_cast<std::size_t>(bodies));
  for (int b = 0; b < bodies; ++b) columns[static_cast<std::size_t>(b)].insert(b);
  for (const auto& [a, b] : links) columns[static_cast<std::size_t>(a)].insert(b), columns[static_cast<std::size_t>(b)].insert(a);
  p.start.push_back(0);
  for (int t = 0; t < bodies; ++t) {
    for (const int s : columns[static_cast<std::size_t>(t)]) {
      p.neighbours.push_back(s);
      p.values.push_back(p.dense.block<6, 6>(6 * s, 6 * t));
    }
    p.start.push_back(static_cast<SparseIndex>(p.neighbours.size()));
  }
  return p;
}

TEST(BlockLdlt, SolvesLikeTheDenseFactorization) {
  for (const auto& [bodies, extra] : {std::pair{1, 0}, std::pair{2, 0}, std::pair{7, 5}, std::pair{60, 80}, std::pair{100, 200}}) {
    const Problem p = random_problem(bodies, extra, 1.0, 0xB10C + static_cast<std::uint64_t>(bodies));
    BlockLdlt ldlt;
    ldlt.analyze(p.start, p.neighbours);
    EXPECT_TRUE(ldlt.same_pattern(p.start, p.neighbours));
    ASSERT_TRUE(ldlt.factorize(p.values)) << bodies << " bodies";
    Eigen::VectorXd b(6 * bodies);
    for (Eigen::Index i = 0; i < b.size(); ++i) b(i) = std::sin(1.0 + static_cast<double>(i));
    Eigen::VectorXd x = b;
    ldlt.solve(x);
    const Eigen::VectorXd reference = p.dense.ldlt().solve(b);
    // Both backward stable: the difference is bounded by the condition number times rounding.
    const double condition = p.dense.norm() * p.dense.inverse().norm();
    EXPECT_LE((x - reference).norm(), 1e-14 * condition * reference.norm()) << bodies << " bodies";
    EXPECT_LE((p.dense * x - b).norm(), 1e-12 * p.dense.norm() * x.norm()) << bodies << " bodies";
  }
}

TEST(BlockLdlt, RefusesAMatrixThatIsNotPositiveDefinite) {
  Problem p = random_problem(30, 20, 1.0, 0xB10D);
  BlockLdlt ldlt;
  ldlt.analyze(p.start, p.neighbours);
  // Body 17's diagonal block made negative definite: the matrix is indefinite.
  const auto diagonal = std::find(p.neighbours.begin() + p.start[17], p.neighbours.begin() + p.start[18], 17);
  p.values[static_cast<std::size_t>(diagonal - p.neighbours.begin())] -= 1e6 * Block::Identity();
  EXPECT_FALSE(ldlt.factorize(p.values));
  p.values[static_cast<std::size_t>(diagonal - p.neighbours.begin())](2, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(ldlt.factorize(p.values));
}

}  // namespace
}  // namespace impetus::ledas
