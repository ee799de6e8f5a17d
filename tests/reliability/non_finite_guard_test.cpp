// The non-finite guard (World::step, core/src/world.cpp): a NaN or Inf produced inside a step — here by
// a plugin, the fixture integrator 'fixture_nan', or by a resolver built in code — never reaches the
// state. The step reports the body, the stage and the step; every body keeps its last finite state, bit
// for bit; time does not advance; and a world that keeps producing it stays stopped there.

#include "impetus/engine/metrics.hpp"
#include "reliability_support.hpp"

#include <limits>

namespace impetus::reliability {
namespace {

// Two balls falling freely; 'fixture_nan' poisons ball 'b' at step `step` in `stage`.
std::string poisoned_scene(int step, const std::string& stage, const std::string& value) {
  return "dt: 0.001\n"
         "modules:\n"
         "  integrator: {plugin: fixture_nan, body: b, step: " + std::to_string(step) + ", stage: " + stage +
         ", value: " + value + "}\n"
         "  detector: none\n"
         "  resolver: none\n"
         "bodies:\n"
         "  - {name: a, shape: {sphere: {radius: 0.5}}, mass: 1, position: [0, 0, 10]}\n"
         "  - {name: b, shape: {sphere: {radius: 0.5}}, mass: 2, position: [3, 0, 10], velocity: [1, 0, 0]}\n";
}

struct Case {
  const char* stage;      // fixture option
  const char* value;      // fixture option
  const char* reported;   // the World's name for the stage
};

void PrintTo(const Case& c, std::ostream* out) { *out << c.stage << " " << c.value; }

class NonFiniteGuard : public testing::TestWithParam<Case> {};

TEST_P(NonFiniteGuard, StopsNamingBodyStageAndStepAndKeepsTheLastFiniteState) {
  const Case& c = GetParam();
  const int poisoned_step = 7;
  const auto host = make_host();
  const auto world = build_world(load_scene_text(poisoned_scene(poisoned_step, c.stage, c.value), "nan.yaml", "."), *host);
  for (int i = 0; i < poisoned_step; ++i) ASSERT_TRUE(world->step().ok) << world->last_status().message;
  const std::vector<std::uint64_t> last_finite = state_bits(*world);
  const double time = world->time();

  // The guard holds however often the caller insists: the plugin poisons step 7 each time it is tried.
  for (int attempt = 0; attempt < 3; ++attempt) {
    const StepStatus& status = world->step();
    EXPECT_FALSE(status.ok);
    EXPECT_EQ(status.nan_caught, 1u) << "only body 'b' was poisoned";
    EXPECT_NE(status.message.find("body 'b'"), std::string::npos) << status.message;
    EXPECT_NE(status.message.find(c.reported), std::string::npos) << status.message;
    EXPECT_NE(status.message.find("at step " + std::to_string(poisoned_step)), std::string::npos) << status.message;
    EXPECT_EQ(state_bits(*world), last_finite) << "the state must be the last finite one, bit for bit";
    EXPECT_EQ(world->step_count(), static_cast<std::uint64_t>(poisoned_step));
    EXPECT_EQ(world->time(), time);
  }
  for (const RigidBody& body : world->bodies()) {
    EXPECT_TRUE(body.position.allFinite() && body.velocity.allFinite() && body.rotation.allFinite()) << body.name;
  }
  // The measures a user reads afterwards are finite too.
  const WorldMetrics m = measure(*world);
  EXPECT_TRUE(std::isfinite(m.kinetic_energy) && std::isfinite(m.potential_energy));
}

INSTANTIATE_TEST_SUITE_P(Plugin, NonFiniteGuard,
                         testing::Values(Case{"velocities", "nan", "velocity integration"},
                                         Case{"velocities", "inf", "velocity integration"},
                                         Case{"positions", "nan", "position integration"},
                                         Case{"positions", "inf", "position integration"}),
                         [](const testing::TestParamInfo<Case>& info) {
                           return std::string(info.param.stage) + "_" + info.param.value;
                         });

// A resolver that returns an infinite velocity for body 1 at every step from `from` on.
class InfResolver final : public CollisionResolver {
 public:
  explicit InfResolver(std::uint64_t from) : from_(from) {}
  void resolve(std::span<RigidBody> bodies, std::span<Contact>, std::span<const Constraint>, const StepContext& ctx,
               ResolverCounters&) noexcept override {
    if (ctx.step >= from_) bodies[1].angular_velocity.y() = std::numeric_limits<double>::infinity();
  }

 private:
  std::uint64_t from_;
};

TEST(NonFiniteGuardResolution, ANonFiniteImpulseIsCaughtAfterResolution) {
  const auto host = make_host();
  Scene scene = load_scene_text(
      "bodies:\n  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1]}}}\n"
      "  - {name: ball, shape: {sphere: {radius: 0.5}}, mass: 1, position: [0, 0, 0.5]}\n",
      "resting.yaml", ".");
  const auto world = build_world(scene, *host);
  world->set_resolver(std::make_shared<InfResolver>(3));
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(world->step().ok);
  const std::vector<std::uint64_t> last_finite = state_bits(*world);
  const StepStatus& status = world->step();
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.message.find("body 'ball' became non-finite during resolution at step 3"), std::string::npos)
      << status.message;
  EXPECT_EQ(state_bits(*world), last_finite);
}

// The same guard in the paper's step order, where both integrator phases run before detection.
TEST(NonFiniteGuardResolution, PaperOrderNamesTheIntegration) {
  const auto host = make_host();
  const auto world = build_world(
      load_scene_text("step_order: paper\n" + poisoned_scene(2, "positions", "nan"), "nan.yaml", "."), *host);
  ASSERT_TRUE(world->step().ok);
  ASSERT_TRUE(world->step().ok);
  const std::vector<std::uint64_t> last_finite = state_bits(*world);
  const StepStatus& status = world->step();
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.message.find("body 'b' became non-finite during integration at step 2"), std::string::npos)
      << status.message;
  EXPECT_EQ(state_bits(*world), last_finite);
}

}  // namespace
}  // namespace impetus::reliability
