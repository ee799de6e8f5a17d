// The body-space interior point of redundant islands (resolution/ledas/README.md, "Redundant islands:
// an interior point in body space"): a wall of cubes in stack bond, four contact points on every shared
// face, so its rows outnumber its bodies' coordinates. Its answers are judged against the active-set
// search on the same problem and against analytic displacements.
#include "ledas_test_support.hpp"

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

}  // namespace
}  // namespace impetus
