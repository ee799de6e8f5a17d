// LEDAS resolver with Coulomb friction, resolver level (hand-built bodies and contacts): Kane's rod and
// the energy rule, Painlevé's rod, mirror symmetry, the frictional solver's independence of the tangent
// basis, and its sparse path's kept analysis. Scenes over time are in tests/scenarios/test_scenario_friction.cpp.
#include "ledas_test_support.hpp"

#include "impetus/resolution/ledas/frictional_solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace impetus {
namespace {

using namespace ledas_test;

// A slender rod (1 m × 2 cm × 2 cm, 1 kg) tilted by `tilt` from the horizontal about y, its lower end on
// the ground z = 0 at the origin, with friction μ on both bodies.
std::vector<RigidBody> rod_on_ground(double tilt, double mu, double restitution) {
  const Mat3 rotation = Eigen::AngleAxisd(-tilt, Vec3::UnitY()).toRotationMatrix();
  RigidBody rod = solid(Box{Vec3(1.0, 0.02, 0.02)}, 1.0, Vec3::Zero(), Vec3::Zero(), restitution, rotation);
  rod.position = -(rotation * Vec3(-0.5, 0.0, 0.0));  // the end at −x of the body sits at the origin
  rod.material.friction = mu;
  RigidBody ground = ground_plane(restitution);
  ground.material.friction = mu;
  return {ground, rod};
}

std::vector<Contact> end_contact() { return {contact(0, 1, Vec3::Zero(), Vec3::UnitZ())}; }

// Kane's rod: an oblique impact of a spinning rod on one end, the classic case where Newton's
// restitution rule with Coulomb friction creates energy. With the two-phase rule (frictional impact,
// then a frictional restitution phase capped at the pre-impact energy) the kinetic energy after the
// impact never exceeds the energy before (1e-12 relative), at e = 0.5 and 1 and over a range of
// μ, angles and spins; with μ = 0 and e = 1 it is conserved (1e-12).
TEST(LedasFriction, KanesRodGainsNoEnergy) {
  int capped = 0;
  for (const double e : {0.5, 1.0})
    for (const double mu : {0.0, 0.3, 0.8, 2.0})
      for (const double tilt : {0.3, 0.6, 0.9})
        for (const double spin : {-20.0, -5.0, 5.0}) {
          std::vector<RigidBody> bodies = rod_on_ground(tilt, mu, e);
          bodies[1].velocity = Vec3(1.0, 0.0, -2.0);
          bodies[1].angular_velocity = Vec3(0.0, spin, 0.0);
          std::vector<Contact> contacts = end_contact();
          if (normal_velocity(contacts[0], bodies[0], bodies[1]) >= -0.1) continue;  // not an impact
          const double before = kinetic_energy(bodies);
          LedasResolver resolver;
          const ResolverCounters counters = resolve(resolver, bodies, contacts);
          const double after = kinetic_energy(bodies);
          EXPECT_EQ(counters.non_converged, 0u);
          EXPECT_LE(after, before * (1.0 + 1e-12)) << "e " << e << " mu " << mu << " tilt " << tilt << " spin " << spin;
          if (mu == 0.0 && e == 1.0) {
            EXPECT_NEAR(after, before, 1e-12 * before);
          }
          EXPECT_LE(contacts[0].tangent_impulse.norm(), mu * contacts[0].impulse * (1.0 + 1e-9));
          capped += static_cast<int>(resolver.last_stats().restitution_capped);
        }
  std::printf("[ friction ] Kane's rod: %d of the impacts needed the restitution cap\n", capped);
}

// Painlevé's rod: sliding on one end with μ = 1.5 at 63° (inside the region where the rigid rod's
// sliding has no consistent contact force): at the impulse level it jams — the frictional impact stops
// the slip — and the solver converges with finite impulses and no energy gain.
TEST(LedasFriction, PainleveRodJamsInsteadOfFailing) {
  for (const double vx : {-1.0, 1.0}) {
    std::vector<RigidBody> bodies = rod_on_ground(63.0 * M_PI / 180.0, 1.5, 0.0);
    bodies[1].velocity = Vec3(vx, 0.0, -9.81e-3);  // sliding, pressed by one step of gravity
    std::vector<Contact> contacts = end_contact();
    const double before = kinetic_energy(bodies);
    LedasResolver resolver;
    const ResolverCounters counters = resolve(resolver, bodies, contacts);
    EXPECT_EQ(counters.non_converged, 0u);
    EXPECT_EQ(counters.nan_caught, 0u);
    EXPECT_TRUE(std::isfinite(contacts[0].impulse) && contacts[0].tangent_impulse.allFinite());
    EXPECT_LE(kinetic_energy(bodies), before * (1.0 + 1e-12));
    const Vec3 u = relative_velocity(contacts[0], bodies[0], bodies[1]);
    EXPECT_GE(u.z(), -1e-9);
    // Sliding toward −x (the lower end running out from under the rod) is Painlevé's case: it jams.
    if (vx < 0.0) {
      EXPECT_EQ(contacts[0].mode, ContactMode::stick);
      EXPECT_LT(std::hypot(u.x(), u.y()), 1e-9);
    }
    std::printf("[ friction ] Painleve rod vx %+.0f: mode %s, p_n %.6g, |p_t| %.6g, slip after %.3g m/s\n", vx,
                contact_mode_name(contacts[0].mode), contacts[0].impulse, contacts[0].tangent_impulse.norm(),
                std::hypot(u.x(), u.y()));
  }
}

// A sphere dropped into a symmetric V-groove while rolling along it: the problem is its own mirror image
// in the plane x = 0, so the two contacts' impulses are mirror images (1e-12 relative).
TEST(LedasFriction, MirrorSymmetricProblemGivesMirrorSymmetricImpulses) {
  const double s = std::sqrt(0.5);
  RigidBody ball = sphere(1.0, 2.0, Vec3::Zero(), Vec3(0.0, 0.7, -1.0));
  ball.angular_velocity = Vec3(3.0, 0.0, 0.0);
  ball.material.friction = 0.3;
  RigidBody wall = ground_plane();
  wall.material.friction = 0.3;
  std::vector<RigidBody> bodies{wall, ball};
  // Contact points on the sphere at ±45° below its centre; normals from the walls into the sphere.
  std::vector<Contact> contacts{contact(0, 1, Vec3(-s, 0.0, -s), Vec3(s, 0.0, s)),
                                contact(0, 1, Vec3(s, 0.0, -s), Vec3(-s, 0.0, s))};
  LedasResolver resolver;
  const ResolverCounters counters = resolve(resolver, bodies, contacts);
  EXPECT_EQ(counters.non_converged, 0u);
  const double scale = contacts[0].impulse;
  ASSERT_GT(scale, 0.0);
  EXPECT_NEAR(contacts[0].impulse, contacts[1].impulse, 1e-12 * scale);
  const Vec3 t0 = contacts[0].tangent_impulse, t1 = contacts[1].tangent_impulse;
  EXPECT_NEAR(t0.x(), -t1.x(), 1e-12 * scale);
  EXPECT_NEAR(t0.y(), t1.y(), 1e-12 * scale);
  EXPECT_NEAR(t0.z(), t1.z(), 1e-12 * scale);
  EXPECT_NEAR(bodies[1].velocity.x(), 0.0, 1e-12);
}

// A cluster of three spheres on the ground (masses 1, 2, 1.5 kg; 5 contacts, 15 rows, 18 degrees of
// freedom) with random velocities from `random`, as a frictional problem with μ = 0.2 (small enough
// for the solution to be unique: at μ = 0.4 one draw in twenty has two Coulomb solutions). Each
// contact's tangent pair is turned about its normal by turn[k]; `rows` are the problem's rows.
// The frictional problem of `rows` (three per contact: normal, t1, t2) on `bodies`, every contact with
// coefficient μ, solved to `tolerance`: W (from the rows' couplings) into `w`, q the rows' velocities.
ledas::FrictionalProblem frictional_problem(const std::vector<resolution::ImpulseRow>& rows,
                                            const std::vector<RigidBody>& bodies, double mu, double tolerance,
                                            ledas::SparseMatrix& w) {
  const auto m = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd dense(m, m);
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index k = 0; k < m; ++k)
      dense(i, k) = resolution::coupling(rows[static_cast<std::size_t>(i)], rows[static_cast<std::size_t>(k)]);
  w = dense.sparseView();
  ledas::FrictionalProblem problem;
  problem.w = &w;
  problem.q.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) problem.q(i) = resolution::row_velocity(rows[static_cast<std::size_t>(i)], bodies);
  for (Eigen::Index i = 0; i < m; i += 3) {
    problem.role.insert(problem.role.end(), {ledas::RowRole::normal, ledas::RowRole::tangent, ledas::RowRole::tangent});
    problem.mu.insert(problem.mu.end(), {mu, 0.0, 0.0});
  }
  problem.tolerance = tolerance;
  return problem;
}

struct SphereCluster {
  std::vector<RigidBody> bodies{ground_plane(), sphere(0.5, 1.0, Vec3(0, 0, 0.5)), sphere(0.5, 2.0, Vec3(1, 0, 0.5)),
                                sphere(0.5, 1.5, Vec3(0.5, 0, 0.5 + std::sqrt(0.75)))};
  static constexpr std::size_t kContacts = 5;

  void draw_velocities(std::mt19937_64& random) {
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    for (std::size_t i = 1; i < bodies.size(); ++i) {
      bodies[i].velocity = Vec3(uniform(random), uniform(random), uniform(random) - 1.0);
      bodies[i].angular_velocity = 3.0 * Vec3(uniform(random), uniform(random), uniform(random));
    }
  }

  // W into `w`, and the problem on it (tolerance 1e-13).
  ledas::FrictionalProblem problem(const std::vector<double>& turn, ledas::SparseMatrix& w,
                                   std::vector<resolution::ImpulseRow>& rows) const {
    struct Pair {
      BodyIndex a, b;
    };
    const Pair pairs[kContacts] = {{0, 1}, {0, 2}, {1, 3}, {2, 3}, {1, 2}};
    rows.clear();
    for (std::size_t k = 0; k < kContacts; ++k) {
      const RigidBody &a = bodies[pairs[k].a], &b = bodies[pairs[k].b];
      const Vec3 n = pairs[k].a == 0 ? Vec3::UnitZ() : Vec3(b.position - a.position).normalized();
      const Vec3 point = pairs[k].a == 0 ? Vec3(b.position.x(), 0, 0) : Vec3(a.position + 0.5 * (b.position - a.position));
      Vec3 t1, t2;
      tangent_basis(n, t1, t2);
      const Vec3 s1 = std::cos(turn[k]) * t1 + std::sin(turn[k]) * t2, s2 = n.cross(s1);
      for (const Vec3& d : {n, s1, s2}) rows.push_back(resolution::make_row(bodies, pairs[k].a, pairs[k].b, point, d));
    }
    return frictional_problem(rows, bodies, 0.2, 1e-13, w);
  }
};

// The frictional solver's answer does not depend on the tangent basis: the same contacts with each
// tangent pair turned by a random angle give the same tangential impulses (turned back) and velocities,
// to 1e-10 relative, on the sphere cluster above.
TEST(LedasFriction, FrictionalSolverDoesNotDependOnTheTangentBasis) {
  std::mt19937_64 random(17);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  SphereCluster cluster;
  const auto solve_with = [&](const std::vector<double>& turn, ledas::Vector& r, ledas::Vector& u) {
    ledas::SparseMatrix w;
    std::vector<resolution::ImpulseRow> rows;
    const ledas::FrictionalProblem problem = cluster.problem(turn, w, rows);
    ledas::FrictionalSolver solver;
    ledas::FrictionalStats stats;
    const ledas::Vector solution = solver.solve(problem, stats);
    EXPECT_EQ(stats.non_converged, 0u);
    // World vectors: each contact's impulse n p_n + s1 p_1 + s2 p_2 and velocity likewise.
    r.resize(3 * static_cast<Eigen::Index>(SphereCluster::kContacts));
    u.resize(r.size());
    const ledas::Vector velocity = w * solution + problem.q;
    for (std::size_t k = 0; k < SphereCluster::kContacts; ++k) {
      Vec3 p = Vec3::Zero(), v = Vec3::Zero();
      for (std::size_t j = 0; j < 3; ++j) {
        p += solution(static_cast<Eigen::Index>(3 * k + j)) * rows[3 * k + j].normal;
        v += velocity(static_cast<Eigen::Index>(3 * k + j)) * rows[3 * k + j].normal;
      }
      r.segment<3>(static_cast<Eigen::Index>(3 * k)) = p;
      u.segment<3>(static_cast<Eigen::Index>(3 * k)) = v;
    }
  };
  for (int trial = 0; trial < 20; ++trial) {
    cluster.draw_velocities(random);
    ledas::Vector r0, u0, r1, u1;
    solve_with(std::vector<double>(SphereCluster::kContacts, 0.0), r0, u0);
    std::vector<double> turn;
    for (std::size_t k = 0; k < SphereCluster::kContacts; ++k) turn.push_back(M_PI * uniform(random));
    solve_with(turn, r1, u1);
    EXPECT_LE((r1 - r0).norm(), 1e-10 * std::max(1.0, r0.norm())) << "trial " << trial;
    EXPECT_LE((u1 - u0).norm(), 1e-10 * std::max(1.0, u0.norm())) << "trial " << trial;
  }
}

// Newton's sparse path keeps its LU's ordering and symbolic analysis in the workspace while W's pattern
// does not change. Problem after problem on one workspace (the sphere cluster with new velocities, and
// every other draw new masses, so W's values change under the same pattern), solved on the sparse path
// (dense_limit 4), each gives the velocities a fresh solver gives on the dense path to 1e-10 relative
// (the solution is unique at μ = 0.2), and reaches its tolerance.
TEST(LedasFriction, KeptSparseAnalysisSolvesProblemsWithNewValues) {
  std::mt19937_64 random(29);
  std::uniform_real_distribution<double> mass(0.5, 3.0);
  SphereCluster cluster;
  const std::vector<double> no_turn(SphereCluster::kContacts, 0.0);
  ledas::FrictionalSettings sparse_settings;
  sparse_settings.dense_limit = 4;
  ledas::FrictionalSolver sparse(sparse_settings);
  ledas::FrictionalWorkspace workspace;
  for (int trial = 0; trial < 12; ++trial) {
    cluster.draw_velocities(random);
    if (trial % 2 == 1)
      for (std::size_t i = 1; i < cluster.bodies.size(); ++i)
        cluster.bodies[i] = sphere(0.5, mass(random), cluster.bodies[i].position, cluster.bodies[i].velocity);
    ledas::SparseMatrix w;
    std::vector<resolution::ImpulseRow> rows;
    ledas::FrictionalProblem problem = cluster.problem(no_turn, w, rows);
    ledas::FrictionalStats fresh_stats, kept_stats;
    const ledas::Vector expected = ledas::FrictionalSolver().solve(problem, fresh_stats);
    problem.workspace = &workspace;
    ledas::Vector r;
    sparse.solve(problem, kept_stats, r);
    ASSERT_EQ(kept_stats.non_converged, 0u) << "trial " << trial;
    ASSERT_EQ(fresh_stats.non_converged, 0u) << "trial " << trial;
    EXPECT_LE(ledas::natural_map_residual(problem, r), problem.tolerance) << "trial " << trial;
    const ledas::Vector u = w * r + problem.q, u_expected = w * expected + problem.q;
    EXPECT_LE((u - u_expected).norm(), 1e-10 * std::max(1.0, u_expected.norm())) << "trial " << trial;
  }
}

// A column of 40 spheres (radius 0.5, masses 1 + 0.1 k) stacked on the ground at μ = 0.7: the lower 39
// move down at 1 m/s, the top one up at 1 m/s. Every contact below the top sphere is pressed and sticks
// (no tangential motion at all), and the impact stops the 39: contact c (below sphere c) carries the
// momentum of spheres c … 38, r_n = Σ m_j × 1 m/s, r_t = 0; the top contact opens (r = 0). From a warm
// start that is wrong on every contact (the pressed impulses × 0.9, 0.3 N·s on the open contact, a
// tangential push), Newton solves it in one step up to the Jacobian's shift (1e-10 max W_ii), and to the
// tolerance 1e-12 in two: every block is active or open there, so the Alart–Curnier function is linear,
// and Newton's system is the symmetric one on the active rows (120 rows: the sparse path), which must
// also carry the open contact's correction across. Impulses to 1e-10 relative, velocities to 1e-10 m/s.
// The second step's matrix is the first's, so it factorizes nothing.
TEST(LedasFriction, NewtonSolvesAStickingColumnFromAWrongWarmStartInTwoSteps) {
  constexpr int kSpheres = 40;
  std::vector<RigidBody> bodies{ground_plane()};
  for (int k = 0; k < kSpheres; ++k)
    bodies.push_back(sphere(0.5, 1.0 + 0.1 * k, Vec3(0, 0, 0.5 + k), Vec3(0, 0, k + 1 < kSpheres ? -1.0 : 1.0)));
  std::vector<resolution::ImpulseRow> rows;
  for (int c = 0; c < kSpheres; ++c) {
    const Vec3 n = Vec3::UnitZ();
    Vec3 t1, t2;
    tangent_basis(n, t1, t2);
    for (const Vec3& d : {n, t1, t2})
      rows.push_back(resolution::make_row(bodies, static_cast<BodyIndex>(c), static_cast<BodyIndex>(c + 1),
                                          Vec3(0, 0, c), d));
  }
  ledas::SparseMatrix w;
  ledas::FrictionalProblem problem = frictional_problem(rows, bodies, 0.7, 1e-12, w);
  const auto m = static_cast<Eigen::Index>(rows.size());
  ledas::Vector expected = ledas::Vector::Zero(m);
  for (int c = kSpheres - 2; c >= 0; --c) expected(3 * c) = (c + 1 < kSpheres - 1 ? expected(3 * (c + 1)) : 0.0) + 1.0 + 0.1 * c;
  ledas::Vector start = 0.9 * expected;
  start(3 * (kSpheres - 1)) = 0.3;
  start(3 * 5 + 1) = 0.05;  // a tangential impulse inside the cone, which the answer must remove
  problem.start = &start;
  ASSERT_GT(m, static_cast<Eigen::Index>(ledas::FrictionalSettings{}.dense_limit));

  ledas::FrictionalStats stats;
  const ledas::Vector r = ledas::FrictionalSolver().solve(problem, stats);
  EXPECT_EQ(stats.warm_started, 1u);
  EXPECT_EQ(stats.newton_steps, 2u);  // the second removes what the Jacobian's shift left (~1e-9)
  // Both steps stick every contact with the same shift, so the second's matrix is the first's: it reuses
  // that factorization (the bits a new one would give) instead of computing it again.
  EXPECT_EQ(stats.newton_reused, 1u);
  EXPECT_LE((r - expected).norm(), 1e-10 * expected.norm());
  const ledas::Vector u = w * r + problem.q;
  for (int c = 0; c + 1 < kSpheres; ++c)
    EXPECT_LE(u.segment<3>(3 * c).norm(), 1e-10) << "contact " << c << " slips or separates";
  EXPECT_NEAR(u(3 * (kSpheres - 1)), 1.0, 1e-10) << "the top sphere leaves at 1 m/s";
}

}  // namespace
}  // namespace impetus

namespace impetus {
namespace {

// One frictional contact with W = `w`, q = (−1, 2, 0), μ = 0.5, solved to 1e-13.
ledas::FrictionalProblem one_pushed_contact(const ledas::SparseMatrix& w) {
  ledas::FrictionalProblem problem;
  problem.w = &w;
  problem.q = ledas::Vector::Zero(3);
  problem.q << -1.0, 2.0, 0.0;
  problem.role = {ledas::RowRole::normal, ledas::RowRole::tangent, ledas::RowRole::tangent};
  problem.mu = {0.5, 0.0, 0.0};
  problem.tolerance = 1e-13;
  return problem;
}

// The convex relaxation against its closed form on one contact with W = I, q = (−1, 2, 0), μ = 0.5: r is
// the projection of −q on the cone, s = (1 + μ·2)/(1 + μ²) = 1.6, r = (1.6, −0.8, 0), and the contact
// separates at u_n = μ‖u_t‖ = 0.6. Coulomb's problem on the same contact slides without separating:
// u_n = 0, r = (1, −0.5, 0). Both to 1e-12.
TEST(LedasFriction, RelaxationAndCoulombMatchTheirClosedFormsOnOneContact) {
  const ledas::SparseMatrix w = Eigen::MatrixXd::Identity(3, 3).sparseView();
  ledas::FrictionalProblem problem = one_pushed_contact(w);
  ledas::FrictionalSolver solver;
  ledas::FrictionalStats stats;
  const ledas::Vector coulomb = solver.solve(problem, stats);
  problem.convex = true;
  const ledas::Vector relaxed = solver.solve(problem, stats);
  EXPECT_EQ(stats.non_converged, 0u);
  EXPECT_NEAR(relaxed(0), 1.6, 1e-12);
  EXPECT_NEAR(relaxed(1), -0.8, 1e-12);
  EXPECT_NEAR(relaxed(2), 0.0, 1e-12);
  EXPECT_NEAR((w * relaxed + problem.q)(0), 0.6, 1e-12);
  EXPECT_NEAR(coulomb(0), 1.0, 1e-12);
  EXPECT_NEAR(coulomb(1), -0.5, 1e-12);
  EXPECT_NEAR(coulomb(2), 0.0, 1e-12);
}

// The overload that solves into the caller's vector, with a workspace, gives the bits of the one that
// returns a new vector: from zero, from a warm start held elsewhere, and from a warm start that is the
// output vector itself (slipping contact of the test above, Coulomb: r = (1, −0.5, 0) to 1e-12; the
// warm start (0.9, −0.4, 0.1) does not solve it at once).
TEST(LedasFriction, SolvingIntoAVectorMatchesTheReturnedSolution) {
  const ledas::SparseMatrix w = Eigen::MatrixXd::Identity(3, 3).sparseView();
  ledas::FrictionalProblem problem = one_pushed_contact(w);
  ledas::FrictionalSolver solver;
  ledas::FrictionalStats stats;
  const ledas::Vector cold = solver.solve(problem, stats);
  ledas::Vector start(3);
  start << 0.9, -0.4, 0.1;
  problem.start = &start;
  const ledas::Vector warm = solver.solve(problem, stats);

  ledas::FrictionalWorkspace workspace;
  problem.workspace = &workspace;
  problem.start = nullptr;
  ledas::Vector into;
  solver.solve(problem, stats, into);
  EXPECT_EQ(into, cold);
  problem.start = &start;
  solver.solve(problem, stats, into);
  EXPECT_EQ(into, warm);
  ledas::Vector itself = start;
  problem.start = &itself;
  solver.solve(problem, stats, itself);
  EXPECT_EQ(itself, warm);
  EXPECT_EQ(stats.non_converged, 0u);
  EXPECT_NEAR(warm(0), 1.0, 1e-12);
  EXPECT_NEAR(warm(1), -0.5, 1e-12);
  EXPECT_NEAR(warm(2), 0.0, 1e-12);
}


// The pushed contact (W = I), warm-started near its slipping answer r = (1, −0.5, 0).
struct PushedContactWarmStarted {
  PushedContactWarmStarted() : w(Eigen::MatrixXd::Identity(3, 3).sparseView()), problem(one_pushed_contact(w)) {
    start << 0.9, -0.4, 0.1;
    problem.start = &start;
  }
  PushedContactWarmStarted(const PushedContactWarmStarted&) = delete;  // problem points into it
  static void expect_slipping_answer(const ledas::Vector& r) {
    EXPECT_NEAR(r(0), 1.0, 1e-12);
    EXPECT_NEAR(r(1), -0.5, 1e-12);
    EXPECT_NEAR(r(2), 0.0, 1e-12);
  }
  PushedContactWarmStarted& operator=(const PushedContactWarmStarted&) = delete;
  ledas::SparseMatrix w;
  ledas::Vector start = ledas::Vector::Zero(3);
  ledas::FrictionalProblem problem;
};

// The sphere cluster's next random draw, warm-started from its cold answer with the normal impulses
// halved and the tangential ones reversed (a start its warm Newton steps can take to a slipping answer).
struct WarmStartedDraw {
  WarmStartedDraw(SphereCluster& cluster, std::mt19937_64& random) {
    cluster.draw_velocities(random);
    problem = cluster.problem(std::vector<double>(SphereCluster::kContacts, 0.0), w, rows);
    ledas::FrictionalSolver cold_solver;
    ledas::FrictionalStats cold_stats;
    start = cold_solver.solve(problem, cold_stats);
    for (Eigen::Index i = 0; i < start.size(); ++i) start(i) *= i % 3 == 0 ? 0.5 : -1.0;
    problem.start = &start;
  }
  WarmStartedDraw(const WarmStartedDraw&) = delete;  // problem points into it
  WarmStartedDraw& operator=(const WarmStartedDraw&) = delete;
  ledas::SparseMatrix w;
  std::vector<resolution::ImpulseRow> rows;
  ledas::Vector start;
  ledas::FrictionalProblem problem;
};

// A slipping answer Newton reaches from a warm start is taken after the loose interior-point check only
// where no static equilibrium exists, and it is then what the full relaxation leads to as well:
//  - the pushed contact above (its relaxation separates: no equilibrium), from (0.9, −0.4, 0.1): the
//    check takes the answer, Coulomb's r = (1, −0.5, 0) to 1e-12, bit for bit the full path's;
//  - the sphere cluster above, 20 random draws, each warm-started from its cold answer with the normal
//    impulses halved and the tangential ones reversed: where the warm Newton steps reach a slipping
//    answer although the relaxation finds a static equilibrium, the check declines and the relaxation's
//    answer is taken, bit for bit the full path's, solving the problem to its tolerance.
// One unchecked warm Newton step (the default 2 reach the pushed contact's answer before the check), and
// no Newton on the relaxation first (warm_relaxation: tested below), so that the interior point checks.
TEST(LedasFriction, SlippingWarmAnswerIsTakenOnlyWhereNoStaticEquilibriumExists) {
  ledas::FrictionalSettings settings;
  settings.warm_newton_iterations = 1;
  settings.warm_relaxation = false;
  ledas::FrictionalSettings full_settings = settings;
  full_settings.slip_check = false;
  {
    PushedContactWarmStarted pushed;
    ledas::FrictionalProblem& problem = pushed.problem;
    ledas::FrictionalSolver checked(settings), full(full_settings);
    ledas::FrictionalStats checked_stats, full_stats;
    const ledas::Vector r = checked.solve(problem, checked_stats);
    EXPECT_EQ(r, full.solve(problem, full_stats));
    EXPECT_EQ(checked_stats.slips_taken, 1u);
    EXPECT_EQ(checked_stats.non_converged, 0u);
    PushedContactWarmStarted::expect_slipping_answer(r);
  }
  std::mt19937_64 random(5);
  SphereCluster cluster;
  std::uint64_t declined = 0;
  for (int trial = 0; trial < 20; ++trial) {
    WarmStartedDraw draw(cluster, random);
    ledas::FrictionalProblem& problem = draw.problem;
    ledas::FrictionalSolver checked(settings), full(full_settings);
    ledas::FrictionalStats checked_stats, full_stats;
    const ledas::Vector r = checked.solve(problem, checked_stats);
    EXPECT_EQ(r, full.solve(problem, full_stats)) << "draw " << trial;
    EXPECT_EQ(checked_stats.non_converged, 0u) << "draw " << trial;
    EXPECT_LE(ledas::natural_map_residual(problem, r), problem.tolerance) << "draw " << trial;
    // The check ran (its interior point on top of the full path's) and declined.
    if (checked_stats.slips_taken == 0 && checked_stats.interior_point_steps > full_stats.interior_point_steps) ++declined;
  }
  EXPECT_GE(declined, 10u);
}

// Newton on the relaxation from a warm start (warm_relaxation) decides the same as the interior point:
//  - the pushed contact: its relaxation is solved by Newton from the slipping answer, without an interior
//    point step, and the slipping answer r = (1, −0.5, 0) is taken (to 1e-12);
//  - the sphere cluster's 20 draws above, warm-started as there: every problem solved to its tolerance,
//    with and without it, and with the same velocities u = W r + q to 10× the tolerance (the relaxation's
//    velocities are unique; its impulses need not be); most (≥ 10) solved by it, with fewer interior-point
//    steps in all.
TEST(LedasFriction, NewtonOnTheRelaxationFromAWarmStartDecidesAsTheInteriorPoint) {
  ledas::FrictionalSettings settings;
  settings.warm_newton_iterations = 1;
  ledas::FrictionalSettings without = settings;
  without.warm_relaxation = false;
  {
    PushedContactWarmStarted pushed;
    ledas::FrictionalProblem& problem = pushed.problem;
    ledas::FrictionalSolver solver(settings);
    ledas::FrictionalStats stats;
    const ledas::Vector r = solver.solve(problem, stats);
    EXPECT_EQ(stats.warm_relaxed, 1u);
    EXPECT_EQ(stats.slips_taken, 1u);
    EXPECT_EQ(stats.interior_point_steps, 0u);
    EXPECT_EQ(stats.non_converged, 0u);
    PushedContactWarmStarted::expect_slipping_answer(r);
  }
  std::mt19937_64 random(5);
  SphereCluster cluster;
  ledas::FrictionalStats with_stats, without_stats;
  for (int trial = 0; trial < 20; ++trial) {
    WarmStartedDraw draw(cluster, random);
    ledas::FrictionalProblem& problem = draw.problem;
    ledas::FrictionalSolver with_solver(settings), without_solver(without);
    const ledas::Vector r = with_solver.solve(problem, with_stats);
    const ledas::Vector reference = without_solver.solve(problem, without_stats);
    EXPECT_LE(ledas::natural_map_residual(problem, r), problem.tolerance) << "draw " << trial;
    const ledas::Vector u = draw.w * r + problem.q, u_reference = draw.w * reference + problem.q;
    EXPECT_LE((u - u_reference).lpNorm<Eigen::Infinity>(), 10 * problem.tolerance) << "draw " << trial;
  }
  EXPECT_EQ(with_stats.non_converged, 0u);
  EXPECT_EQ(without_stats.non_converged, 0u);
  EXPECT_EQ(without_stats.warm_relaxed, 0u);
  EXPECT_GE(with_stats.warm_relaxed, 10u);
  EXPECT_LT(with_stats.interior_point_steps, without_stats.interior_point_steps);
}

// W (n × n) from its lower triangle by rows, as dumped problems are kept here.
ledas::SparseMatrix symmetric_from_lower(const double* lower, int n) {
  Eigen::MatrixXd dense(n, n);
  for (int i = 0, k = 0; i < n; ++i)
    for (int j = 0; j <= i; ++j, ++k) dense(i, j) = dense(j, i) = lower[k];
  return dense.sparseView();
}

// The frictional problem of contacts with coefficient μ on W (3 rows each) and q, tolerance 1e-10 ‖q‖.
ledas::FrictionalProblem frictional_contacts(const ledas::SparseMatrix& w, const double* q, double mu, std::size_t dofs) {
  ledas::FrictionalProblem problem;
  problem.w = &w;
  problem.q = Eigen::Map<const ledas::Vector>(q, w.rows());
  for (Eigen::Index c = 0; c < w.rows() / 3; ++c) {
    problem.role.insert(problem.role.end(), {ledas::RowRole::normal, ledas::RowRole::tangent, ledas::RowRole::tangent});
    problem.mu.insert(problem.mu.end(), {mu, 0.0, 0.0});
  }
  problem.dofs = dofs;
  problem.tolerance = 1e-10 * problem.q.norm();
  return problem;
}

// A problem the stages leave stalled, dumped from the frictional pile of bench_step (2026-12-05): one box
// (6 degrees of freedom) on the ground at 4 contacts, μ = 0.5, two of them approaching at 1.57 m/s. Every
// stage presses all four contacts and stalls at a natural-map residual of 1.9e-5; the solution leaves
// the fourth open (projected Gauss–Seidel finds it after ~1,000 sweeps). With the release stage the
// solver reaches fclib's natural map ≤ the tolerance by forcing that contact open: Coulomb's law holds
// at every contact (the residual is zero exactly when it does), the released contact carries no impulse
// and separates (u_n ≥ 0). Without the stage the same problem is counted unconverged.
TEST(LedasFriction, ReleasingOneContactSolvesWhereEveryStageStalls) {
  const double lower[] = {
      1.8239385470855221, 0.5605172468188947, 0.59051337698547635, -0.24172044607345169, 0.14609289324644092,
      1.5827665912785611, 0.22393979923631985, -0.15987778569173688, -0.5886458314870483, 1.8239388794830029,
      0.56026092985282483, 0.72395059608550349, 0.8280558289293517, -0.1596214753162658, 1.3408009669735985,
      -0.24118958447332636, -0.13046961044728159, 0.16932833128367986, -0.58917667942740204, -0.45043004667593084,
      0.83247909140468956, 0.44102832581745283, 0.15938507371887883, 0.58966683652228113, -1.1589704227649302,
      0.15912876340470855, 0.59019768433566167, 1.8273394761186468, 0.55936630756039563, 0.38248306556216949,
      -0.91386699474302147, -0.1598341361987575, -0.23552065042887832, 0.3670089637226594, 0.15934278590358045,
      1.3425308060360088, -0.24086146238775835, 0.046131592338302295, 1.0705014274205522, -0.58721047646423519,
      0.36553543357674123, 0.40850410193513642, 0.5882286603777882, -0.45024911203322082, 0.83015720141581206,
      -1.1589704220317485, -0.56100995879175219, 0.24274145110868481, 0.4410286574817518, -0.56075364176438158,
      0.24221058938158635, 0.22734072753626494, -0.55985765785557218, 0.24187964630131165, 1.8273398070497642,
      0.55910999059432576, 0.51592028466219664, -0.23190405906011108, -0.15957782582328636, 0.38132972045921637,
      0.047048527494010256, 0.15908647558941014, 0.72452709004496141, -0.13084527079478206, -0.55960134082820145,
      0.58993652584198131, -0.24033060078763299, -0.23043091135542002, -0.34293683257432822, -0.58774132440458904,
      -0.91295044202854048, 1.0716548620561457, 0.58875950819116896, 0.83062684643245932, 0.16815987593039666,
      0.24134878457421322, 0.14810731575933908, 1.5827515705608699,
  };
  const double q[] = {-1.5698639851772085, 0.26863832330346077, 0.19417066529508392, -1.5698821452072425, 0.26517984982081932, 0.20133870654283836, -0.0043893198394081567, 0.27463998747818952, 0.19546815186803573, -0.0043660217618699537, 0.27118151399554807, 0.20263619311579018};

  const ledas::SparseMatrix w = symmetric_from_lower(lower, 12);
  const ledas::FrictionalProblem problem = frictional_contacts(w, q, 0.5, 6);
  ledas::FrictionalSettings without;
  without.release_max_contacts = 0;
  ledas::FrictionalSolver stalled(without), solver;
  ledas::FrictionalStats stalled_stats, stats;
  const ledas::Vector stuck = stalled.solve(problem, stalled_stats);
  EXPECT_EQ(stalled_stats.non_converged, 1u);
  EXPECT_GT(ledas::natural_map_residual(problem, stuck), 1e-6);
  const ledas::Vector r = solver.solve(problem, stats);
  EXPECT_EQ(stats.non_converged, 0u);
  EXPECT_EQ(stats.releases, 1u);
  EXPECT_LE(ledas::natural_map_residual(problem, r), problem.tolerance);
  const ledas::Vector u = w * r + problem.q;
  EXPECT_EQ(r.segment(9, 3), ledas::Vector::Zero(3));
  EXPECT_GE(u(9), -problem.tolerance);
  for (int c = 0; c < 3; ++c) {  // the other three press and slide on the cone's surface
    EXPECT_GT(r(3 * c), 0.0);
    EXPECT_NEAR(r.segment(3 * c + 1, 2).norm(), 0.5 * r(3 * c), 1e-9);
  }
  // The residual from velocities a caller already has (Newton's accepted trial, the interior point's
  // W r) is the residual, bit for bit, on the solution and on the stalled iterate alike.
  for (const ledas::Vector* iterate : {&r, &stuck}) {
    const ledas::Vector velocities = w.transpose() * *iterate + problem.q;
    EXPECT_EQ(ledas::natural_map_residual(problem, *iterate, velocities), ledas::natural_map_residual(problem, *iterate));
  }
}

// Coulomb's law contact by contact (three rows each, μ on the normal row), to the problem's tolerance:
// r_n ≥ 0, u_n ≥ 0, r_n u_n = 0, the friction within the cone, and where a contact slides, at the cone's
// edge and against the slip; and the natural-map residual within the tolerance.
void expect_coulomb_law(const ledas::SparseMatrix& w, const ledas::FrictionalProblem& problem, const ledas::Vector& r) {
  EXPECT_LE(ledas::natural_map_residual(problem, r), problem.tolerance);
  const ledas::Vector u = w * r + problem.q;
  const double tol = problem.tolerance;
  for (Eigen::Index c = 0; c < r.size() / 3; ++c) {
    const double rn = r(3 * c), un = u(3 * c), friction = r.segment(3 * c + 1, 2).norm(), slip = u.segment(3 * c + 1, 2).norm();
    const double mu = problem.mu[static_cast<std::size_t>(3 * c)];
    EXPECT_GE(rn, -tol) << c;
    EXPECT_GE(un, -tol) << c;
    EXPECT_LE(std::abs(rn * un), tol) << c;
    EXPECT_LE(friction, mu * rn + tol) << c;
    if (slip > 1e-6) {  // sliding: friction at the cone's edge, against the slip
      EXPECT_NEAR(friction, mu * rn, tol) << c;
      EXPECT_NEAR(r.segment(3 * c + 1, 2).dot(u.segment(3 * c + 1, 2)), -friction * slip, tol) << c;
    }
  }
}

// An island of the frictional 1,000-primitive pile (dumped from a run, values to the bit): a box on four
// corners and a fifth contact sliding at 0.6 m/s on it, 15 rows on 12 degrees of freedom, the box's
// contacts on the edge between sticking and slipping. Newton from the relaxation, one step of Cadoux's
// fixed point and the proximal stages stall at 20 times the tolerance; Cadoux's fixed point carried on
// (FrictionalSolver::solve, stage 4) solves it, and the answer obeys Coulomb's law contact by contact.
// Since 2026-12-07 the interior point on Coulomb's problem (stage 3, 1b) lets the proximal rounds
// finish it first.
TEST(LedasFriction, CadouxFixedPointSolvesWhereTheStagesStall) {
  const double lower[] = {
      1.5459288839486223, -0.46288894150724758, 1.9592216012218269, -0.088499883253268186, -0.25505376286274989,
      2.35590355906186, 0.65396634562904321, -0.71358852227882097, -0.56848308905250056, 1.8248819179319613,
      0.47173400826690848, -0.033838621535441926, -0.076796686715975102, 0.55953600733378983, 0.59207850006791474,
      -0.026973292680672556, -0.21103112846078836, 0.78857012279016425, -0.24442968187696326, 0.15124705471695507,
      1.5817870242775434, -0.40238158767805887, 0.22331486106818074, -0.45998168637436671, 0.22488211919809503,
      -0.16254315673333602, -0.58835658467805785, 1.8248818880427631, 0.64410377062631163, -0.24971219283265361,
      0.42903452061888592, 0.55942283409172078, 0.72770430096677341, 0.82608217479996671, -0.16242998290067329,
      1.3373606305517527, -0.38855955193171576, 0.24181464617542042, -0.27253029042327154, -0.24419223958005104,
      -0.13326007542828788, 0.16616100313180204, -0.58859402821387896, -0.45281593292451899, 0.83650488572140769,
      -0.20046496143849768, -0.10006851722221924, 0.71851998875787082, 0.44102622350868831, 0.16232549613832831,
      0.58881319653650133, -1.1589735751957246, 0.16221232230322852, 0.58905064007743546, 1.8263994272617619,
      0.20009937459025406, 0.30616478593308954, -0.87236393549180702, 0.55902416075500039, 0.37842706149399247,
      -0.91042044376088416, -0.16252077090462397, -0.23174005585455953, 0.36954919322129937, 0.16230337867121913,
      1.3381330371189222, -0.15607368625880352, -0.049229353899875546, 0.40873375992021949, -0.24404360878258893,
      0.049579330223640611, 1.0753061064260525, -0.5877158406581855, 0.3688917039083921, 0.40547300355108618,
      0.58817188952036858, -0.4527437793447992, 0.83546757323731868, -1.2568128947455999, 0.83683486612478253,
      0.82702139143600473, -1.158973575225178, -0.55975366792879766, 0.24488629373540682, 0.44102619364894363,
      -0.55964049468916544, 0.24464885144360757, 0.22639962855734952, -0.55924155298840539, 0.24449965764477211,
      1.8263993974314712, 0.37246913694965711, 0.090291214635877859, -0.36653272815694604, 0.55891098751293111,
      0.51405286239285108, -0.23558532367787249, -0.16240759707196123, 0.3779162737304198, 0.049993335725068221,
      0.16219020483611929, 0.72796591977037028, -0.13343140566004777, -0.55912837974877305, 0.59182933110793901,
      -0.51765994550984673, 0.40361642073633319, -0.6523666532932163, -0.24380616648567666, -0.23492779992160234,
      -0.34031991471968909, -0.58795328419400639, -0.91000640381609366, 1.0758168861406918, 0.58840933306130239,
      0.82722585763738421, 0.16563447036235229, 0.24426221535297279, 0.15214725374289301, 1.5817712712227332,
  };

  const double q[] = {
      -0.0057123326505887362, 0.38621531909239332, 0.46364105682365181, -0.0098032923189391753, 3.3525722209647963e-09,
      -2.5948515047829784e-09, -0.0098099990069972411, 3.2636077935295279e-09, -2.4080821766254911e-09, -0.0098080282458798077,
      1.3306192805395304e-10, -2.8460413046263345e-10, -0.0098184439512048038, 4.4097500617837652e-11, -9.7834802304087341e-11,
  };

  const ledas::SparseMatrix w = symmetric_from_lower(lower, 15);
  const ledas::FrictionalProblem problem = frictional_contacts(w, q, 0.5, 12);
  ledas::FrictionalSettings one_step;  // as before 2026-12-06: one fixed-point step, no sweeps
  one_step.fixed_point_iterations = 1;
  one_step.nonsmooth_sweeps = 0;
  one_step.projection_iterations = 0;  // nor the projection stage (2026-12-06, later)
  one_step.coulomb_interior_point_iterations = 0;  // nor the interior point on Coulomb's problem (2026-12-07)
  ledas::FrictionalSettings carried_on;
  carried_on.coulomb_interior_point_iterations = 0;
  ledas::FrictionalSolver stalled(one_step), solver(carried_on), by_default;
  ledas::FrictionalStats stalled_stats, stats, default_stats;
  const ledas::Vector stuck = stalled.solve(problem, stalled_stats);
  EXPECT_EQ(stalled_stats.non_converged, 1u);
  EXPECT_GT(ledas::natural_map_residual(problem, stuck), 5.0 * problem.tolerance);
  const ledas::Vector r = solver.solve(problem, stats);
  EXPECT_EQ(stats.non_converged, 0u);
  EXPECT_GT(stats.fixed_point_steps, 1u);
  EXPECT_EQ(stats.nonsmooth_solved, 0u);
  expect_coulomb_law(w, problem, r);
  EXPECT_GT((w * r + problem.q).segment(1, 2).norm(), 0.5);  // the fifth contact (first here) keeps sliding
  // With the defaults, the interior point on Coulomb's problem (cone_qp.hpp) runs before the proximal
  // rounds, which then finish from its answer where they stalled before: no fixed-point step beyond
  // the first, and an answer that obeys Coulomb's law as well.
  const ledas::Vector by_interior_point = by_default.solve(problem, default_stats);
  EXPECT_GT(default_stats.coulomb_interior_point_steps, 0u);
  EXPECT_EQ(default_stats.fixed_point_steps, 1u);
  EXPECT_EQ(default_stats.non_converged, 0u);
  expect_coulomb_law(w, problem, by_interior_point);
}

// The proximal stage solves the problem it is given: on the relaxation, its subproblems are relaxations
// too. The contact of the tests above doubled (two identical contacts, W = [I I; I I], q twice: one
// redundant contact), relaxed, with no interior point and no Gauss–Seidel sweeps, so that only proximal
// Newton steps can solve it. The pair's total impulse is the closed form above, r₁ + r₂ = (1.6, −0.8, 0),
// and both contacts separate at u_n = 0.6, to 1e-12. (Until 2026-12-05 each subproblem was judged by
// Coulomb's residual, which the relaxation's answer does not zero here: no subproblem was ever accepted.)
TEST(LedasFriction, ProximalStageSolvesTheRelaxationOnRedundantContacts) {
  Eigen::MatrixXd pair(6, 6);
  pair << Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(),
      Eigen::Matrix3d::Identity();
  const ledas::SparseMatrix w = pair.sparseView();
  const ledas::SparseMatrix single = Eigen::MatrixXd::Identity(3, 3).sparseView();
  const ledas::FrictionalProblem one = one_pushed_contact(single);
  ledas::FrictionalProblem problem = one;
  problem.w = &w;
  problem.q = ledas::Vector(6);
  problem.q << one.q, one.q;
  problem.role.insert(problem.role.end(), one.role.begin(), one.role.end());
  problem.mu.insert(problem.mu.end(), one.mu.begin(), one.mu.end());
  problem.dofs = 3;  // fewer than the rows: the solver knows W is singular
  problem.convex = true;
  ledas::FrictionalSettings settings;
  settings.interior_point_iterations = 0;
  settings.polish_newton_iterations = 0;
  settings.sweeps_per_round = 0;
  ledas::FrictionalSolver solver(settings);
  ledas::FrictionalStats stats;
  const ledas::Vector r = solver.solve(problem, stats);
  EXPECT_EQ(stats.interior_point_steps, 0u);
  EXPECT_GT(stats.proximal_steps, 0u);
  EXPECT_EQ(stats.non_converged, 0u);
  const ledas::Vector total = r.head(3) + r.tail(3), u = w * r + problem.q;
  EXPECT_NEAR(total(0), 1.6, 1e-12);
  EXPECT_NEAR(total(1), -0.8, 1e-12);
  EXPECT_NEAR(total(2), 0.0, 1e-12);
  EXPECT_NEAR(u(0), 0.6, 1e-12);
  EXPECT_NEAR(u(3), 0.6, 1e-12);
}

}  // namespace
}  // namespace impetus
