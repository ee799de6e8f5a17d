// Pathological but legal scenes (issue 22, item 3): each finishes its steps under a bound on work that
// the test states and checks through a counter (never a wall-clock time), and with a physical answer:
//  - a 10¹²:1 mass ratio on a two-box stack: the light box stays on the heavy one, which stays on the
//    ground, in a bounded number of active-set solves (resolution/ledas: diagonal scaling, work budget);
//  - 1,000 identical joints on one pair: the same velocities as one joint, at one joint's cost
//    (resolution/ledas: duplicate constraints left out);
//  - spheres generated at one point: a failed step naming the most crowded body, never an abort or an
//    allocation of every pair (detection/fcl: the broadphase's pair limit);
//  - a body pinned by a joint deep inside the ground: the position correction moves it no further than
//    the documented bound (resolution/common/resting.hpp, "Displacement bound") and the status says so;
//  - finite but absurd states (1e200 m/s, dt = 1e300 s): a failed step naming the body, never inf or nan
//    in what the run measures (World::step's guard).

#include "impetus/core/mass.hpp"
#include "impetus/engine/metrics.hpp"
#include "reliability_support.hpp"

#include <cmath>
#include <sstream>

namespace impetus::reliability {
namespace {

std::unique_ptr<World> world_of(const std::string& text, PluginHost& host) {
  return build_world(load_scene_text(text, "pathological.yaml", "."), host);
}

const RigidBody& body_named(const World& world, const std::string& name) {
  for (const RigidBody& b : world.bodies())
    if (b.name == name) return b;
  throw Error("no body " + name);
}

// The work budget of one complementarity problem (resolution/ledas/island_solver.cpp, work_budget):
// 100 + 100 solves per row, for the search and again for the minimum-norm fallback.
constexpr std::uint64_t budget(std::uint64_t rows) { return 100 + 100 * rows; }

TEST(PathologicalScenes, MassRatioOfTenToTheTwelveStacksInBoundedWork) {
  const auto host = make_host();
  const auto world = world_of(
      "dt: 0.001\n"
      "bodies:\n"
      "  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1], offset: 0}}}\n"
      "  - {name: heavy, shape: {box: {size: [1, 1, 1]}}, mass: 1.0e12, position: [0, 0, 0.5]}\n"
      "  - {name: light, shape: {box: {size: [1, 1, 1]}}, mass: 1.0, position: [0, 0, 1.5]}\n",
      *host);
  // Eight contacts (four corners under each box): one velocity problem of 8 rows per step, and at most
  // a position problem of as many. Before the fix one step ran 10⁶ solves (the iteration cap).
  const std::uint64_t bound = 2 * 2 * budget(8);
  for (int step = 0; step < 50; ++step) {
    const StepStatus& status = world->step();
    ASSERT_TRUE(status.ok) << status.message;
    EXPECT_LE(status.resolver.rounds, bound) << "step " << step;
    EXPECT_EQ(status.resolver.work_limited, 0u) << "the scaled problem converges on its own";
  }
  const RigidBody &heavy = body_named(*world, "heavy"), &light = body_named(*world, "light");
  EXPECT_NEAR(heavy.position.z(), 0.5, 1e-4) << "the heavy box stands on the ground";
  EXPECT_NEAR(light.position.z() - heavy.position.z(), 1.0, 1e-4) << "the light box stays on the heavy one";
  EXPECT_NEAR(light.velocity.z(), heavy.velocity.z(), 1e-6);
  EXPECT_LT(std::abs(heavy.velocity.z()), 1e-6);
}

std::string pendulum(int joints) {
  std::ostringstream s;
  s << "dt: 0.001\n"
       "bodies:\n"
       "  - {name: anchor, fixed: true, shape: {sphere: {radius: 0.1}}, position: [0, 0, 2]}\n"
       "  - {name: bob, shape: {box: {size: [0.2, 0.1, 0.3]}}, mass: 1, position: [1, 0, 2], velocity: [0, 0.5, 0],"
       " angular_velocity: [0.3, -0.2, 1]}\n"
       "constraints:\n";
  for (int i = 0; i < joints; ++i) s << "  - point_point: {bodies: [anchor, bob], point: [0, 0, 2]}\n";
  return s.str();
}

TEST(PathologicalScenes, AThousandIdenticalJointsActLikeOneAtOnesCost) {
  const auto host = make_host();
  const auto one = world_of(pendulum(1), *host), many = world_of(pendulum(1000), *host);
  for (int step = 0; step < 20; ++step) {
    const StepStatus a = one->step();
    const StepStatus& b = many->step();
    ASSERT_TRUE(a.ok && b.ok) << a.message << b.message;
    EXPECT_EQ(b.resolver.rounds, a.resolver.rounds) << "the same solves as one joint (3 rows), step " << step;
    const RigidBody &p = body_named(*one, "bob"), &q = body_named(*many, "bob");
    EXPECT_LE((p.velocity - q.velocity).lpNorm<Eigen::Infinity>(), 1e-9) << "step " << step;
    EXPECT_LE((p.angular_velocity - q.angular_velocity).lpNorm<Eigen::Infinity>(), 1e-9) << "step " << step;
    EXPECT_LE((p.position - q.position).lpNorm<Eigen::Infinity>(), 1e-9) << "step " << step;
  }
}

std::string pile(int spheres) {
  std::ostringstream s;
  s << "dt: 0.001\n"
       "bodies:\n"
       "  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1], offset: 0}}}\n";
  for (int i = 0; i < spheres; ++i)
    s << "  - {name: s" << i << ", shape: {sphere: {radius: 0.5}}, mass: 1, position: [0, 0, 2]}\n";
  return s.str();
}

TEST(PathologicalScenes, SpheresAtOnePointAreRefusedNamingABodyNeverAborted) {
  const auto host = make_host();
  // 3,000 spheres at one point: 4.5 million pairs (and up to four contacts each) if every pair were kept.
  const int count = 3000;
  const auto world = world_of(pile(count), *host);
  const std::vector<std::uint64_t> before = state_bits(*world);
  for (int attempt = 0; attempt < 2; ++attempt) {
    const StepStatus& status = world->step();
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find("candidate pairs"), std::string::npos) << status.message;
    EXPECT_NE(status.message.find("body 's"), std::string::npos) << status.message;
    // Work: the broadphase stopped at its limit (16 pairs per movable body) instead of n²/2 pairs.
    EXPECT_EQ(status.detector.pair_limit, 16u * count);
    EXPECT_LE(status.detector.pairs_tested, status.detector.pair_limit);
    EXPECT_EQ(status.detector.narrowphase_calls, 0u);
    EXPECT_GT(status.detector.crowded_pairs, 0u);
    EXPECT_EQ(state_bits(*world), before) << "the refused step changes nothing";
    EXPECT_EQ(world->step_count(), 0u);
  }
  // The limit is an option: a few spheres at one point are under it and step (bounded: 45 pairs).
  const auto few = world_of(pile(10), *host);
  for (int step = 0; step < 3; ++step) {
    const StepStatus& status = few->step();
    EXPECT_TRUE(status.ok) << status.message;
    EXPECT_EQ(status.detector.pair_limit, 0u);
  }
}

TEST(PathologicalScenes, ABodyPinnedDeepInTheGroundIsNotThrown) {
  const auto host = make_host();
  // The ball's centre is pinned 0.5 m below the ground: it overlaps the ground by 1 m, the joint holds
  // it there, so the correction's targets conflict (before the fix: 10¹⁴ m in one step).
  const auto world = world_of(
      "dt: 0.001\n"
      "bodies:\n"
      "  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1], offset: 0}}}\n"
      "  - {name: post, fixed: true, shape: {sphere: {radius: 0.05}}, position: [0, 0, -0.5]}\n"
      "  - {name: ball, shape: {sphere: {radius: 0.5}}, mass: 1, position: [0, 0, -0.5]}\n"
      "constraints:\n"
      "  - point_point: {bodies: [post, ball], point: [0, 0, -0.5]}\n",
      *host);
  // The bound (resting.hpp): kCorrectionBoundFactor (2) × the island's total target, correction 0.2 ×
  // (depth 1 m − slop 1e-4 m), so 0.4 m at most per step; the depth never grows, so neither does it.
  const double bound = 2.0 * 0.2 * 1.0;
  std::uint64_t clamped = 0;
  for (int step = 0; step < 20; ++step) {
    const Vec3 before = body_named(*world, "ball").position;
    const StepStatus& status = world->step();
    ASSERT_TRUE(status.ok) << status.message;
    const RigidBody& ball = body_named(*world, "ball");
    EXPECT_LE(status.resolver.largest_correction, bound) << "step " << step;
    EXPECT_LE((ball.position - before).norm(), bound + ball.velocity.norm() * 0.001 + 1e-12) << "step " << step;
    EXPECT_LT(ball.position.norm(), 10.0) << "step " << step;
    clamped += status.resolver.corrections_clamped;
  }
  EXPECT_GT(clamped, 0u) << "the status reports the clamp";
}

TEST(PathologicalScenes, OverflowingKineticEnergyFailsTheStepNamingTheBody) {
  const auto host = make_host();
  // Finite everywhere, but v² m overflows after one step: 1e153 m/s (½ m v² = 5e305 J) pushed by 1e300 N.
  const auto world = world_of(
      "dt: 0.001\n"
      "modules: {detector: none, resolver: none}\n"
      "bodies:\n"
      "  - {name: calm, shape: {sphere: {radius: 0.5}}, mass: 1, position: [0, 0, 0]}\n"
      "  - {name: rocket, shape: {sphere: {radius: 0.5}}, mass: 1, position: [5, 0, 0], velocity: [1.0e153, 0, 0],"
      " force: [1.0e300, 0, 0]}\n",
      *host);
  ASSERT_TRUE(std::isfinite(measure(*world).kinetic_energy));
  const std::vector<std::uint64_t> before = state_bits(*world);
  for (int attempt = 0; attempt < 2; ++attempt) {
    const StepStatus& status = world->step();
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find("body 'rocket'"), std::string::npos) << status.message;
    EXPECT_NE(status.message.find("kinetic energy"), std::string::npos) << status.message;
    EXPECT_NE(status.message.find("velocity integration"), std::string::npos) << status.message;
    EXPECT_EQ(state_bits(*world), before);
    EXPECT_TRUE(std::isfinite(measure(*world).kinetic_energy)) << "what the run measures stays finite";
  }
  // A body whose kinetic energy already overflows (1e200 m/s) is refused: by the scene reader at its
  // line, and by the World, by name, when a program adds it in code.
  const std::string error = error_of([&] {
    world_of("modules: {detector: none, resolver: none}\n"
             "bodies:\n"
             "  - {name: rocket, shape: {sphere: {radius: 0.5}}, mass: 1, velocity: [1.0e200, 0, 0]}\n",
             *host);
  });
  EXPECT_NE(error.find("pathological.yaml:3:"), std::string::npos) << error;
  EXPECT_NE(error.find("kinetic energy"), std::string::npos) << error;
  RigidBody rocket;
  rocket.name = "rocket";
  rocket.shape = Sphere{0.5};
  set_primitive_mass(rocket, 1.0);
  rocket.velocity = Vec3(1.0e200, 0, 0);
  World plain;
  const std::string added = error_of([&] { plain.add_body(rocket); });
  EXPECT_NE(added.find("body 'rocket'"), std::string::npos) << added;
  EXPECT_NE(added.find("kinetic energy"), std::string::npos) << added;
}

TEST(PathologicalScenes, AWorldTotalThatOverflowsFailsTheStepForEveryThreadCount) {
  // 3000 balls of 1e305 J each: every ball, and every chunk of 1024 that the world sums in parallel
  // (1.024e308 J), is finite; the world's total (3e308 J) is not. The step fails naming a body and the
  // total, leaves the state as it was, and does so alike on 1 and 2 threads.
  std::ostringstream text;
  text << "modules: {detector: none, resolver: none}\nbodies:\n";
  const double speed = std::sqrt(2.0e305);  // ½ · 1 kg · v² = 1e305 J
  for (int i = 0; i < 3000; ++i)
    text << "  - {name: b" << i << ", shape: {sphere: {radius: 0.5}}, mass: 1, position: [" << 2 * i
         << ", 0, 0], velocity: [0, 0, " << (i % 2 ? speed : -speed) << "]}\n";
  const auto host = make_host();
  std::vector<std::string> messages;
  for (const std::uint32_t threads : {1u, 2u}) {
    const auto world = world_of(text.str(), *host);
    world->set_threads(threads);
    const std::vector<std::uint64_t> before = state_bits(*world);
    const StepStatus& status = world->step();
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find("kinetic energy (or the world's total) overflowed"), std::string::npos)
        << status.message;
    EXPECT_EQ(state_bits(*world), before);
    messages.push_back(status.message);
  }
  EXPECT_EQ(messages[0], messages[1]);
}

TEST(PathologicalScenes, AnAbsurdTimeStepFailsTheStepNamingTheBody) {
  const auto host = make_host();
  const auto world = world_of(
      "dt: 1.0e300\n"
      "bodies:\n"
      "  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1], offset: 0}}}\n"
      "  - {name: ball, shape: {sphere: {radius: 0.5}}, mass: 1, position: [0, 0, 2]}\n",
      *host);
  const std::vector<std::uint64_t> before = state_bits(*world);
  const StepStatus& status = world->step();
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.message.find("body 'ball'"), std::string::npos) << status.message;
  EXPECT_EQ(state_bits(*world), before);
  EXPECT_EQ(world->step_count(), 0u);
}

}  // namespace
}  // namespace impetus::reliability
