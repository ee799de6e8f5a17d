// The fast paths of the LEDAS resolver checked against straightforward references: the masked sparse
// LDLᵀ against dense algebra, the proximal complementarity solve on rank-deficient start sets, and the
// paper mode's cheap rounds against the rounds written out literally (sec. 3.2).
#include "impetus/engine/generators.hpp"
#include "impetus/resolution/ledas/island_solver.hpp"
#include "impetus/resolution/ledas/masked_ldlt.hpp"
#include "ledas_test_support.hpp"

#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

namespace impetus {
namespace {

using namespace ledas_test;
using ledas::SparseMatrix;
using ledas::Vector;

// A = B Bᵀ like the contact matrix (B: rows × dofs, each row touching three dofs). Rank ≤ dofs.
SparseMatrix contact_like_matrix(int rows, int dofs, std::mt19937& rng, Eigen::MatrixXd* b_out = nullptr) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(rows, dofs);
  for (int i = 0; i < rows; ++i)
    for (int k = 0; k < 3; ++k) b(i, (i * 2 + k * 3) % dofs) += u(rng);
  if (b_out) *b_out = b;
  const Eigen::MatrixXd a = b * b.transpose();
  return a.sparseView(1e-300);
}

// Masked LDLᵀ of a rank-deficient A (60 rows, rank ≤ 24) on random row subsets F, consistent
// right-hand sides c = A x: the solution satisfies A_FF z = c_F (1e-9 relative), is zero outside F and
// on the dropped rows, and the kept rows number rank(A_FF) (dense rank with the same 1e-10 tolerance).
TEST(MaskedLdlt, SolvesPrincipalSubmatricesAndDropsDependentRows) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::bernoulli_distribution coin(0.7);
  const SparseMatrix a = contact_like_matrix(60, 24, rng);
  ledas::MaskedLdlt ldlt;
  ldlt.analyze(a);
  ASSERT_TRUE(ldlt.same_pattern(a));
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<char> on(60);
    for (char& f : on) f = coin(rng);
    Vector x(60);
    for (int i = 0; i < 60; ++i) x(i) = on[static_cast<std::size_t>(i)] ? u(rng) : 0.0;
    const Vector c = a * x;
    const std::size_t dropped = ldlt.factorize(a, on, 1e-10, 1e-12);
    Vector z = c;
    ldlt.solve(z);
    std::vector<int> kept;
    for (int i = 0; i < 60; ++i) {
      if (!on[static_cast<std::size_t>(i)] || ldlt.dropped(static_cast<std::size_t>(i))) {
        EXPECT_EQ(z(i), 0.0);
      } else {
        kept.push_back(i);
      }
    }
    const Vector r = a * z - c;
    for (int i = 0; i < 60; ++i) {
      if (on[static_cast<std::size_t>(i)]) {
        EXPECT_LT(std::abs(r(i)), 1e-9 * c.norm()) << "row " << i;
      }
    }
    std::vector<int> members;
    for (int i = 0; i < 60; ++i)
      if (on[static_cast<std::size_t>(i)]) members.push_back(i);
    Eigen::MatrixXd sub(members.size(), members.size());
    for (std::size_t i = 0; i < members.size(); ++i)
      for (std::size_t j = 0; j < members.size(); ++j) sub(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = a.coeff(members[i], members[j]);
    Eigen::FullPivLU<Eigen::MatrixXd> lu(sub);
    lu.setThreshold(1e-10);
    EXPECT_EQ(kept.size(), static_cast<std::size_t>(lu.rank()));
    EXPECT_EQ(kept.size() + dropped, members.size());
  }
}

// The halves of a solve and the sparse forward solve of an update (complementarity.cpp): on random
// subsets F of a shifted 200-row problem, forward() then backward() is solve() (1e-14 relative), and
// forward_sparse() of a right-hand side with three non-zeros equals forward() of it (1e-14 relative)
// while returning only entries on the elimination-tree path of those rows (fewer than all rows).
TEST(MaskedLdlt, SparseForwardSolveMatchesTheFullOne) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::bernoulli_distribution coin(0.8);
  std::uniform_int_distribution<int> pick(0, 199);
  const SparseMatrix a = contact_like_matrix(200, 300, rng);
  ledas::MaskedLdlt ldlt;
  ldlt.analyze(a);
  for (int trial = 0; trial < 10; ++trial) {
    std::vector<char> on(200);
    for (char& f : on) f = coin(rng);
    ldlt.factorize(a, on, 1e-10, 1e-12, 1e-3);
    Vector b = Vector::NullaryExpr(200, [&] { return u(rng); });
    Vector whole = b, t, halves(200);
    ldlt.solve(whole);
    ldlt.forward(b, t);
    ldlt.backward(t, halves);
    EXPECT_LE((whole - halves).norm(), 1e-14 * whole.norm());
    std::vector<std::pair<int, double>> sparse;
    Vector dense = Vector::Zero(200);
    for (int k = 0; k < 3; ++k) {
      const int row = pick(rng);
      const double value = u(rng);
      sparse.emplace_back(row, value);
      dense(row) += value;
    }
    std::vector<int> index;
    std::vector<double> value;
    ldlt.forward_sparse(sparse, index, value);
    ldlt.forward(dense, t);
    Vector from_sparse = Vector::Zero(200);
    for (std::size_t q = 0; q < index.size(); ++q) from_sparse(index[q]) = value[q];
    EXPECT_LE((from_sparse - t).norm(), 1e-14 * (1.0 + t.norm()));
    EXPECT_LT(index.size(), 200u);
  }
}

// A contact matrix of a grid of bodies (2 dofs each) touching their right and upper neighbours, one row
// per contact on the 4 dofs of its pair: a sparse, two-dimensional pattern like a pyramid's, with more
// rows than dofs (rank deficient, so rows are dropped).
SparseMatrix grid_contact_matrix(int side, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  int row = 0;
  const auto contact = [&](int a, int b) {
    for (const int body : {a, b})
      for (int d = 0; d < 2; ++d) entries.emplace_back(row, 2 * body + d, u(rng));
    ++row;
  };
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      if (x + 1 < side) contact(y * side + x, y * side + x + 1);
      if (y + 1 < side) contact(y * side + x, (y + 1) * side + x);
    }
  SparseMatrix b(row, 2 * side * side);
  b.setFromTriplets(entries.begin(), entries.end());
  SparseMatrix a = b * SparseMatrix(b.transpose());
  a.makeCompressed();
  return a;
}

// The rows' bodies of grid_contact_matrix(side): per row, its pair, in the same order.
std::vector<std::array<std::int32_t, 2>> grid_contact_groups(int side) {
  std::vector<std::array<std::int32_t, 2>> groups;
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      if (x + 1 < side) groups.push_back({y * side + x, y * side + x + 1});
      if (y + 1 < side) groups.push_back({y * side + x, (y + 1) * side + x});
    }
  return groups;
}

// The order read from the rows' bodies (COLAMD on G, MaskedLdlt::analyze) changes only the order: on a
// 24 × 24 grid (1,104 rows, all analysed and a random 70% of them), for random subsets F of the analysed
// rows with the shift 1e-3 (A_FF + εI positive definite, one solution), the solution solves
// (A_FF + εI) z = c_F (1e-10 relative) and equals the one factorized in AMD's order (1e-9 relative). Groups
// that are not one per row are ignored (AMD's order, the same solution).
TEST(MaskedLdlt, OrderFromTheRowsBodiesSolvesTheSameSystems) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::bernoulli_distribution coin(0.7);
  constexpr int kSide = 24;
  const SparseMatrix a = grid_contact_matrix(kSide, rng);
  const auto groups = grid_contact_groups(kSide);
  const auto n = static_cast<std::size_t>(a.rows());
  ASSERT_EQ(groups.size(), n);
  const std::vector<std::array<std::int32_t, 2>> short_groups(groups.begin(), groups.end() - 1);
  constexpr double kShift = 1e-3;
  for (const bool all : {true, false}) {
    std::vector<char> analysed(n, 1);
    if (!all)
      for (char& f : analysed) f = coin(rng);
    ledas::MaskedLdlt by_groups, by_matrix, ignored;
    by_groups.analyze(a, analysed, groups);
    by_matrix.analyze(a, analysed);
    ignored.analyze(a, analysed, short_groups);
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<char> on(n, 0);
      for (std::size_t k = 0; k < n; ++k) on[k] = analysed[k] && coin(rng);
      Vector c = Vector::NullaryExpr(a.rows(), [&] { return u(rng); });
      for (std::size_t k = 0; k < n; ++k)
        if (!on[k]) c(static_cast<Eigen::Index>(k)) = 0.0;
      Vector z = c, reference = c, fallback = c;
      ASSERT_EQ(by_groups.factorize(a, on, 1e-10, 1e-12, kShift), 0u);
      by_groups.solve(z);
      by_matrix.factorize(a, on, 1e-10, 1e-12, kShift);
      by_matrix.solve(reference);
      ignored.factorize(a, on, 1e-10, 1e-12, kShift);
      ignored.solve(fallback);
      Vector r = a * z + kShift * z - c;
      for (std::size_t k = 0; k < n; ++k)
        if (!on[k]) r(static_cast<Eigen::Index>(k)) = 0.0;
      EXPECT_LE(r.norm(), 1e-10 * c.norm()) << (all ? "all rows" : "70% of the rows") << ", trial " << trial;
      EXPECT_LE((z - reference).norm(), 1e-9 * reference.norm());
      EXPECT_EQ(fallback, reference);  // the same order, so the same bits
    }
  }
}

// The parallel factorization (subtrees of the elimination tree on threads) gives the serial one's bits:
// a 1,740-row grid problem analysed and factorized in an arena of one thread and in one of four, on
// random subsets F, with and without a shift. The four-thread analysis does split the tree; both drop
// the same rows, and their solutions are identical to the bit and solve A_FF z = c_F (1e-9 relative).
TEST(MaskedLdlt, ParallelSubtreesGiveTheSerialBits) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::bernoulli_distribution coin(0.85);
  const SparseMatrix a = grid_contact_matrix(30, rng);
  const auto n = static_cast<int>(a.rows());
  ledas::MaskedLdlt serial, parallel;
  tbb::task_arena one(1), four(4);
  one.execute([&] { serial.analyze(a); });
  four.execute([&] { parallel.analyze(a); });
  EXPECT_EQ(serial.parallel_groups(), 0u);
  ASSERT_GE(parallel.parallel_groups(), 2u);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<char> on(static_cast<std::size_t>(n));
    for (char& f : on) f = coin(rng);
    Vector x(n);
    for (int i = 0; i < n; ++i) x(i) = on[static_cast<std::size_t>(i)] ? u(rng) : 0.0;
    const Vector c = a * x;
    const double shift = trial % 2 == 0 ? 0.0 : 1e-3;
    std::size_t dropped_serial = 0, dropped_parallel = 0;
    one.execute([&] { dropped_serial = serial.factorize(a, on, 1e-10, 1e-12, shift); });
    four.execute([&] { dropped_parallel = parallel.factorize(a, on, 1e-10, 1e-12, shift); });
    EXPECT_EQ(dropped_serial, dropped_parallel);
    EXPECT_EQ(serial.factorization_work(), parallel.factorization_work());
    Vector zs = c, zp = c;
    serial.solve(zs);
    parallel.solve(zp);
    EXPECT_EQ(std::memcmp(zs.data(), zp.data(), sizeof(double) * static_cast<std::size_t>(n)), 0) << "trial " << trial;
    if (shift == 0.0) {
      const Vector r = a * zp - c;
      for (int i = 0; i < n; ++i) {
        if (on[static_cast<std::size_t>(i)]) {
          EXPECT_LT(std::abs(r(i)), 1e-9 * c.norm()) << "row " << i;
        }
      }
    }
  }
}

// Updates of many rows (the automatic limit, √m) give the solution refactoring gives: a 400-row
// problem whose active set changes by tens of rows per iteration, solved with update_limit 1 (every
// larger change refactors) and automatic; the solutions agree to 1e-9 relative, both are complementary
// (p ≥ 0, w ≥ −1e-9, the resolver's default tolerance), and the automatic run refactors less often.
TEST(IslandSolver, LargeUpdatesMatchRefactoring) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    const SparseMatrix a = contact_like_matrix(400, 600, rng);
    Vector c(400);
    for (int i = 0; i < 400; ++i) c(i) = u(rng) + 0.5;  // most rows start active, tens pull
    const ledas::ComplementarityProblem problem{&a, c, std::vector<char>(400, 0), std::vector<char>(400, 1), 1e-9};
    ledas::SolverSettings refactor_settings;
    refactor_settings.update_limit = 1;
    ledas::IslandSolver refactoring(refactor_settings), updating;
    ledas::SolverStats by_refactor, by_update;
    const Vector q = refactoring.solve_complementarity(problem, by_refactor);
    const Vector p = updating.solve_complementarity(problem, by_update);
    EXPECT_LE((p - q).norm(), 1e-9 * (1.0 + q.norm()));
    EXPECT_EQ(by_refactor.non_converged + by_update.non_converged, 0u);
    EXPECT_LT(by_update.sparse, by_refactor.sparse);
    const Vector w = a * p - c;
    EXPECT_GE(p.minCoeff(), 0.0);
    EXPECT_GE(w.minCoeff(), -1e-9);
  }
}

// A rank-deficient start set (60 rows on 24 degrees of freedom, every row free at the start, c = −B v
// like contacts' −G v⁻): the complementarity solution is exact to rounding (p ≥ 0,
// w ≥ −1e-12 (1 + |p|∞), |p·w| ≤ 1e-12 (1 + |p|²); tolerance 1e-12) and
// the velocity change Bᵀp — unique, although p is not — is the same from a different start set (1e-9).
TEST(IslandSolver, RankDeficientStartSetIsSolvedExactly) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    Eigen::MatrixXd b;
    const SparseMatrix a = contact_like_matrix(60, 24, rng, &b);
    Vector v(24);
    for (int i = 0; i < 24; ++i) v(i) = u(rng);
    const Vector c = -b * v;
    Vector first_change;
    for (bool all_start : {true, false}) {
      ledas::ComplementarityProblem problem{&a, c, std::vector<char>(60, 0), std::vector<char>(60, 0), 1e-12};
      for (int i = 0; i < 60; ++i) problem.start[static_cast<std::size_t>(i)] = all_start || c(i) > 0.0;
      ledas::IslandSolver solver;
      ledas::SolverStats stats;
      const Vector p = solver.solve_complementarity(problem, stats);
      const Vector w = a * p - c;
      EXPECT_GE(p.minCoeff(), 0.0);
      EXPECT_GE(w.minCoeff(), -1e-12 * (1.0 + p.lpNorm<Eigen::Infinity>()));
      EXPECT_LE(p.cwiseProduct(w).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + p.squaredNorm()));
      EXPECT_EQ(stats.non_converged, 0u);
      const Vector change = b.transpose() * p;
      if (all_start) {
        EXPECT_GE(stats.singular, 1u);
        first_change = change;
      } else {
        EXPECT_LT((change - first_change).norm(), 1e-9 * (1.0 + first_change.norm()));
      }
    }
  }
}

// The paper's rounds written out literally (sec. 3.2): every round recomputes every contact's velocity
// from the bodies, builds the dense A_SS of the approaching contacts (eq. 7), solves A_SS p = −v_S by
// the minimum-norm least squares (the paper's SVD), applies (1 + e) p (eq. 3) and repeats until no
// contact approaches.
struct Reference {
  std::vector<RigidBody> bodies;
  std::vector<double> impulses;
  std::uint64_t rounds = 0;
  double complementarity = 0.0;  // max |P_k v_k| after the last round's inelastic phase (P = Σ p)
};

Reference paper_rounds(std::vector<RigidBody> bodies, const std::vector<Contact>& contacts, double tolerance,
                       const resolution::RestingSettings& resting) {
  std::vector<resolution::ImpulseRow> rows;
  for (const Contact& c : contacts) rows.push_back(resolution::make_contact_row(bodies, c));
  double impact = 0.0;
  for (const auto& r : rows) impact = std::max(impact, -resolution::row_velocity(r, bodies));
  std::vector<double> e(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) e[k] = resolution::effective_restitution(rows[k], impact, resting);
  Reference out;
  out.impulses.assign(rows.size(), 0.0);
  std::vector<double> inelastic(rows.size(), 0.0);
  for (;; ++out.rounds) {
    std::vector<std::size_t> s;
    std::vector<double> v;
    for (std::size_t k = 0; k < rows.size(); ++k)
      if (const double vk = resolution::row_velocity(rows[k], bodies); vk < -tolerance) s.push_back(k), v.push_back(vk);
    if (s.empty()) break;
    const auto n = static_cast<Eigen::Index>(s.size());
    Eigen::MatrixXd a(n, n);
    Eigen::VectorXd b(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      b(i) = -v[static_cast<std::size_t>(i)];
      for (Eigen::Index j = 0; j < n; ++j) a(i, j) = resolution::coupling(rows[s[static_cast<std::size_t>(i)]], rows[s[static_cast<std::size_t>(j)]]);
    }
    const Eigen::VectorXd p = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(a).solve(b);
    for (Eigen::Index i = 0; i < n; ++i) resolution::apply_row_impulse(rows[s[static_cast<std::size_t>(i)]], p(i), bodies);
    for (Eigen::Index i = 0; i < n; ++i) inelastic[s[static_cast<std::size_t>(i)]] += p(i);
    out.complementarity = 0.0;
    for (std::size_t k = 0; k < rows.size(); ++k)
      out.complementarity = std::max(out.complementarity, std::abs(inelastic[k] * resolution::row_velocity(rows[k], bodies)));
    for (Eigen::Index i = 0; i < n; ++i) {
      const std::size_t k = s[static_cast<std::size_t>(i)];
      if (e[k] != 0.0) resolution::apply_row_impulse(rows[k], e[k] * p(i), bodies);
      out.impulses[k] += (1.0 + e[k]) * p(i);
    }
  }
  out.bodies = std::move(bodies);
  return out;
}

// Paper mode (cheap rounds: only the rows of moved bodies re-checked — by a scan, or from the moved
// rows alone when they are few, as on the line of 100 — the subset split into blocks, closed form for
// single rows) against the literal rounds: the same number of rounds, the same impulses and velocities
// to 1e-12 (N·s, m/s) and the same complementarity error after the last inelastic phase (1e-12), on
// scenes with pulling impulses (pyramid), many rounds (line, e = 0) and restitution (line, e = 1).
TEST(LedasPaperRounds, MatchTheLiteralRounds) {
  struct Case {
    const char* name;
    std::vector<RigidBody> bodies;
  };
  std::vector<Case> cases;
  for (int k : {3, 4, 10}) {
    PyramidParams params;
    params.rows = k;
    cases.push_back({"pyramid", make_pyramid(params)});
  }
  for (double e : {0.0, 1.0}) {
    LineParams params;
    params.count = 10;
    params.restitution = e;
    cases.push_back({e == 0.0 ? "line e=0" : "line e=1", make_line(params)});
  }
  LineParams long_line;
  long_line.count = 100;
  long_line.restitution = 1.0;
  cases.push_back({"line N=100 e=1", make_line(long_line)});
  for (const Case& c : cases) {
    std::vector<RigidBody> bodies = c.bodies;
    std::vector<Contact> contacts = sphere_contacts(bodies);
    LedasSettings settings = settings_for(LedasMode::paper);
    settings.resting.correction = 0.0;
    const Reference expected = paper_rounds(bodies, contacts, settings.tolerance, settings.resting);
    LedasResolver resolver(settings);
    const ResolverCounters counters = resolve(resolver, bodies, contacts);
    EXPECT_EQ(resolver.last_stats().rounds, expected.rounds) << c.name;
    EXPECT_NEAR(counters.complementarity_error, expected.complementarity, 1e-12) << c.name;
    for (std::size_t k = 0; k < contacts.size(); ++k) EXPECT_NEAR(contacts[k].impulse, expected.impulses[k], 1e-12) << c.name << " contact " << k;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      EXPECT_LT((bodies[i].velocity - expected.bodies[i].velocity).norm(), 1e-12) << c.name << " body " << i;
      EXPECT_LT((bodies[i].angular_velocity - expected.bodies[i].angular_velocity).norm(), 1e-12) << c.name << " body " << i;
    }
  }
}

TEST(LedasIslands, OneSystemGivesTheSameVelocitiesAsIslandByIsland) {
  // Two pyramids (K = 4) side by side on one fixed ground: two islands, or one system with
  // `islands: false`. Fixed bodies do not couple rows, so the answers agree to rounding (1e-9 m/s).
  PyramidParams params;
  params.rows = 4;
  std::vector<RigidBody> bodies = make_pyramid(params);
  const std::size_t spheres = bodies.size() - 1;  // the ground comes last
  for (std::size_t i = 0; i < spheres; ++i) {
    RigidBody copy = bodies[i];
    copy.name += "_far";
    copy.position.y() += 5.0;
    bodies.push_back(copy);
  }
  std::vector<RigidBody> merged = bodies;
  std::vector<Contact> contacts = sphere_contacts(bodies);
  std::vector<Contact> merged_contacts = contacts;
  LedasSettings settings = settings_for(LedasMode::complementary);
  settings.resting.correction = 0.0;
  LedasResolver by_island(settings);
  resolve(by_island, bodies, contacts);
  settings.islands = false;
  LedasResolver one_system(settings);
  const ResolverCounters counters = resolve(one_system, merged, merged_contacts);
  EXPECT_EQ(by_island.last_stats().islands, 2u);
  EXPECT_EQ(one_system.last_stats().islands, 1u);
  EXPECT_LT(counters.residual, 1e-9);
  for (std::size_t i = 0; i < bodies.size(); ++i)
    EXPECT_LT((bodies[i].velocity - merged[i].velocity).norm(), 1e-9) << bodies[i].name;
}

}  // namespace
}  // namespace impetus
