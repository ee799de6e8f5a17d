// The shared resolver algebra: A = G M⁻¹ Gᵀ (eq. 7 with docs/conventions.md's reading) and eq. 3's impulses.
#include "impetus/resolution/common/impulse_rows.hpp"

#include "impetus/core/mass.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace impetus::resolution {
namespace {

RigidBody box_body(const Vec3& size, double mass, const Vec3& position, const Mat3& rotation) {
  RigidBody b;
  b.shape = Box{size};
  set_primitive_mass(b, mass);
  b.position = position;
  b.rotation = rotation;
  return b;
}

// Head-on contact of two spheres (masses m1, m2): A = 1/m1 + 1/m2, and p = −v_n/A stops the approach
// while conserving momentum (1e-12).
TEST(ImpulseRows, HeadOnContactStopsTheApproachAndConservesMomentum) {
  std::vector<RigidBody> bodies(2);
  bodies[0] = box_body(Vec3(1, 1, 1), 2.0, Vec3(0, 0, 0), Mat3::Identity());
  bodies[1] = box_body(Vec3(1, 1, 1), 3.0, Vec3(1, 0, 0), Mat3::Identity());
  bodies[0].velocity = {1.5, 0, 0};
  bodies[1].velocity = {-0.5, 0, 0};
  const ImpulseRow row = make_row(bodies, 0, 1, Vec3(0.5, 0, 0), Vec3::UnitX());
  EXPECT_NEAR(self_coupling(row), 1.0 / 2.0 + 1.0 / 3.0, 1e-15);
  const double vn = row_velocity(row, bodies);
  EXPECT_NEAR(vn, -2.0, 1e-15);
  const Vec3 momentum = 2.0 * bodies[0].velocity + 3.0 * bodies[1].velocity;
  apply_row_impulse(row, -vn / self_coupling(row), bodies);
  EXPECT_NEAR(row_velocity(row, bodies), 0.0, 1e-14);
  EXPECT_TRUE((2.0 * bodies[0].velocity + 3.0 * bodies[1].velocity - momentum).norm() < 1e-12);
  EXPECT_NEAR(bodies[0].velocity.x(), 0.3, 1e-14);  // common velocity (2·1.5 − 3·0.5)/5
}

// For random bodies and contacts (including a fixed body), A is symmetric positive semi-definite and
// predicts exactly how impulses change every row's velocity: v⁺ − v⁻ = A p (1e-12).
TEST(ImpulseRows, MatrixIsSymmetricPsdAndPredictsTheVelocityChange) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto random_vec = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  std::vector<RigidBody> bodies;
  for (int i = 0; i < 5; ++i) {
    const Mat3 r = Eigen::AngleAxisd(3 * u(rng), random_vec().normalized()).toRotationMatrix();
    bodies.push_back(box_body(Vec3(1 + u(rng) * 0.5, 1.2, 0.7), 1.5 + u(rng), 2 * random_vec(), r));
    bodies.back().velocity = random_vec();
    bodies.back().angular_velocity = random_vec();
  }
  make_fixed(bodies[4]);
  const std::pair<int, int> pairs[] = {{0, 1}, {0, 1}, {1, 2}, {2, 3}, {0, 4}, {3, 4}, {1, 3}, {2, 2 + 2}};
  std::vector<ImpulseRow> rows;
  for (auto [a, b] : pairs) rows.push_back(make_row(bodies, a, b, random_vec(), random_vec().normalized()));
  const int m = static_cast<int>(rows.size());
  Eigen::MatrixXd A(m, m);
  for (int i = 0; i < m; ++i)
    for (int k = 0; k < m; ++k) A(i, k) = coupling(rows[i], rows[k]);
  EXPECT_LT((A - A.transpose()).norm(), 1e-12);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues().minCoeff(), -1e-12);

  Eigen::VectorXd before(m), p(m);
  for (int i = 0; i < m; ++i) {
    before(i) = row_velocity(rows[i], bodies);
    p(i) = u(rng);
  }
  for (int i = 0; i < m; ++i) apply_row_impulse(rows[i], p(i), bodies);
  Eigen::VectorXd after(m);
  for (int i = 0; i < m; ++i) after(i) = row_velocity(rows[i], bodies);
  EXPECT_LT((after - before - A * p).norm(), 1e-12);
}

// Islands: bodies touching only through a fixed body are independent.
TEST(ImpulseRows, IslandsSplitAtFixedBodies) {
  std::vector<RigidBody> bodies(5);
  for (auto& b : bodies) b = box_body(Vec3(1, 1, 1), 1.0, Vec3::Zero(), Mat3::Identity());
  make_fixed(bodies[0]);
  const std::pair<int, int> pairs[] = {{0, 1}, {3, 4}, {0, 2}, {1, 2}, {0, 3}};
  std::vector<ImpulseRow> rows;
  for (auto [a, b] : pairs) rows.push_back(make_row(bodies, a, b, Vec3::Zero(), Vec3::UnitZ()));
  const auto islands = find_islands(rows, bodies.size(), bodies);
  ASSERT_EQ(islands.size(), 2u);
  EXPECT_EQ(islands[0], (std::vector<std::uint32_t>{0, 2, 3}));
  EXPECT_EQ(islands[1], (std::vector<std::uint32_t>{1, 4}));
}

}  // namespace
}  // namespace impetus::resolution
