// Resting contact and joints over long runs, end to end: bundled scenes stepped with World::step().
#include "scenario_support.hpp"

#include "impetus/core/error.hpp"

#include <cstdio>
#include <string>
#include <utility>

namespace impetus::scenario {
namespace {

// Steps `run` for `seconds` of simulated time and checks that every body stays where it started:
// penetration stays below the detector margin every step, and no body drifts more than 1 mm.
void expect_stays_put(SceneRun& run, double seconds, const char* label) {
  const double margin = run.scene.detector.options.number("margin", 0.0);
  ASSERT_GT(margin, 0.0) << "the scene should set the detector's margin";
  std::vector<Vec3> start;
  for (const RigidBody& b : run.world->bodies()) start.push_back(b.position);
  const auto steps = static_cast<std::uint64_t>(seconds / run.world->settings().dt + 0.5);
  double max_penetration = 0.0;
  std::uint64_t max_rounds = 0, non_converged = 0;
  for (std::uint64_t i = 0; i < steps; ++i) {
    const StepStatus& status = run.world->step();
    ASSERT_TRUE(status.ok) << status.message;
    max_penetration = std::max(max_penetration, measure(*run.world).max_penetration);
    max_rounds = std::max(max_rounds, status.resolver.rounds);
    non_converged += status.resolver.non_converged;
  }
  double drift = 0.0;
  for (std::size_t i = 0; i < start.size(); ++i)
    drift = std::max(drift, (run.world->bodies()[i].position - start[i]).norm());
  std::printf("[ scenario ] %-28s %llu steps: max penetration %.3g m (margin %.3g), drift %.3g m, "
              "max rounds/step %llu, non-converged steps %llu\n",
              label, static_cast<unsigned long long>(steps), max_penetration, margin, drift,
              static_cast<unsigned long long>(max_rounds), static_cast<unsigned long long>(non_converged));
  EXPECT_LT(max_penetration, margin);
  EXPECT_LT(drift, 1e-3);
}

// box_on_ground.yaml with ledas: a unit box rests on the ground for 60 s at dt = 1/60 s.
TEST(ScenarioResting, BoxOnGroundStaysPut) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"});
  SceneRun run("box_on_ground.yaml");
  expect_stays_put(run, 60.0, "box on ground (ledas)");
}

// box_stack_10.yaml with ledas: ten stacked unit boxes rest for 60 s at dt = 1/60 s.
TEST(ScenarioResting, StackOfTenBoxesStaysPut) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"});
  SceneRun run("box_stack_10.yaml");
  expect_stays_put(run, 60.0, "box stack 10 (ledas)");
}

// The sequential resolver on the same single box: one face, four corner contacts; it must also rest.
TEST(ScenarioResting, BoxOnGroundStaysPutSequentially) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "mirtich"});
  SceneRun run("box_on_ground.yaml", {{"modules.resolver", "mirtich"}});
  expect_stays_put(run, 60.0, "box on ground (mirtich)");
}

// Largest distance between the two joined points of any point-point joint of `world` (m).
double joint_separation(const World& world) {
  double worst = 0.0;
  for (const Constraint& c : world.constraints()) {
    if (const auto* pp = std::get_if<PointPointConstraint>(&c)) {
      const RigidBody& a = world.bodies()[pp->a];
      const RigidBody& b = world.bodies()[pp->b];
      worst = std::max(worst, ((a.position + a.rotation * pp->anchor_a) - (b.position + b.rotation * pp->anchor_b)).norm());
    }
  }
  return worst;
}

// Runs pendulum_chain.yaml (ledas) for 20 s with every joint at `level` and time step `dt`; returns
// the largest joint separation seen and the one at the end (m).
std::pair<double, double> swing_chain(const char* level, const char* dt) {
  std::vector<SceneOverride> overrides{{"dt", dt}};
  for (int i = 0; i < 3; ++i) overrides.push_back({"constraints." + std::to_string(i) + ".point_point.level", level});
  SceneRun run("pendulum_chain.yaml", overrides);
  const int steps = static_cast<int>(20.0 / run.world->settings().dt + 0.5);
  double worst = 0.0;
  for (int i = 0; i < steps; ++i) {
    const StepStatus& status = run.world->step();
    EXPECT_TRUE(status.ok) << status.message;
    if (!status.ok) break;
    worst = std::max(worst, joint_separation(*run.world));
  }
  EXPECT_LT(run.body("link3").position.z(), 3.0);  // it swung down: gravity acts through the joints
  const double last = joint_separation(*run.world);
  std::printf("[ scenario ] pendulum chain (ledas) %s level, dt %s, 20 s: largest joint separation %.3g m, "
              "at the end %.3g m\n", level, dt, worst, last);
  return {worst, last};
}

// pendulum_chain.yaml with ledas, the paper's sec. 4 claim: velocity-level joints drift apart (at
// dt = 0.01 "unacceptable after 20 seconds"), position-level ones do not. Position level keeps only a
// per-step linearization error, O(L (ω dt)²), that does not accumulate: below 2 cm at dt = 0.01 with
// the chain whipping, below 1 mm at dt = 0.001. Velocity level at dt = 0.01 ends more than 10 cm apart.
TEST(ScenarioResting, PendulumChainPositionLevelJointsDoNotDrift) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"});
  EXPECT_LT(swing_chain("position", "0.01").first, 0.02);
  EXPECT_LT(swing_chain("position", "0.001").first, 1e-3);
  EXPECT_GT(swing_chain("velocity", "0.01").second, 0.1);
}

// The sequential resolver does not support joints: building the pendulum with it fails with a message
// that says so, rather than silently ignoring the constraints.
TEST(ScenarioResting, SequentialResolverRefusesJoints) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "mirtich"});
  try {
    SceneRun run("pendulum_chain.yaml", {{"modules.resolver", "mirtich"}});
    FAIL() << "expected the world to refuse the constraints";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("constraint"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace impetus::scenario
