// The sequential resolver with friction inside a World (split step, the euler integrator): a box
// sliding down and a box sticking on a 30° slope, and the behaviour of a frictional box stack (a
// measured figure for README.md).
#include "impetus/engine/world.hpp"
#include "impetus/integrators/euler/euler.hpp"
#include "impetus_test/box_stack_detector.hpp"
#include "mirtich_test_support.hpp"

#include <cstdio>
#include <memory>
#include <numbers>

namespace impetus::mirtich_test {
namespace {

constexpr double kGravity = 9.81;

std::unique_ptr<World> make_world(double dt, const Vec3& gravity, const MirtichSettings& settings) {
  WorldSettings ws;
  ws.dt = dt;
  ws.gravity = gravity;
  auto world = std::make_unique<World>(ws);
  world->set_integrator(std::make_shared<EulerIntegrator>(ModuleOptions{}));
  world->set_resolver(std::make_shared<MirtichResolver>(settings));
  return world;
}

using ::impetus::test::BoxStackDetector;

struct SlopeRun {
  double velocity = 0.0;      // final down-slope velocity (m/s)
  double displacement = 0.0;  // largest distance of the box from its start (m)
  std::uint64_t sliding = 0, sticking = 0, non_converged = 0;
};

// How the box on the slope may turn.
enum class Turning { free, locked };

// A 0.4 m cube of 1 kg resting on a 30° slope with friction μ (both materials), its four bottom
// corners in contact, for `seconds` at dt = 1e-3. The slope is the ground z ≤ 0 with gravity turned by
// the slope angle about y (the same physics as a turned plane under vertical gravity, with a simpler
// detector): down the slope is +x. `locked`: the cube's inertia is multiplied by 1e12, so it cannot
// pick up spin from the corner impulses and its four corners move as one point — this isolates the
// friction law from the sequential resolution of the four simultaneous corner contacts.
SlopeRun run_slope(double mu, double seconds, Turning turning) {
  const double slope = std::numbers::pi / 6;
  auto world = make_world(1e-3, kGravity * Vec3(std::sin(slope), 0.0, -std::cos(slope)), MirtichSettings{});
  RigidBody g = ground();
  g.material.friction = mu;
  world->add_body(g);
  RigidBody cube = box(1.0, Vec3(0.4, 0.4, 0.4), Vec3(0, 0, 0.2));
  cube.material.friction = mu;
  if (turning == Turning::locked) {
    cube.inertia_body *= 1e12;
    cube.inv_inertia_body *= 1e-12;
  }
  world->add_body(cube);
  world->set_detector(std::make_shared<BoxStackDetector>(1e-3));
  const Vec3 start = world->bodies()[1].position;
  SlopeRun run;
  const int steps = static_cast<int>(std::lround(seconds / 1e-3));
  for (int step = 0; step < steps; ++step) {
    const StepStatus& s = world->step();
    EXPECT_TRUE(s.ok) << s.message;
    run.sliding += s.resolver.sliding;
    run.sticking += s.resolver.sticking;
    run.non_converged += s.resolver.non_converged;
    run.displacement = std::max(run.displacement, (world->bodies()[1].position - start).norm());
  }
  run.velocity = world->bodies()[1].velocity.x();
  return run;
}

void print_run(const char* what, const SlopeRun& run, double expected) {
  std::printf("[ mirtich friction ] %s: v = %.15f m/s, expected %.15f (relative error %.3e), largest "
              "displacement %.3e m; %llu sliding / %llu sticking contact-steps\n",
              what, run.velocity, expected, expected == 0.0 ? 0.0 : std::abs(run.velocity - expected) / expected,
              run.displacement, static_cast<unsigned long long>(run.sliding),
              static_cast<unsigned long long>(run.sticking));
}

// μ = 0.5 < tan 30°: the (rotation-locked) box slides with a = g (sin θ − μ cos θ); its velocity after
// 1 s equals a × 1 s to 1e-9 relative, and its contacts slide.
TEST(MirtichFrictionWorld, BoxSlidesDownASlopeWithCoulombDeceleration) {
  const double slope = std::numbers::pi / 6, mu = 0.5;
  const SlopeRun run = run_slope(mu, 1.0, Turning::locked);
  const double expected = kGravity * (std::sin(slope) - mu * std::cos(slope)) * 1.0;
  print_run("slope 30°, mu 0.5, 1 s, rotation locked", run, expected);
  EXPECT_NEAR(run.velocity, expected, 1e-9 * expected);
  EXPECT_GT(run.sliding, 0u);
  EXPECT_EQ(run.non_converged, 0u);
}

// μ = 0.7 > tan 30° ≈ 0.577: the (rotation-locked) box sticks; it moves no more than 1e-9 m in 2 s.
TEST(MirtichFrictionWorld, BoxSticksOnASlopeSteeperFrictionThanItsAngle) {
  const SlopeRun run = run_slope(0.7, 2.0, Turning::locked);
  print_run("slope 30°, mu 0.7, 2 s, rotation locked", run, 0.0);
  EXPECT_LE(run.displacement, 1e-9);
  EXPECT_GT(run.sticking, 0u);
  EXPECT_EQ(run.non_converged, 0u);
}

// The same slope with a free box, measured for README.md: the four corner contacts are resolved one
// collision at a time, each corner's impulse spins the box a little and the sweep stops once no corner
// approaches, with slip left at the others. Printed: the sliding box's velocity error and the sticking
// box's creep. Asserted only loosely (the sequential method's known weakness): the sliding velocity
// within 5 % of Coulomb's, and the sticking box moves less than 1 cm in 2 s (it would slide 9.8 m
// without friction).
TEST(MirtichFrictionWorld, FreeBoxOnASlopeIsMeasured) {
  const double slope = std::numbers::pi / 6;
  const SlopeRun sliding = run_slope(0.5, 1.0, Turning::free);
  const double expected = kGravity * (std::sin(slope) - 0.5 * std::cos(slope)) * 1.0;
  print_run("slope 30°, mu 0.5, 1 s, free box", sliding, expected);
  EXPECT_NEAR(sliding.velocity, expected, 0.05 * expected);
  const SlopeRun sticking = run_slope(0.7, 2.0, Turning::free);
  print_run("slope 30°, mu 0.7, 2 s, free box", sticking, 0.0);
  EXPECT_LT(sticking.displacement, 1e-2);
}

// Measured, for README.md: a stack of 10 cubes of 1 kg (0.4 m at the bottom, each 2 cm smaller and
// offset 5 mm in x from the one below, starting 0.2 mm into its support) under vertical gravity for
// 2 s at dt = 1/60 s, frictionless and with μ = 0.5. Printed: the largest horizontal drift and the
// largest penetration of any box, and the single impulses per step. Asserted: the stack stays up (every
// box within 5 cm of its start). Disabled by default because it takes about two minutes (every step
// hits the cap of 10 000 single impulses); run it with
//   test_resolver_mirtich --gtest_also_run_disabled_tests --gtest_filter='*FrictionalStack*'
TEST(MirtichFrictionWorld, DISABLED_FrictionalStackDriftIsMeasured) {
  for (const double mu : {0.0, 0.5}) {
    auto world = make_world(1.0 / 60.0, Vec3(0, 0, -kGravity), MirtichSettings{});
    RigidBody g = ground();
    g.material.friction = mu;
    world->add_body(g);
    double z = 0.0;
    for (int i = 0; i < 10; ++i) {
      const double size = 0.4 - 0.02 * i, overlap = 2e-4;
      RigidBody cube = box(1.0, Vec3(size, size, size), Vec3(0.005 * i, 0, z + 0.5 * size - overlap));
      cube.material.friction = mu;
      world->add_body(cube);
      z += size - overlap;
    }
    world->set_detector(std::make_shared<BoxStackDetector>(1e-3));
    std::vector<Vec3> start;
    for (const RigidBody& b : world->bodies()) start.push_back(b.position);
    double drift = 0.0, deepest = 0.0, moved = 0.0;
    std::uint64_t impulses = 0, non_converged = 0;
    const int steps = 120;
    for (int step = 0; step < steps; ++step) {
      const StepStatus& s = world->step();
      ASSERT_TRUE(s.ok) << s.message;
      impulses += s.resolver.rounds;
      non_converged += s.resolver.non_converged;
      for (const Contact& c : world->contacts()) deepest = std::max(deepest, c.depth);
      for (std::size_t i = 1; i < start.size(); ++i) {
        drift = std::max(drift, (world->bodies()[i].position - start[i]).head<2>().norm());
        moved = std::max(moved, (world->bodies()[i].position - start[i]).norm());
      }
    }
    std::printf("[ mirtich friction ] 10-box stack, mu %.1f, 2 s at dt 1/60: largest horizontal drift %.3e m, "
                "largest penetration %.3e m, %.1f single impulses per step, %llu capped steps\n",
                mu, drift, deepest, static_cast<double>(impulses) / steps,
                static_cast<unsigned long long>(non_converged));
    EXPECT_LT(moved, 5e-2) << "mu " << mu;
  }
}

}  // namespace
}  // namespace impetus::mirtich_test
