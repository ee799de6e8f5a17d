// LEDAS resolver inside a World (split step, the paper's euler integrator): assembly constraints at
// velocity and position level (sec. 4), resting boxes and stacks, a ball landing through a gap
// contact; options and constraint acceptance.
#include "impetus/integrators/euler/euler.hpp"
#include "impetus/engine/world.hpp"
#include "ledas_test_support.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

namespace impetus {
namespace {

using namespace ledas_test;

std::unique_ptr<World> make_world(double dt, const LedasSettings& settings = {}) {
  WorldSettings ws;
  ws.dt = dt;
  auto world = std::make_unique<World>(ws);
  world->set_integrator(std::make_shared<EulerIntegrator>(ModuleOptions{}));
  world->set_resolver(std::make_shared<LedasResolver>(settings));
  return world;
}

struct ChainRun {
  double gap = 0.0;           // largest joint gap over the run (m)
  double systems_per_step = 0.0;
  double lowest = 0.0;        // lowest z of the last link's centre (m): it did swing
};

// A chain of three boxes hanging from a fixed point by point-point joints, released horizontally,
// swinging for 20 s at dt = 0.01 (the paper's experiment, sec. 4).
ChainRun swing_chain(ConstraintLevel level) {
  auto world = make_world(0.01);
  RigidBody anchor = solid(Box{Vec3(0.1, 0.1, 0.1)}, 1.0, Vec3::Zero());
  anchor.name = "anchor";
  make_fixed(anchor);
  world->add_body(anchor);
  for (int i = 0; i < 3; ++i) {
    RigidBody link = solid(Box{Vec3(1.0, 0.2, 0.2)}, 1.0, Vec3(0.5 + i, 0, 0));
    link.name = "link" + std::to_string(i);
    world->add_body(link);
  }
  for (BodyIndex i = 0; i < 3; ++i) {  // joint i at x = i, between body i and body i + 1
    const Vec3 point(double(i), 0, 0);
    PointPointConstraint joint;
    joint.a = i;
    joint.b = i + 1;
    joint.anchor_a = world->bodies()[i].rotation.transpose() * (point - world->bodies()[i].position);
    joint.anchor_b = point - world->bodies()[i + 1].position;
    joint.level = level;
    world->add_constraint(joint);
  }
  ChainRun run;
  std::uint64_t systems = 0;
  for (int step = 0; step < 2000; ++step) {
    const StepStatus& s = world->step();
    EXPECT_TRUE(s.ok);
    EXPECT_EQ(s.resolver.non_converged, 0u);
    systems += s.resolver.rounds;
    for (const Constraint& c : world->constraints()) run.gap = std::max(run.gap, ledas::constraint_gap(world->bodies(), c));
    run.lowest = std::min(run.lowest, world->bodies()[3].position.z());
  }
  run.systems_per_step = static_cast<double>(systems) / 2000.0;
  return run;
}

// Position-level joints (eqs. 9–10, re-linearized round by round) keep the joined points together
// orders of magnitude better than velocity-level ones, which drift apart as the paper reports.
TEST(LedasWorld, PositionLevelJointsHoldFarBetterThanVelocityLevel) {
  const ChainRun velocity = swing_chain(ConstraintLevel::velocity);
  const ChainRun position = swing_chain(ConstraintLevel::position);
  std::printf("[ledas] 3-box chain, 20 s at dt = 0.01: max joint gap velocity level %.3e m (%.2f systems/step), "
              "position level %.3e m (%.2f systems/step)\n",
              velocity.gap, velocity.systems_per_step, position.gap, position.systems_per_step);
  EXPECT_LT(position.gap, 1e-7);
  EXPECT_GT(velocity.gap, 1e-2);
  EXPECT_LT(velocity.lowest, -1.0);
  EXPECT_LT(position.lowest, -1.0);
}

// Coaxial joint to a fixed body, axis z: the body slides along and spins about the axis freely while
// gravity pulls sideways; its axis stays on the fixed axis (position level, 1e-6 m) and the sliding
// and spinning speeds are untouched (1e-9).
TEST(LedasWorld, CoaxialJointLetsTheBodySlideAndSpin) {
  auto world = make_world(0.01);
  RigidBody rail = solid(Box{Vec3(0.1, 0.1, 0.1)}, 1.0, Vec3::Zero());
  rail.name = "rail";
  make_fixed(rail);
  world->add_body(rail);
  RigidBody slider = solid(Box{Vec3(0.3, 0.4, 1.0)}, 2.0, Vec3(0, 0, 0.5), Vec3(0, 0, 0.7));
  slider.name = "slider";
  slider.angular_velocity = Vec3(0, 0, 3.0);
  world->add_body(slider);
  CoaxialConstraint joint;
  joint.a = 0;
  joint.b = 1;
  joint.anchor_b = Vec3(0, 0, -0.5);
  joint.length = 1.0;
  world->add_constraint(joint);
  WorldSettings ws = world->settings();
  double gap = 0.0;
  for (int step = 0; step < 200; ++step) {
    world->bodies()[1].force = Vec3(2.0 * 9.81, 0, 0);  // a sideways pull the joint must hold
    ASSERT_TRUE(world->step().ok);
    gap = std::max(gap, ledas::constraint_gap(world->bodies(), world->constraints()[0]));
  }
  const RigidBody& b = world->bodies()[1];
  EXPECT_LT(gap, 1e-6);
  EXPECT_NEAR(b.velocity.z(), 0.7 - 9.81 * 2.0, 1e-9);  // gravity along the axis is not resisted
  EXPECT_NEAR(b.angular_velocity.z(), 3.0, 1e-9);
  EXPECT_LT(b.velocity.head<2>().norm(), 1e-9);
  (void)ws;
}

// Boxes resting for 60 s at dt = 1/60 (split step, e = 0): a single box on the ground, and a stack of
// five boxes (each smaller, offset 1 cm in x), every one starting 0.2 mm into its support (more than
// the slop, so the position correction acts). Every contact's penetration stays below the detector
// margin, no box drifts more than 1 mm nor turns more than 1e-5 rad, and the final penetration is
// the slop (0.1 mm, 1e-6).
TEST(LedasWorld, RestingBoxAndStackStayPut) {
  const double margin = 1e-3;
  for (int count : {1, 5}) {
    auto world = make_world(1.0 / 60.0);
    world->add_body(ground_plane());
    double z = 0.0;
    for (int i = 0; i < count; ++i) {
      const double size = 1.0 - 0.1 * i, overlap = 2e-4;
      RigidBody box = solid(Box{Vec3(size, size, size)}, 1.0 + i, Vec3(0.01 * i, 0, z + 0.5 * size - overlap));
      box.name = "box" + std::to_string(i);
      world->add_body(box);
      z += size - overlap;
    }
    world->set_detector(std::make_shared<BoxStackDetector>(margin));
    std::vector<Vec3> start;
    for (const RigidBody& b : world->bodies()) start.push_back(b.position);
    double deepest = 0.0, drift = 0.0;
    for (int step = 0; step < 3600; ++step) {
      const StepStatus& s = world->step();
      ASSERT_TRUE(s.ok);
      EXPECT_EQ(s.resolver.non_converged, 0u);
      for (const Contact& c : world->contacts()) deepest = std::max(deepest, c.depth);
      for (std::size_t i = 1; i < start.size(); ++i)
        drift = std::max(drift, (world->bodies()[i].position - start[i]).norm());
    }
    double final_depth = 0.0;
    for (const Contact& c : world->contacts()) final_depth = std::max(final_depth, c.depth);
    std::printf("[ledas] %d resting box(es), 60 s at dt = 1/60: max penetration %.3e m (final %.3e m), max drift "
                "%.3e m\n", count, deepest, final_depth, drift);
    EXPECT_NEAR(final_depth, 1e-4, 1e-6);
    EXPECT_LT(deepest, margin);
    EXPECT_LT(drift, 1e-3);
    for (std::size_t i = 1; i < start.size(); ++i)
      EXPECT_LT((world->bodies()[i].rotation - Mat3::Identity()).norm(), 1e-5);
  }
}

// Sphere–ground detector with a generous margin: contacts from 5 cm above the ground.
class MarginSphereDetector final : public CollisionDetector {
 public:
  ModuleStatus set_bodies(std::span<const RigidBody>, std::span<const BodyPair>) noexcept override { return {}; }
  void detect(std::span<const RigidBody> bodies, const StepContext&, std::vector<Contact>& contacts,
              DetectorCounters&) noexcept override {
    const double r = std::get<Sphere>(bodies[1].shape).radius;
    if (bodies[1].position.z() - r < 0.05)
      contacts.push_back(contact(0, 1, bodies[1].position - Vec3(0, 0, r), Vec3::UnitZ(), r - bodies[1].position.z()));
  }
};

// A ball dropped onto the ground through gap contacts (margin 5 cm) lands exactly on the surface, not
// the margin short of it, and stays there (1e-9 m); it never penetrates.
TEST(LedasWorld, FallingBallDoesNotStopShortOfTheGround) {
  for (LedasMode mode : {LedasMode::paper, LedasMode::complementary}) {
    auto world = make_world(0.01, settings_for(mode));
    world->add_body(ground_plane());
    world->add_body(sphere(0.5, 1.0, Vec3(0, 0, 1.2)));
    world->set_detector(std::make_shared<MarginSphereDetector>());
    double lowest = 1e9;
    for (int step = 0; step < 200; ++step) {
      ASSERT_TRUE(world->step().ok);
      lowest = std::min(lowest, world->bodies()[1].position.z());
    }
    EXPECT_NEAR(world->bodies()[1].position.z(), 0.5, 1e-9);
    EXPECT_GE(lowest, 0.5 - 1e-12);
  }
}

// The position correction asks only for what the problem's tolerance (1e-12 m) can see: a sphere at
// rest on the ground overlapping by the slop plus rounding (1e-15 m more) gets no correction problem
// and does not move; overlapping by 1e-6 m more it is pushed out by correction × 1e-6 m (1e-15).
TEST(LedasWorld, PositionCorrectionSkipsRoundingAboveTheSlop) {
  const LedasSettings settings = settings_for(LedasMode::complementary);
  for (const double excess : {1e-15, 1e-6}) {
    const double depth = settings.resting.slop + excess;
    std::vector<RigidBody> bodies{ground_plane(), sphere(0.5, 1.0, {0, 0, 0.5 - depth})};
    std::vector<Contact> contacts{contact(0, 1, {0, 0, -depth}, Vec3::UnitZ(), depth)};
    LedasResolver resolver(settings);
    resolve(resolver, bodies, contacts);
    const double moved = bodies[1].position.z() - (0.5 - depth);
    if (excess < 1e-12) {
      EXPECT_EQ(resolver.last_stats().position.iterations, 0u);
      EXPECT_EQ(moved, 0.0);
    } else {
      EXPECT_GE(resolver.last_stats().position.iterations, 1u);
      EXPECT_NEAR(moved, settings.resting.correction * excess, 1e-15);
    }
  }
}

// Options: every documented option is read; bad values are rejected with the option's name.
TEST(LedasWorld, OptionsAreReadAndChecked) {
  ModuleOptions options("plugin 'ledas' (resolver)");
  const auto set = [&](const char* key, const char* value) { options.set(key, OptionValue{value, {}, false, "--set"}); };
  set("mode", "paper");
  set("tolerance", "1e-8");
  set("max_rounds", "500");
  set("dense_limit", "32");
  set("rank_tolerance", "1e-9");
  set("update_limit", "4");
  set("slop", "2e-4");
  set("correction", "0.5");
  set("bounce_threshold", "0.1");
  set("search_regularization", "1e-4");
  set("sharpen_refinement", "false");
  set("start_set", "touching");
  set("interior_point_rows", "0");
  set("interior_point_stall_excess", "10");
  const LedasSettings s = LedasSettings::from_options(options);
  EXPECT_TRUE(options.unread().empty());
  EXPECT_EQ(s.mode, LedasMode::paper);
  EXPECT_EQ(s.max_rounds, 500u);
  EXPECT_EQ(s.solver.dense_limit, 32u);
  EXPECT_DOUBLE_EQ(s.solver.search_regularization, 1e-4);
  EXPECT_FALSE(s.solver.sharpen_refinement);
  EXPECT_EQ(s.start_set, LedasStartSet::touching);
  EXPECT_EQ(s.solver.interior_point_rows, 0u);
  EXPECT_DOUBLE_EQ(s.solver.interior_point_stall_excess, 10.0);
  EXPECT_DOUBLE_EQ(s.resting.correction, 0.5);
  set("mode", "sequential");
  EXPECT_THROW(LedasSettings::from_options(options), OptionError);
  set("mode", "paper");
  set("start_set", "all");
  EXPECT_THROW(LedasSettings::from_options(options), OptionError);
  set("start_set", "impact");
  set("interior_point_rows", "-1");
  EXPECT_THROW(LedasSettings::from_options(options), OptionError);
  set("interior_point_rows", "0");
  for (const char* bad : {"-1", "nan", "1e7"}) {
    set("interior_point_stall_excess", bad);
    EXPECT_THROW(LedasSettings::from_options(options), OptionError) << bad;
  }
}

// Constraints: point-point and coaxial are accepted, a coaxial joint with a zero axis is refused.
TEST(LedasWorld, AcceptsPointPointAndCoaxialConstraints) {
  LedasResolver resolver;
  CoaxialConstraint bad;
  bad.axis_b = Vec3::Zero();
  const Constraint good[] = {PointPointConstraint{}, CoaxialConstraint{}};
  const Constraint wrong[] = {bad};
  EXPECT_TRUE(resolver.accept_constraints(good).ok);
  const ModuleStatus s = resolver.accept_constraints(wrong);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("axis"), std::string::npos);
}

}  // namespace
}  // namespace impetus
