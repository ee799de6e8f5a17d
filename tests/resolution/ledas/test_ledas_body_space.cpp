// The body-space interior point of redundant islands (resolution/ledas/README.md, "Redundant islands:
// an interior point in body space"): a wall of cubes in stack bond, four contact points on every shared
// face, so its rows outnumber its bodies' coordinates. Its answers are judged against the active-set
// search on the same problem and against analytic displacements; with friction, the relaxation's
// interior point solved in body space against the same in contact space.
#include "ledas_test_support.hpp"

#include "impetus/resolution/ledas/frictional_solver.hpp"
#include "impetus/resolution/ledas/island_solver.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace impetus {
namespace {

using namespace ledas_test;

constexpr double kSide = 0.2;   // m, the cubes' edge
constexpr int kColumns = 10, kCourses = 8;

BodyIndex cube_index(int column, int course, int columns = kColumns) {
  return static_cast<BodyIndex>(1 + course * columns + column);
}

// The ground (body 0) and `columns` × `courses` cubes of 8 kg touching face to face, each moving by a
// seeded pseudo-random amount (up to 1 m/s, 1 rad/s) if `moving`.
std::vector<RigidBody> cube_wall(bool moving, int courses = kCourses, int columns = kColumns) {
  std::vector<RigidBody> bodies{ground_plane()};
  std::uint64_t state = 0x5EED0003;
  const auto uniform = [&state] {  // in [−1, 1)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / static_cast<double>(1ULL << 52) - 1.0;
  };
  for (int course = 0; course < courses; ++course)
    for (int column = 0; column < columns; ++column) {
      RigidBody cube = solid(Box{Vec3::Constant(kSide)}, 8.0, Vec3(column * kSide, 0.0, (course + 0.5) * kSide));
      if (moving) {
        cube.velocity = Vec3(uniform(), uniform(), uniform());
        cube.angular_velocity = Vec3(uniform(), uniform(), uniform());
      }
      bodies.push_back(cube);
    }
  return bodies;
}

// Four contacts at the corners of every shared face: the bottom course on the ground (depth
// `ground_depth`), each cube on the one below, each beside the next; depth 0 elsewhere.
std::vector<Contact> wall_contacts(double ground_depth, int courses = kCourses, int columns = kColumns) {
  std::vector<Contact> contacts;
  const double h = 0.5 * kSide;
  const auto face = [&](BodyIndex a, BodyIndex b, const Vec3& centre, const Vec3& normal, const Vec3& u,
                        const Vec3& v, double depth) {
    for (double su : {-h, h})
      for (double sv : {-h, h}) contacts.push_back(contact(a, b, centre + su * u + sv * v, normal, depth));
  };
  for (int course = 0; course < courses; ++course)
    for (int column = 0; column < columns; ++column) {
      const BodyIndex self = cube_index(column, course, columns);
      const Vec3 centre(column * kSide, 0.0, (course + 0.5) * kSide);
      const BodyIndex below = course == 0 ? 0 : cube_index(column, course - 1, columns);
      face(below, self, centre - Vec3(0, 0, h), Vec3::UnitZ(), Vec3::UnitX(), Vec3::UnitY(),
           course == 0 ? ground_depth : 0.0);
      if (column + 1 < columns)
        face(self, cube_index(column + 1, course, columns), centre + Vec3(h, 0, 0), Vec3::UnitX(), Vec3::UnitY(),
             Vec3::UnitZ(), 0.0);
    }
  return contacts;
}

struct Outcome {
  std::vector<RigidBody> bodies;
  std::vector<Contact> contacts;
  LedasStats stats;
};

Outcome resolve_wall(bool moving, double ground_depth, std::size_t interior_point_rows) {
  LedasSettings settings;
  settings.solver.interior_point_rows = interior_point_rows;
  LedasResolver resolver(settings);
  Outcome out{cube_wall(moving), wall_contacts(ground_depth), {}};
  resolve(resolver, out.bodies, out.contacts);
  out.stats = resolver.last_stats();
  return out;
}

// The island has more rows than coordinates, so A is singular: it goes to the interior point, which
// stops on its ε-complementarity rule (no contact approaches by more than the tolerance, every
// contact's impulse × separation at most 1e-4 · tolerance × the largest impulse). Its velocities are
// the active-set search's (the velocities of the problem are unique; the impulses are not) to within the
// tolerance, 1e-9 m/s and rad/s (5.7e-11 measured), and it spends no active-set iteration.
TEST(LedasBodySpace, RedundantWallMatchesTheActiveSetSearch) {
  const std::vector<Contact> contacts = wall_contacts(0.0);
  const std::size_t rows = contacts.size();
  ASSERT_GE(rows, LedasSettings{}.solver.interior_point_rows);
  ASSERT_GT(rows, 6u * kColumns * kCourses);  // redundant by count

  const Outcome interior = resolve_wall(true, 0.0, LedasSettings{}.solver.interior_point_rows);
  const Outcome search = resolve_wall(true, 0.0, 0);
  EXPECT_EQ(interior.stats.velocity.interior_point_solved, 1u);
  EXPECT_GT(interior.stats.velocity.interior_point_steps, 0u);
  EXPECT_EQ(interior.stats.velocity.iterations, 0u);  // no fallback to the search
  EXPECT_EQ(search.stats.velocity.interior_point_steps, 0u);
  EXPECT_GT(search.stats.velocity.iterations, 0u);

  const double tolerance = LedasSettings{}.tolerance;
  const std::vector<RigidBody> before = cube_wall(true);
  for (const Outcome* o : {&interior, &search}) {
    double largest = 0.0;
    for (const Contact& c : o->contacts) largest = std::max(largest, c.impulse);
    ASSERT_GT(largest, 0.0);
    for (const Contact& c : o->contacts) {
      const double v_n = relative_normal_velocity(o->bodies[c.a], c.point, o->bodies[c.b], c.point, c.normal);
      EXPECT_GE(v_n, -tolerance);
      EXPECT_GE(c.impulse, 0.0);
      EXPECT_LE(c.impulse * std::max(v_n, 0.0), 1e-4 * tolerance * largest);
    }
    EXPECT_LT(kinetic_energy(o->bodies), kinetic_energy(before));  // inelastic impacts lose energy
  }
  double difference = 0.0;
  for (std::size_t i = 1; i < before.size(); ++i) {
    difference = std::max(difference, (interior.bodies[i].velocity - search.bodies[i].velocity).lpNorm<Eigen::Infinity>());
    difference = std::max(difference,
                          (interior.bodies[i].angular_velocity - search.bodies[i].angular_velocity).lpNorm<Eigen::Infinity>());
  }
  std::printf("[ledas] cube wall, %zu rows: interior point %llu steps, search %llu iterations, velocities differ by "
              "%.2e\n", rows, static_cast<unsigned long long>(interior.stats.velocity.interior_point_steps),
              static_cast<unsigned long long>(search.stats.velocity.iterations), difference);
  EXPECT_LT(difference, tolerance);
}

// A wall sunk 2 mm into the ground at rest: the position correction (a complementarity problem on the
// same redundant rows, solved by the interior point) must lift every cube by the same
// correction · (depth − slop) = 0.2 · 1.9 mm = 0.38 mm, the least displacement that clears the ground
// without pushing any cube into another, and move nothing else.
TEST(LedasBodySpace, CorrectionLiftsASunkenWallUniformly) {
  const double depth = 2e-3;
  const LedasSettings defaults;
  const double lift = defaults.resting.correction * (depth - defaults.resting.slop);
  for (const std::size_t interior_point_rows : {defaults.solver.interior_point_rows, std::size_t{0}}) {
    const Outcome out = resolve_wall(false, depth, interior_point_rows);
    EXPECT_EQ(out.stats.position.interior_point_solved, interior_point_rows > 0 ? 1u : 0u);
    const std::vector<RigidBody> start = cube_wall(false);
    double error = 0.0;
    for (std::size_t i = 1; i < start.size(); ++i) {
      const Vec3 moved = out.bodies[i].position - start[i].position;
      error = std::max(error, (moved - Vec3(0, 0, lift)).lpNorm<Eigen::Infinity>());
      EXPECT_LT((out.bodies[i].rotation - Mat3::Identity()).norm(), 1e-9);
      EXPECT_EQ(out.bodies[i].velocity, Vec3::Zero());
    }
    std::printf("[ledas] sunken cube wall, interior_point_rows %zu: lift error %.2e m\n", interior_point_rows, error);
    EXPECT_LT(error, 1e-10);
  }
}

// Determinism: a wall of 200 cubes (1,200 coordinates, 1,568 rows) resolved in a task arena of one
// thread and of four gives the same velocities and impulses to the bit. (The interior point's block
// LDLᵀ is serial; what threads could change is the island's other work around it.)
TEST(LedasBodySpace, SameBitsForEveryThreadCount) {
  constexpr int kTall = 8, kWide = 25;
  std::vector<RigidBody> serial = cube_wall(true, kTall, kWide), parallel = serial;
  std::vector<Contact> serial_contacts = wall_contacts(0.0, kTall, kWide), parallel_contacts = serial_contacts;
  LedasResolver one_resolver, four_resolver;
  tbb::task_arena one(1), four(4);
  one.execute([&] { resolve(one_resolver, serial, serial_contacts); });
  four.execute([&] { resolve(four_resolver, parallel, parallel_contacts); });
  EXPECT_EQ(one_resolver.last_stats().velocity.interior_point_solved, 1u);
  EXPECT_EQ(four_resolver.last_stats().velocity.interior_point_solved, 1u);
  for (std::size_t i = 0; i < serial.size(); ++i) {
    EXPECT_EQ(std::memcmp(serial[i].velocity.data(), parallel[i].velocity.data(), sizeof(Vec3)), 0) << "body " << i;
    EXPECT_EQ(std::memcmp(serial[i].angular_velocity.data(), parallel[i].angular_velocity.data(), sizeof(Vec3)), 0)
        << "body " << i;
  }
  for (std::size_t k = 0; k < serial_contacts.size(); ++k)
    EXPECT_EQ(std::memcmp(&serial_contacts[k].impulse, &parallel_contacts[k].impulse, sizeof(double)), 0) << "contact " << k;
}

// The frictional wall's convex relaxation (Anitescu's cone complementarity) built by hand from G and M:
// three rows per contact (n, t1, t2), W = G M⁻¹ Gᵀ, q = G v for the cubes' seeded velocities, μ = 0.5.
// 5 × 4 cubes: 36 faces, 144 contacts, 432 rows on 120 body coordinates.
struct WallRelaxation final : ledas::BodySpaceSource {
  const ledas::BodySpace& body_space() override { return body; }
  ledas::BodySpace body;
  ledas::SparseMatrix w;
  ledas::FrictionalProblem problem;
};

void wall_relaxation(WallRelaxation& out) {
  constexpr int columns = 5, courses = 4;
  const std::vector<RigidBody> bodies = cube_wall(true, courses, columns);
  const std::vector<Contact> contacts = wall_contacts(0.0, courses, columns);
  const auto cubes = static_cast<Eigen::Index>(bodies.size() - 1);  // body i ≥ 1 is block i − 1
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(3 * static_cast<Eigen::Index>(contacts.size()), 6 * cubes);
  Eigen::VectorXd v(6 * cubes), inverse_mass(6 * cubes);
  for (Eigen::Index b = 0; b < cubes; ++b) {
    const RigidBody& cube = bodies[static_cast<std::size_t>(b + 1)];
    v.segment<3>(6 * b) = cube.velocity;
    v.segment<3>(6 * b + 3) = cube.angular_velocity;
    inverse_mass.segment<3>(6 * b).setConstant(1.0 / cube.mass);
    inverse_mass.segment<3>(6 * b + 3) = cube.inertia_world().diagonal().cwiseInverse();  // a cube: J = (m s²/6) I
    out.body.mass.push_back(cube.mass);
    out.body.inertia.push_back(cube.inertia_world());
  }
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    const Contact& k = contacts[c];
    Vec3 directions[3] = {k.normal, Vec3::Zero(), Vec3::Zero()};
    tangent_basis(k.normal, directions[1], directions[2]);
    for (int j = 0; j < 3; ++j) {
      const Eigen::Index row = 3 * static_cast<Eigen::Index>(c) + j;
      const Vec3& e = directions[j];
      std::array<double, 12> entries{};
      std::array<std::int32_t, 2> sides{-1, -1};
      int side = 0;
      for (const auto& [body, sign] : {std::pair{k.a, -1.0}, std::pair{k.b, 1.0}}) {
        if (body == 0) continue;  // the ground has no coordinates
        const Eigen::Index block = static_cast<Eigen::Index>(body) - 1;
        const Vec3 arm = (k.point - bodies[body].position).cross(e);
        g.block<1, 3>(row, 6 * block) = sign * e.transpose();
        g.block<1, 3>(row, 6 * block + 3) = sign * arm.transpose();
        for (int d = 0; d < 3; ++d) {
          entries[static_cast<std::size_t>(6 * side + d)] = sign * e(d);
          entries[static_cast<std::size_t>(6 * side + 3 + d)] = sign * arm(d);
        }
        sides[static_cast<std::size_t>(side++)] = static_cast<std::int32_t>(block);
      }
      out.body.blocks.push_back(sides);
      out.body.jacobian.push_back(entries);
      out.problem.role.push_back(j == 0 ? ledas::RowRole::normal : ledas::RowRole::tangent);
      out.problem.mu.push_back(j == 0 ? 0.5 : 0.0);
    }
  }
  const Eigen::MatrixXd w = g * inverse_mass.asDiagonal() * g.transpose();
  out.w = w.sparseView();
  out.problem.w = &out.w;
  out.problem.q = g * v;
  out.problem.tolerance = 1e-10 * out.problem.q.norm();
  out.problem.dofs = static_cast<std::size_t>(6 * cubes);
  out.problem.convex = true;
}

// The relaxation's interior point with W's factored form: each step's Newton system (P + T²) Δx = b is
// solved through the bodies' M + Bᵀ H B (cone_qp.cpp) instead of in contact space. The relaxation's
// velocities are unique (its dual in the velocity change is strictly convex), so both solves must give
// the same u = W r + q, to the tolerance (1.3e-10 against 1.5e-9 measured), with every impulse in its
// cone and every velocity in the dual cone to the tolerance; only the body-space one counts body-space
// steps.
TEST(LedasBodySpace, FrictionalRelaxationInBodySpaceMatchesContactSpace) {
  WallRelaxation wall;
  wall_relaxation(wall);
  ASSERT_GT(wall.problem.q.size(), static_cast<Eigen::Index>(wall.problem.dofs));
  ledas::FrictionalSolver solver;
  ledas::FrictionalStats in_body, in_contacts;
  wall.problem.body_space = &wall;
  const ledas::Vector r_body = solver.solve(wall.problem, in_body);
  wall.problem.body_space = nullptr;
  const ledas::Vector r_contacts = solver.solve(wall.problem, in_contacts);
  EXPECT_GT(in_body.interior_point_body_steps, 0u);
  EXPECT_EQ(in_contacts.interior_point_body_steps, 0u);
  EXPECT_EQ(in_body.non_converged + in_contacts.non_converged, 0u);
  const double tol = wall.problem.tolerance;
  const ledas::Vector u_body = wall.w * r_body + wall.problem.q, u_contacts = wall.w * r_contacts + wall.problem.q;
  for (const auto& [r, u] : {std::pair{&r_body, &u_body}, std::pair{&r_contacts, &u_contacts}})
    for (Eigen::Index c = 0; c < u->size(); c += 3) {
      EXPECT_LE(r->segment<2>(c + 1).norm(), 0.5 * (*r)(c) + tol) << "contact " << c / 3;
      EXPECT_GE((*u)(c), 0.5 * u->segment<2>(c + 1).norm() - tol) << "contact " << c / 3;
    }
  const double difference = (u_body - u_contacts).lpNorm<Eigen::Infinity>();
  std::printf("[ledas] frictional wall relaxation, %lld rows: %llu interior-point steps in body space, %llu in "
              "contact space; velocities differ by %.2e (tolerance %.2e)\n",
              static_cast<long long>(wall.problem.q.size()), static_cast<unsigned long long>(in_body.interior_point_steps),
              static_cast<unsigned long long>(in_contacts.interior_point_steps), difference, tol);
  EXPECT_LT(difference, tol);
}

// The resolver hands a frictional island with more rows than body coordinates its factored form: the
// moving wall of 5 × 4 cubes with μ = 0.5 (432 rows on 120 coordinates; `interior_point_rows` lowered
// to 100 to let so small an island in), cold, goes through the relaxation's interior point in body
// space and is solved to the tolerance, losing energy.
TEST(LedasBodySpace, FrictionalIslandUsesTheBodySpaceInteriorPoint) {
  constexpr int columns = 5, courses = 4;
  std::vector<RigidBody> bodies = cube_wall(true, courses, columns);
  for (RigidBody& b : bodies) b.material.friction = 0.5;
  std::vector<Contact> contacts = wall_contacts(0.0, courses, columns);
  LedasSettings settings;
  settings.solver.interior_point_rows = 100;
  LedasResolver resolver(settings);
  resolve(resolver, bodies, contacts);
  const ledas::FrictionalStats& friction = resolver.last_stats().friction;
  EXPECT_GT(friction.interior_point_body_steps, 0u);
  EXPECT_EQ(friction.non_converged, 0u);
  EXPECT_LT(kinetic_energy(bodies), kinetic_energy(cube_wall(true, courses, columns)));
}

}  // namespace
}  // namespace impetus
