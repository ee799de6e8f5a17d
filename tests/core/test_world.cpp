// The World and its step: stage order, the sink of the paper's order, NaN rollback, metrics, validation.
// Modules here are tiny test doubles written against the module contracts, not plugins.
#include "impetus/core/error.hpp"
#include "impetus/core/mass.hpp"
#include "impetus/engine/metrics.hpp"
#include "impetus/engine/world.hpp"
#include "impetus_test/bodies.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace impetus {
namespace {

using Log = std::vector<std::string>;

RigidBody sphere(const std::string& name, double radius, double mass, const Vec3& position) {
  RigidBody b;
  b.name = name;
  b.shape = Sphere{radius};
  set_primitive_mass(b, mass);
  b.position = position;
  return b;
}

RigidBody ground() { return test::ground_plane(); }

// Symplectic Euler for translation only; logs its phases.
class LinearIntegrator : public Integrator {
 public:
  explicit LinearIntegrator(Log* log = nullptr) : log_(log) {}
  void integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx, IntegratorCounters&) noexcept override {
    if (log_) log_->push_back("velocities");
    for (RigidBody& b : bodies)
      if (!b.fixed) b.velocity += ctx.dt * (ctx.gravity + b.inv_mass * b.force);
  }
  void integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx, IntegratorCounters&) noexcept override {
    if (log_) log_->push_back("positions");
    for (RigidBody& b : bodies)
      if (!b.fixed) b.position += ctx.dt * b.velocity;
  }
  Log* log_;
};

// Exact sphere–ground-plane contacts (plane z = 0), normal out of the ground (body a) into the sphere.
class SpherePlaneDetector : public CollisionDetector {
 public:
  explicit SpherePlaneDetector(Log* log = nullptr) : log_(log) {}
  ModuleStatus set_bodies(std::span<const RigidBody>, std::span<const BodyPair> excluded) noexcept override {
    excluded_.assign(excluded.begin(), excluded.end());
    return {};
  }
  void detect(std::span<const RigidBody> bodies, const StepContext&, std::vector<Contact>& contacts,
              DetectorCounters& counters) noexcept override {
    if (log_) log_->push_back("detect");
    for (BodyIndex i = 1; i < bodies.size(); ++i) {
      const double r = std::get<Sphere>(bodies[i].shape).radius;
      const double depth = r - bodies[i].position.z();
      if (depth < -1e-6) continue;
      contacts.push_back({0, i, bodies[i].position - Vec3(0, 0, r), Vec3::UnitZ(), depth, 0, 0.0});
      ++counters.contacts;
    }
  }
  Log* log_;
  std::vector<BodyPair> excluded_;
};

// Single-contact closed form for a sphere on a fixed plane: p = −v_n / (1/m) (pushes when approaching).
class PlaneContactResolver : public CollisionResolver {
 public:
  explicit PlaneContactResolver(Log* log = nullptr) : log_(log) {}
  void resolve(std::span<RigidBody> bodies, std::span<Contact> contacts, std::span<const Constraint>,
               const StepContext&, ResolverCounters& counters) noexcept override {
    if (log_) log_->push_back("resolve");
    for (Contact& c : contacts) {
      const double vn = normal_velocity(c, bodies[c.a], bodies[c.b]);
      if (vn >= 0.0) continue;
      c.impulse = -vn / bodies[c.b].inv_mass;
      apply_contact_impulse(c, c.impulse, bodies[c.a], bodies[c.b]);
      ++counters.rounds;
    }
  }
  Log* log_;
};

// Writes a NaN into the last body's velocity: the world must catch it and roll back.
class PoisonIntegrator : public LinearIntegrator {
 public:
  void integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx, IntegratorCounters& c) noexcept override {
    LinearIntegrator::integrate_velocities(bodies, ctx, c);
    bodies.back().velocity.y() = std::numeric_limits<double>::quiet_NaN();
  }
};

std::unique_ptr<World> world_with_ball_on_ground(StepOrder order, Log* log = nullptr) {
  WorldSettings settings;
  settings.order = order;
  auto world = std::make_unique<World>(settings);
  world->add_body(ground());
  world->add_body(sphere("ball", 0.5, 2.0, {0, 0, 0.5}));
  world->set_integrator(std::make_shared<LinearIntegrator>(log));
  world->set_detector(std::make_shared<SpherePlaneDetector>(log));
  world->set_resolver(std::make_shared<PlaneContactResolver>(log));
  return world;
}

TEST(WorldStep, SplitOrderIsVelocitiesDetectResolvePositions) {
  Log log;
  world_with_ball_on_ground(StepOrder::split, &log)->step();
  EXPECT_EQ(log, (Log{"velocities", "detect", "resolve", "positions"}));
}

TEST(WorldStep, PaperOrderIsVelocitiesPositionsDetectResolve) {
  Log log;
  world_with_ball_on_ground(StepOrder::paper, &log)->step();
  EXPECT_EQ(log, (Log{"velocities", "positions", "detect", "resolve"}));
}

// docs/conventions.md, "The step": in the paper's order a resting body sinks by g·dt² every step (positions move
// with velocities the resolver has not seen); in the split order it does not move. Tolerance 1e-12 m.
TEST(WorldStep, RestingBallSinksByGDtSquaredPerStepOnlyInThePaperOrder) {
  const int steps = 100;
  const auto paper_world = world_with_ball_on_ground(StepOrder::paper);
  const auto split_world = world_with_ball_on_ground(StepOrder::split);
  World& paper = *paper_world;
  World& split = *split_world;
  for (int i = 0; i < steps; ++i) {
    ASSERT_TRUE(paper.step().ok);
    ASSERT_TRUE(split.step().ok);
  }
  const double g = 9.81, dt = paper.settings().dt;
  EXPECT_NEAR(0.5 - paper.bodies()[1].position.z(), steps * g * dt * dt, 1e-12);
  EXPECT_NEAR(split.bodies()[1].position.z(), 0.5, 1e-12);
  EXPECT_NEAR(split.bodies()[1].velocity.norm(), 0.0, 1e-12);
}

TEST(WorldStep, TimeIsStepCountTimesDtWithoutAccumulatedRounding) {
  auto world = world_with_ball_on_ground(StepOrder::split);
  for (int i = 0; i < 1000; ++i) world->step();
  EXPECT_EQ(world->step_count(), 1000u);
  EXPECT_EQ(world->time(), 1000 * world->settings().dt);
}

TEST(WorldStep, ProfileTimesEveryStageAndTotalCoversThem) {
  auto world = world_with_ball_on_ground(StepOrder::split);
  const StepStatus& s = world->step();
  for (double t : {s.profile.velocities, s.profile.detect, s.profile.resolve, s.profile.positions})
    EXPECT_GE(t, 0.0);
  EXPECT_GE(s.profile.total, s.profile.velocities + s.profile.detect + s.profile.resolve + s.profile.positions);
  EXPECT_EQ(s.detector.contacts, 1u);
  EXPECT_EQ(s.resolver.rounds, 1u);
}

TEST(WorldStep, NanIsCaughtNamedAndRolledBackBitExactly) {
  World world;
  world.add_body(sphere("a", 0.5, 1.0, {0, 0, 3}));
  world.add_body(sphere("b", 0.5, 1.0, {2, 0, 3}));
  world.set_integrator(std::make_shared<PoisonIntegrator>());
  const Vec3 before = world.bodies()[1].velocity;
  const StepStatus& s = world.step();
  EXPECT_FALSE(s.ok);
  EXPECT_EQ(s.nan_caught, 1u);
  EXPECT_NE(s.message.find("'b'"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("velocity integration"), std::string::npos) << s.message;
  EXPECT_EQ(world.bodies()[1].velocity, before);
  EXPECT_EQ(world.bodies()[0].position, Vec3(0, 0, 3));
  EXPECT_EQ(world.step_count(), 0u);
}

// Kinetic energy ½ m v² + ½ ωᵀ J ω, potential −m g·x, momenta Σ m v and Σ x × m v + J ω. Exact to 1e-12.
TEST(WorldMetrics, MatchTheClosedFormsForASpinningMovingBox) {
  World world;
  RigidBody box;
  box.name = "box";
  box.shape = Box{Vec3(1, 2, 3)};
  const double m = 6.0;
  box.mass = m;
  box.inv_mass = 1 / m;
  box.inertia_body = Vec3(m * 13 / 12, m * 10 / 12, m * 5 / 12).asDiagonal();
  box.inv_inertia_body = box.inertia_body.inverse();
  box.position = {1, 2, 3};
  box.velocity = {0.5, -1, 2};
  box.angular_velocity = {0.3, 0.2, -0.1};
  world.add_body(box);
  world.add_body(ground());
  const WorldMetrics w = measure(world);
  const Vec3 Jw(m * 13 / 12 * 0.3, m * 10 / 12 * 0.2, m * 5 / 12 * -0.1);
  EXPECT_NEAR(w.kinetic_energy, 0.5 * m * 5.25 + 0.5 * Vec3(0.3, 0.2, -0.1).dot(Jw), 1e-12);
  EXPECT_NEAR(w.potential_energy, m * 9.81 * 3, 1e-12);
  EXPECT_TRUE(w.linear_momentum.isApprox(m * Vec3(0.5, -1, 2), 1e-12));
  EXPECT_TRUE(w.angular_momentum.isApprox(Vec3(1, 2, 3).cross(m * Vec3(0.5, -1, 2)) + Jw, 1e-12));
}

TEST(WorldBodies, InvalidBodiesAreRefusedNamingTheBody) {
  World world;
  RigidBody negative = sphere("neg", 0.5, 1.0, Vec3::Zero());
  negative.mass = -1;
  negative.inv_mass = -1;
  EXPECT_THROW(
      {
        try {
          world.add_body(negative);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("'neg'"), std::string::npos);
          throw;
        }
      },
      Error);
  RigidBody nan = sphere("nan", 0.5, 1.0, Vec3::Zero());
  nan.position.x() = std::nan("");
  EXPECT_THROW(world.add_body(nan), Error);
  RigidBody plane;
  plane.name = "loose_plane";
  plane.shape = Plane{};
  EXPECT_THROW(world.add_body(plane), Error);
  world.add_body(sphere("twin", 0.5, 1.0, Vec3::Zero()));
  EXPECT_THROW(world.add_body(sphere("twin", 0.5, 1.0, Vec3::Zero())), Error);
}

TEST(WorldConstraints, NonCollidingConstraintPairsAreExcludedFromDetection) {
  World world;
  world.add_body(sphere("a", 0.5, 1.0, Vec3::Zero()));
  world.add_body(sphere("b", 0.5, 1.0, Vec3(1, 0, 0)));
  world.add_body(sphere("c", 0.5, 1.0, Vec3(2, 0, 0)));
  world.add_constraint(PointPointConstraint{1, 0, Vec3(0.5, 0, 0), Vec3(-0.5, 0, 0)});
  world.add_constraint(PointPointConstraint{1, 2, Vec3(0.5, 0, 0), Vec3(-0.5, 0, 0), ConstraintLevel::position, true});
  auto detector = std::make_shared<SpherePlaneDetector>();
  world.set_detector(detector);
  EXPECT_EQ(detector->excluded_, (std::vector<BodyPair>{{0, 1}}));
  EXPECT_THROW(world.add_constraint(PointPointConstraint{0, 7}), Error);
}

// A resolver that records what bodies_removed() told it.
class RenumberLog : public PlaneContactResolver {
 public:
  ModuleStatus accept_constraints(std::span<const Constraint>) noexcept override { return {}; }
  void bodies_removed(std::span<const std::int64_t> new_index) noexcept override {
    told.assign(new_index.begin(), new_index.end());
  }
  std::vector<std::int64_t> told;
};

// Removal: later indices shift down, handles stay, the joined constraints go with the body and the others
// are renumbered, the last contacts are cleared, the resolver gets the renumbering at once and the
// detector the new bodies before the next detection.
TEST(WorldBodies, RemovalRenumbersConstraintsAndTellsTheModules) {
  World world;
  world.add_body(ground());
  for (const char* name : {"a", "b", "c", "d"}) world.add_body(sphere(name, 0.5, 1.0, {0, 0, 0.5}));
  world.add_constraint(PointPointConstraint{1, 2, Vec3::Zero(), Vec3::Zero()});  // a–b: goes with b
  world.add_constraint(PointPointConstraint{3, 4, Vec3::Zero(), Vec3::Zero()});  // c–d: renumbered
  world.set_integrator(std::make_shared<LinearIntegrator>());
  auto detector = std::make_shared<SpherePlaneDetector>();
  auto resolver = std::make_shared<RenumberLog>();
  world.set_detector(detector);
  world.set_resolver(resolver);
  world.step();
  ASSERT_EQ(world.contacts().size(), 4u);
  const BodyHandle b = world.handle(2), d = world.handle(4);
  EXPECT_EQ(world.remove_body("b"), 1u);
  EXPECT_EQ(resolver->told, (std::vector<std::int64_t>{0, 1, -1, 2, 3}));
  EXPECT_TRUE(world.contacts().empty());
  ASSERT_EQ(world.constraints().size(), 1u);
  const auto& joint = std::get<PointPointConstraint>(world.constraints()[0]);
  EXPECT_EQ(joint.a, 2u);
  EXPECT_EQ(joint.b, 3u);
  EXPECT_EQ(world.index_of(d), BodyIndex{3});
  EXPECT_FALSE(world.index_of(b).has_value());
  world.step();
  EXPECT_EQ(world.contacts().size(), 3u);  // the detector saw four bodies, not five
  for (const Contact& c : world.contacts()) EXPECT_LT(c.b, 4u);
  // Twice is an error, by handle or by name, and says which.
  try {
    world.remove_body(b);
    ADD_FAILURE() << "removing a removed body did not throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("(it was removed)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(world.remove_body("b"), Error);
  EXPECT_THROW(world.remove_body(BodyHandle{99}), Error);
  // New bodies get new handles, never a removed one's.
  world.add_body(sphere("e", 0.5, 1.0, {0, 0, 0.5}));
  EXPECT_GT(world.handle(4).value, d.value);
}

// A fixed body moves exactly with its prescribed velocities (x += dt v, R = Q(ω dt) R each step): after
// 1000 steps it sits at v t (1e-12) turned by ω t (1e-12); `surface` leaves it in place.
TEST(WorldBodies, FixedBodiesMoveWithTheirPrescribedMotion) {
  World world;
  RigidBody mover = ground();
  mover.name = "mover";
  mover.shape = Box{Vec3(1, 1, 1)};
  mover.motion = PrescribedMotion::moving;
  mover.velocity = Vec3(0.3, -0.2, 0.1);
  mover.angular_velocity = Vec3(0.0, 0.0, 0.5);
  RigidBody belt = mover;
  belt.name = "belt";
  belt.motion = PrescribedMotion::surface;
  world.add_body(mover);
  world.add_body(belt);
  world.set_integrator(std::make_shared<LinearIntegrator>());
  for (int i = 0; i < 1000; ++i) world.step();
  const RigidBody& moved = world.bodies()[0];
  EXPECT_LT((moved.position - Vec3(0.3, -0.2, 0.1)).norm(), 1e-12);
  EXPECT_LT((moved.rotation - Eigen::AngleAxisd(0.5, Vec3::UnitZ()).toRotationMatrix()).norm(), 1e-12);
  EXPECT_EQ(moved.velocity, mover.velocity);  // never changed by the step
  EXPECT_EQ(world.bodies()[1].position, Vec3::Zero());
  EXPECT_EQ(world.bodies()[1].rotation, Mat3::Identity());
}

}  // namespace
}  // namespace impetus
