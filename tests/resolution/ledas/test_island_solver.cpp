// The island solver on its own: the complementarity solution against brute force, minimum-norm
// solutions of singular systems against the pseudo-inverse, the update path against refactoring.
#include "impetus/resolution/ledas/island_solver.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace impetus::ledas {
namespace {

// A = B M⁻¹ Bᵀ like the contact matrix: B sparse (rows × dofs), M = I. Rank ≤ dofs.
SparseMatrix contact_like_matrix(int rows, int dofs, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(rows, dofs);
  for (int i = 0; i < rows; ++i)
    for (int k = 0; k < 3; ++k) b(i, (i * 2 + k * 3) % dofs) += u(rng);  // each row touches a few dofs
  const Eigen::MatrixXd a = b * b.transpose();
  return a.sparseView(1e-300);
}

std::vector<RowIndex> all_rows(Eigen::Index n) {
  std::vector<RowIndex> out(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<RowIndex>(i);
  return out;
}

Vector pseudo_inverse_solution(const SparseMatrix& a, const Vector& c) {
  return Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(Eigen::MatrixXd(a)).solve(c);
}

// Positive definite 6×6 problems: the unique LCP solution equals the one found by trying all 2⁶
// active sets (1e-10); the solver's answer satisfies p ≥ 0, w ≥ −1e-12, |p·w| ≤ 1e-12 (1 + |p|²).
TEST(IslandSolver, ComplementarityMatchesBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const SparseMatrix a = contact_like_matrix(6, 9, rng);
    Vector c(6);
    for (int i = 0; i < 6; ++i) c(i) = u(rng);
    IslandSolver solver;
    ComplementarityProblem problem{&a, c, std::vector<char>(6, 0), std::vector<char>(6, 0), 1e-12};
    for (int i = 0; i < 6; ++i) problem.start[static_cast<std::size_t>(i)] = c(i) > 0;
    SolverStats stats;
    const Vector p = solver.solve_complementarity(problem, stats);
    const Vector w = a * p - c;
    EXPECT_GE(p.minCoeff(), 0.0);
    EXPECT_GE(w.minCoeff(), -1e-12);
    EXPECT_LE(p.cwiseProduct(w).cwiseAbs().maxCoeff(), 1e-12 * (1 + p.squaredNorm()));
    EXPECT_EQ(stats.non_converged, 0u);
    Vector brute;
    for (int mask = 0; mask < 64 && brute.size() == 0; ++mask) {
      std::vector<RowIndex> set;
      for (int i = 0; i < 6; ++i)
        if (mask >> i & 1) set.push_back(static_cast<RowIndex>(i));
      SolverStats ignored;
      const Vector q = solver.solve_subset(a, c, set, ignored);
      const Vector r = a * q - c;
      if (q.minCoeff() >= -1e-12 && r.minCoeff() >= -1e-12) brute = q;
    }
    ASSERT_EQ(brute.size(), 6);
    EXPECT_LT((p - brute).norm(), 1e-10);
  }
}

// Singular systems (12 rows, rank 8): the dense path, the sparse path (dense_limit 4) and the
// pseudo-inverse agree (1e-9 relative), for right-hand sides in the range and for inconsistent ones
// (minimum-norm least squares); both paths report the system singular.
TEST(IslandSolver, MinimumNormSolutionsOfSingularSystems) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const SparseMatrix a = contact_like_matrix(12, 8, rng);
    for (bool consistent : {true, false}) {
      Vector c(12);
      for (int i = 0; i < 12; ++i) c(i) = u(rng);
      if (consistent) c = a * c;
      const Vector expected = pseudo_inverse_solution(a, c);
      for (std::size_t limit : {std::size_t{4}, std::size_t{64}}) {
        SolverSettings settings;
        settings.dense_limit = limit;
        IslandSolver solver(settings);
        SolverStats stats;
        const Vector p = solver.solve_subset(a, c, all_rows(12), stats);
        EXPECT_LT((p - expected).norm(), 1e-9 * expected.norm()) << "dense_limit " << limit;
        EXPECT_EQ(stats.singular, 1u);
        EXPECT_EQ(limit == 4 ? stats.sparse : stats.dense, 1u);
      }
    }
  }
}

// A larger positive definite problem solved on the sparse path (dense_limit 4): the same solution as
// the dense path (1e-9); small active-set changes are solved by updates, and a second solve of the same
// pattern reuses the cached symbolic analysis.
TEST(IslandSolver, SparseUpdatesMatchTheDensePath) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uint64_t updates = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const SparseMatrix a = contact_like_matrix(80, 120, rng);
    Vector c(80);
    for (int i = 0; i < 80; ++i) c(i) = u(rng) + 0.3;  // most rows start active, a few pull
    ComplementarityProblem problem{&a, c, std::vector<char>(80, 0), std::vector<char>(80, 1), 1e-12};
    SolverSettings sparse_settings;
    sparse_settings.dense_limit = 4;
    SolverSettings dense_settings;
    dense_settings.dense_limit = 1000;
    IslandSolver sparse(sparse_settings), dense(dense_settings);
    SolverStats s1, s2;
    const Vector p = sparse.solve_complementarity(problem, s1);
    const Vector q = dense.solve_complementarity(problem, s2);
    EXPECT_LT((p - q).norm(), 1e-9 * (1 + q.norm()));
    EXPECT_EQ(s1.non_converged + s2.non_converged, 0u);
    updates += s1.updated;
    SolverStats again;
    sparse.solve_complementarity(problem, again);
    EXPECT_GT(again.symbolic_reused, 0u);
  }
  EXPECT_GT(updates, 0u);
}

// Equality rows are never released, even when their impulse is negative.
TEST(IslandSolver, EqualityRowsKeepNegativeImpulses) {
  Eigen::Matrix2d dense;
  dense << 2.0, 1.0, 1.0, 2.0;
  const SparseMatrix a = dense.sparseView();
  ComplementarityProblem problem{&a, Vector(Eigen::Vector2d(-1.0, 1.0)), {1, 0}, {0, 1}, 1e-12};
  IslandSolver solver;
  SolverStats stats;
  const Vector p = solver.solve_complementarity(problem, stats);
  EXPECT_NEAR(p(0), -1.0, 1e-12);  // 2 p0 + p1 = −1, p0 + 2 p1 = 1
  EXPECT_NEAR(p(1), 1.0, 1e-12);
  const Vector w = a * p - problem.rhs;
  EXPECT_NEAR(w(0), 0.0, 1e-12);
  EXPECT_GE(w(1), -1e-12);
  EXPECT_LE(std::abs(p(1) * w(1)), 1e-12);
}

// Two identical rows (a duplicated contact) asking for different separations, A = [[2, 2], [2, 2]],
// c = (2, 1): the equality system is singular and inconsistent. The solution is p = (1, 0): the larger
// demand is met, the other row is left with slack w = 1 (1e-12).
TEST(IslandSolver, InconsistentSingularSystemIsSolved) {
  Eigen::Matrix2d dense;
  dense << 2.0, 2.0, 2.0, 2.0;
  const SparseMatrix a = dense.sparseView();
  ComplementarityProblem problem{&a, Vector(Eigen::Vector2d(2.0, 1.0)), {0, 0}, {1, 1}, 1e-12};
  IslandSolver solver;
  SolverStats stats;
  const Vector p = solver.solve_complementarity(problem, stats);
  EXPECT_NEAR(p(0), 1.0, 1e-12);
  EXPECT_NEAR(p(1), 0.0, 1e-12);
  EXPECT_EQ(stats.non_converged, 0u);
  EXPECT_GE(stats.singular, 1u);
}

}  // namespace
}  // namespace impetus::ledas
