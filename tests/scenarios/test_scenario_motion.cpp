// Applied loads and prescribed motion end to end (docs/conventions.md, "Applied loads and prescribed
// motion"): bundled scenes stepped through the real plugins and compared with closed forms, and bodies
// added and removed between steps.
#include "scenario_support.hpp"

#include "impetus/core/error.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace impetus::scenario {
namespace {

constexpr double kG = 9.81;

std::string number(double x) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", x);
  return text;
}

void step(SceneRun& run, int steps) {
  for (int i = 0; i < steps; ++i) {
    const StepStatus& status = run.world->step();
    ASSERT_TRUE(status.ok) << status.message;
    ASSERT_EQ(status.resolver.non_converged, 0u) << "step " << i;
  }
}

// The unit box of friction_slope.yaml on level ground (μ = 0.5, m = 1 kg) or lifted into free space.
std::vector<SceneOverride> level(std::vector<SceneOverride> more) {
  more.push_back({"gravity", "[0, 0, -9.81]"});
  return more;
}

class MotionScene : public ::testing::Test {
 protected:
  void SetUp() override { IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}); }
};

// Static friction holds a box pulled by F = 0.3 m g < μ m g (it moves less than 1e-12 m in 1 s); at
// F = 0.8 m g it slides with a = F/m − μ g = 0.3 g (1e-9 relative after 1 s, the split step's velocity
// being exact step by step).
TEST_F(MotionScene, PulledBoxSticksBelowAndSlidesAboveTheFrictionLimit) {
  SceneRun holding("friction_slope.yaml", level({{"bodies.box.force", "[" + number(0.3 * kG) + ", 0, 0]"}}));
  const Vec3 start = holding.body("box").position;
  step(holding, 1000);
  EXPECT_LT((holding.body("box").position - start).norm(), 1e-12);

  SceneRun sliding("friction_slope.yaml", level({{"bodies.box.force", "[" + number(0.8 * kG) + ", 0, 0]"}}));
  step(sliding, 1000);
  const double a = 0.8 * kG - 0.5 * kG;
  EXPECT_NEAR(sliding.body("box").velocity.x(), a * 1.0, 1e-9 * a);
  EXPECT_NEAR(sliding.body("box").velocity.y(), 0.0, 1e-12);
}

// Body-frame loads turn with the body. A box turned 90° about z with force_body along its x is pushed
// along world y: v = F t / m exactly (symplectic Euler, constant force), nothing along x. A body-frame
// torque about its z (which stays the world z) spins it up at ω = τ t / J, J = m s²/6 for the unit cube.
TEST_F(MotionScene, BodyFrameLoadsActAlongTheTurnedAxes) {
  const double force = 2.0, torque = 0.5, inertia = 1.0 / 6.0;
  SceneRun run("friction_slope.yaml",
               {{"gravity", "[0, 0, 0]"},
                {"bodies.box.position", "[0, 0, 3]"},
                {"bodies.box.orientation", "[" + number(std::sqrt(0.5)) + ", 0, 0, " + number(std::sqrt(0.5)) + "]"},
                {"bodies.box.force_body", "[" + number(force) + ", 0, 0]"},
                {"bodies.box.torque_body", "[0, 0, " + number(torque) + "]"}});
  step(run, 1000);
  const RigidBody& box = run.body("box");
  // Step n's velocity stage turns the force at the pose the step starts from, turned by
  // φ_n = Σ_{k≤n} k α dt² = α dt² n(n+1)/2 from the start, when the body's x axis was world y: the force
  // points along (−sin φ_n, cos φ_n). The velocity is the exact sum of those kicks (m = 1 kg).
  double vx = 0.0, vy = 0.0;
  const double dt = 1e-3, alpha = torque / inertia;
  for (int n = 0; n < 1000; ++n) {
    const double phi = alpha * dt * dt * n * (n + 1) / 2.0;
    vx -= dt * force * std::sin(phi);
    vy += dt * force * std::cos(phi);
  }
  EXPECT_NEAR(box.angular_velocity.z(), alpha * 1.0, 1e-12 * alpha);
  EXPECT_NEAR(box.velocity.x(), vx, 1e-9 * force);
  EXPECT_NEAR(box.velocity.y(), vy, 1e-9 * force);
  EXPECT_NEAR(box.velocity.z(), 0.0, 1e-12);
}

// A conveyor belt (motion: surface) and a moving platform carry a box at rest up to their speed U at
// μ g (v = μ g t, 1e-9 relative, while slipping; then U to 1e-9), and it ends U²/(2 μ g) behind where it
// sat (to U dt, the split step's first-order position error). The belt stays where it is (bit-exact); the
// platform moves U t (1e-12).
TEST_F(MotionScene, BeltAndPlatformCarryABoxUpToTheirSpeedAtMuG) {
  SceneRun run("conveyor.yaml");
  const double mu = 0.4, belt = 0.5, platform = 0.3, dt = 1e-3;
  const Vec3 belt_start = run.body("belt").position, parcel_start = run.body("parcel").position;
  const Vec3 platform_start = run.body("platform").position, rider_start = run.body("rider").position;
  step(run, 50);
  EXPECT_NEAR(run.body("parcel").velocity.x(), mu * kG * 50 * dt, 1e-9 * belt);
  EXPECT_NEAR(run.body("rider").velocity.x(), mu * kG * 50 * dt, 1e-9 * platform);
  step(run, 950);
  EXPECT_NEAR(run.body("parcel").velocity.x(), belt, 1e-9 * belt);
  EXPECT_NEAR(run.body("rider").velocity.x(), platform, 1e-9 * platform);
  EXPECT_EQ(run.body("belt").position, belt_start);
  EXPECT_NEAR(run.body("platform").position.x() - platform_start.x(), platform * 1.0, 1e-12);
  // Slip: on the belt the parcel lags the surface by U²/(2 μ g); on the platform the rider lags it.
  const double parcel_slip = belt * 1.0 - (run.body("parcel").position.x() - parcel_start.x());
  const double rider_slip = platform * 1.0 - (run.body("rider").position.x() - rider_start.x());
  EXPECT_NEAR(parcel_slip, belt * belt / (2.0 * mu * kG), belt * dt);
  EXPECT_NEAR(rider_slip, platform * platform / (2.0 * mu * kG), platform * dt);
  EXPECT_NEAR(run.body("parcel").position.z(), parcel_start.z(), 1e-6);
}

// A turntable at ω = 1 rad/s (moving about its centre): its pose after 2 s is the rotation by 2 rad about
// z (1e-12). The box on it, once friction has brought it up to speed (centripetal ω² r = 0.5 m/s² is far
// below μ g), turns rigidly with it: ω_box = (0, 0, 1) and v = ω × r to 1e-6, staying 0.5 m out (2 cm).
TEST_F(MotionScene, TurntableCarriesABoxRoundWithIt) {
  SceneRun run("conveyor.yaml");
  const Vec3 centre = run.body("turntable").position;
  step(run, 2000);
  const Mat3 expected = Eigen::AngleAxisd(2.0, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_LT((run.body("turntable").rotation - expected).norm(), 1e-12);
  EXPECT_EQ(run.body("turntable").position, centre);
  const RigidBody& box = run.body("spinner");
  Vec3 arm = box.position - centre;
  arm.z() = 0.0;
  EXPECT_NEAR(box.angular_velocity.z(), 1.0, 1e-6);
  EXPECT_NEAR(box.angular_velocity.head<2>().norm(), 0.0, 1e-6);
  // The velocity is the turntable's at the pose the step started from, before the box moved by dt v.
  EXPECT_LT((box.velocity - Vec3::UnitZ().cross(arm - 1e-3 * box.velocity)).norm(), 1e-6);
  EXPECT_NEAR(arm.norm(), 0.5, 0.02);
}

// A frictionless pusher at U = 0.2 m/s meets the 2 kg crate after 0.5 s and pushes it at U (1e-9). The
// work it does through the contact is m U² (1e-9 relative), of which the crate keeps ½ m U² as kinetic
// energy: the inelastic impact dissipates the other half. The other fixed bodies of the scene are stopped
// so that the pusher's is the only work, and gravity is off so that no resting contact absorbs its kick
// each step. The pusher never sinks into the crate by more than the detector's margin.
TEST_F(MotionScene, PusherDoesTwiceTheKineticEnergyItGivesInWork) {
  SceneRun run("conveyor.yaml", {{"gravity", "[0, 0, 0]"},
                                 {"bodies.belt.velocity", "[0, 0, 0]"},
                                 {"bodies.platform.velocity", "[0, 0, 0]"},
                                 {"bodies.turntable.angular_velocity", "[0, 0, 0]"}});
  const double m = 2.0, u = 0.2;
  double work = 0.0, dissipated = 0.0, deepest = 0.0;
  const BodyIndex pusher = *run.world->find_body("pusher"), crate = *run.world->find_body("crate");
  for (int i = 0; i < 1500; ++i) {
    const StepStatus& status = run.world->step();
    ASSERT_TRUE(status.ok) << status.message;
    for (const Contact& c : run.world->contacts())
      if ((c.a == pusher && c.b == crate) || (c.a == crate && c.b == pusher)) deepest = std::max(deepest, c.depth);
    work += status.prescribed_work;
    dissipated += status.prescribed_work - status.resolve_kinetic_energy_change;
  }
  const RigidBody& box = run.body("crate");
  EXPECT_NEAR(box.velocity.x(), u, 1e-9 * u);
  EXPECT_NEAR(work, m * u * u, 1e-9 * m * u * u);
  EXPECT_NEAR(dissipated, 0.5 * m * u * u, 1e-9 * m * u * u);
  EXPECT_NEAR(kinetic_energy(*run.world), 0.5 * m * u * u, 1e-9 * m * u * u);
  EXPECT_LT(deepest, 1e-3);
}

// Bodies leave and join between steps. The pusher removed at 0.2 s (before it reaches the crate) never
// pushes: the crate is still at rest at 1.5 s (1e-9, the resolver's tolerance on the ball's landing). A ball added above the crate at 0.3 s lands on it
// (the detector is told) and rests on its top (1e-3 m). Handles stay valid across the removal while
// indices shift, and removing the pusher again, by handle or by name, is an error naming it.
TEST_F(MotionScene, BodiesRemovedAndAddedBetweenStepsLeaveAndJoinTheSimulation) {
  const auto scripted = [](SceneRun& run) {
    const BodyHandle pusher = run.world->handle(*run.world->find_body("pusher"));
    const BodyHandle crate = run.world->handle(*run.world->find_body("crate"));
    const BodyIndex crate_before = *run.world->index_of(crate);
    step(run, 200);
    EXPECT_EQ(run.world->remove_body(pusher), 0u);
    EXPECT_FALSE(run.world->index_of(pusher).has_value());
    EXPECT_EQ(*run.world->index_of(crate), crate_before - 1);
    EXPECT_EQ(run.world->bodies()[crate_before - 1].name, "crate");
    EXPECT_THROW(run.world->remove_body(pusher), Error);
    EXPECT_THROW(run.world->remove_body(std::string("pusher")), Error);
    step(run, 100);
    RigidBody ball;
    ball.name = "ball";
    ball.shape = Sphere{0.1};
    ball.mass = 0.5;
    ball.inv_mass = 2.0;
    ball.inertia_body = Mat3::Identity() * (0.4 * 0.5 * 0.01);
    ball.inv_inertia_body = ball.inertia_body.inverse();
    ball.position = Vec3(0.0, 9.0, 0.8);
    run.world->add_body(ball);
    step(run, 1200);
  };
  SceneRun run("conveyor.yaml");
  scripted(run);
  EXPECT_LT(run.body("crate").velocity.norm(), 1e-9);
  EXPECT_NEAR(run.body("crate").position.x(), 0.0, 1e-9);
  EXPECT_NEAR(run.body("ball").position.z(), 0.4 + 0.1, 1e-3);
  EXPECT_LT(run.body("ball").velocity.norm(), 1e-6);
  // Determinism: the same script gives the same bits.
  SceneRun again("conveyor.yaml");
  scripted(again);
  for (std::size_t i = 0; i < run.world->bodies().size(); ++i) {
    EXPECT_EQ(run.world->bodies()[i].position, again.world->bodies()[i].position) << i;
    EXPECT_EQ(run.world->bodies()[i].rotation, again.world->bodies()[i].rotation) << i;
  }
}

// A load on a fixed body, a prescribed motion on a movable one and velocities on a fixed body at rest are
// refused when the body is added, and when a program sets them on a body already in the world, at the
// next step, naming the body.
TEST_F(MotionScene, InconsistentLoadsAndMotionsAreRefusedNamingTheBody) {
  SceneRun run("conveyor.yaml");
  const auto refused = [&](const char* what) {
    try {
      run.world->step();
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      return true;
    }
    return false;
  };
  run.body("parcel").motion = PrescribedMotion::moving;
  EXPECT_TRUE(refused("body 'parcel': a prescribed motion applies to fixed bodies only"));
  run.body("parcel").motion = PrescribedMotion::none;
  run.body("ground").force = Vec3(1, 0, 0);
  EXPECT_TRUE(refused("body 'ground': a fixed body has infinite mass"));
  run.body("ground").force.setZero();
  run.body("ground").velocity = Vec3(1, 0, 0);
  EXPECT_TRUE(refused("body 'ground': a fixed body with velocities needs a prescribed motion"));
  run.body("ground").velocity.setZero();
  EXPECT_FALSE(refused(""));
  RigidBody loaded_wall = run.body("pusher");
  loaded_wall.name = "wall";
  loaded_wall.velocity.setZero();
  loaded_wall.motion = PrescribedMotion::none;
  loaded_wall.torque_body = Vec3(0, 0, 1);
  EXPECT_THROW(run.world->add_body(loaded_wall), Error);
  EXPECT_THROW(run.world->handle(1000), Error);
  EXPECT_THROW(run.world->remove_body(BodyHandle{12345}), Error);
}

}  // namespace
}  // namespace impetus::scenario
