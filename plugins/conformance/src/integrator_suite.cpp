// The integrator conformance suite: the promises of impetus/modules/integrator.hpp, checked on an
// integrator loaded from its .so. A step is the two phases in order (velocities, then positions), as
// the world calls them with no contacts.
#include "impetus/conformance/conformance.hpp"

#include <algorithm>
#include <cmath>

namespace impetus::conformance {
namespace {

/// A torque-free body with principal moments (1, 2, 3) spun near its intermediate axis, gravity off:
/// the true motion tumbles while L stays fixed in the world.
std::vector<RigidBody> tumbling_body() {
  std::vector<RigidBody> bodies{principal_body(1.0, Vec3(1.0, 2.0, 3.0))};
  bodies[0].angular_velocity = Vec3(0.1, 2.0, 0.1);
  return bodies;
}

StepContext gravity_free(double dt = 1e-3) {
  StepContext ctx;
  ctx.dt = dt;
  ctx.gravity.setZero();
  return ctx;
}

// Law: under constant gravity g alone, v after n steps is v0 + g t exactly (1e-12 relative), and the
// position is within the first-order bound of the parabola, |x_n − (x0 + v0 t + ½ g t²)| ≤ ½ |g| dt t
// (1e-9 relative slack; symplectic Euler attains it, a second-order scheme is far inside), and the error
// does not grow when dt halves: err(dt/2) ≤ ½ err(dt) + 1e-12 (first order or better). t = 1 s.
TEST_P(IntegratorConformance, FreeFallMeetsTheFirstOrderBound) {
  const auto integrator = load_integrator(GetParam());
  const Vec3 x0(1.0, -2.0, 3.0), v0(0.5, -0.3, 4.0), g(0.0, 0.0, -9.81);
  const double t = 1.0;
  double previous = -1.0;
  for (const int steps : {1000, 2000}) {
    std::vector<RigidBody> bodies{principal_body(2.0, Vec3(1.0, 2.0, 3.0))};
    bodies[0].position = x0;
    bodies[0].velocity = v0;
    StepContext ctx;
    ctx.dt = t / steps;
    ctx.gravity = g;
    run(*integrator, bodies, ctx, steps);
    EXPECT_LE((bodies[0].velocity - (v0 + g * t)).norm(), 1e-12 * (v0.norm() + g.norm() * t)) << steps << " steps";
    const double error = (bodies[0].position - (x0 + v0 * t + 0.5 * g * t * t)).norm();
    EXPECT_LE(error, 0.5 * g.norm() * ctx.dt * t * (1 + 1e-9)) << steps << " steps";
    if (previous >= 0.0) {
      EXPECT_LE(error, 0.5 * previous + 1e-12) << "halving dt must at least halve the error";
    }
    previous = error;
  }
}

// Law: torque-free rotation about the major principal axis is steady: ω constant and R(t) = Q(ω t) R0.
// After 10 s at dt = 1e-3: ω to 1e-9 rad/s (|ω| = 2.5), the rotation angle to 1e-9 rad.
TEST_P(IntegratorConformance, SteadySpinAboutAPrincipalAxis) {
  const auto integrator = load_integrator(GetParam());
  std::vector<RigidBody> bodies{principal_body(1.0, Vec3(1.0, 2.0, 3.0))};
  const Mat3 r0 = rotation_from_vector(Vec3(0.3, -0.2, 0.5));
  const Vec3 omega0 = 2.5 * r0.col(2);
  bodies[0].rotation = r0;
  bodies[0].angular_velocity = omega0;
  const int steps = 10000;
  const StepContext ctx = gravity_free();
  run(*integrator, bodies, ctx, steps);
  EXPECT_LE((bodies[0].angular_velocity - omega0).norm(), 1e-9);
  EXPECT_LT(angle_between(rotation_from_vector(omega0 * steps * ctx.dt) * r0, bodies[0].rotation), 1e-9);
}

// Law: R stays a rotation. A body tumbling for 10⁴ steps (dt = 1e-3): ‖RᵀR − I‖ < 1e-12 and det R = 1
// (1e-12) at the end.
TEST_P(IntegratorConformance, OrientationStaysOrthonormal) {
  const auto integrator = load_integrator(GetParam());
  std::vector<RigidBody> bodies = tumbling_body();
  bodies[0].rotation = rotation_from_vector(Vec3(0.7, -0.4, 0.2));
  run(*integrator, bodies, gravity_free(), 10000);
  EXPECT_LT(orthonormality_error(bodies[0].rotation), 1e-12);
  EXPECT_NEAR(bodies[0].rotation.determinant(), 1.0, 1e-12);
}

// Law (claim `angular_momentum`): without torque the world-frame angular momentum L = J_world ω is
// conserved. The tumbling body over 10 s at dt = 1e-3: max |L − L0| / |L0| < 1e-9 at every step.
TEST_P(IntegratorConformance, ConservesAngularMomentumWhenClaimed) {
  if (!GetParam().claims_capability("angular_momentum"))
    GTEST_SKIP() << GetParam().label << " does not claim to conserve angular momentum";
  const auto integrator = load_integrator(GetParam());
  std::vector<RigidBody> bodies = tumbling_body();
  const Vec3 l0 = bodies[0].inertia_world() * bodies[0].angular_velocity;
  double drift = 0.0;
  const StepContext ctx = gravity_free();
  for (int i = 0; i < 10000; ++i) {
    run(*integrator, bodies, ctx, 1);
    drift = std::max(drift, (bodies[0].inertia_world() * bodies[0].angular_velocity - l0).norm() / l0.norm());
  }
  EXPECT_LT(drift, 1e-9);
}

// Law: a fixed body has infinite mass and inertia: no load moves it (bit-exact), and it is not counted.
// Counters: `bodies` counts each movable body once per step (100 steps, one movable body: 100).
TEST_P(IntegratorConformance, LeavesFixedBodiesAloneAndCountsTheMovableOnes) {
  const auto integrator = load_integrator(GetParam());
  std::vector<RigidBody> bodies{principal_body(1.0, Vec3::Ones()), principal_body(1.0, Vec3::Ones())};
  RigidBody& wall = bodies[1];
  make_fixed(wall);
  wall.position = Vec3(1.0, 2.0, 3.0);
  wall.rotation = rotation_from_vector(Vec3(0.1, 0.2, 0.3));
  wall.force = Vec3(10.0, 0.0, 0.0);
  wall.torque = Vec3(0.0, 5.0, 0.0);
  const RigidBody before = wall;
  const IntegratorCounters counters = run(*integrator, bodies, StepContext{}, 100);
  EXPECT_EQ(wall.position, before.position);
  EXPECT_EQ(wall.rotation, before.rotation);
  EXPECT_EQ(wall.velocity, Vec3::Zero());
  EXPECT_EQ(wall.angular_velocity, Vec3::Zero());
  EXPECT_EQ(counters.bodies, 100u);
}

// Law: a body-frame load acts as its world-frame image R F_body, R τ_body at the step's starting pose
// (RigidBody::applied_force, applied_torque): one step with either gives the same state to rounding.
TEST_P(IntegratorConformance, AppliesBodyFrameLoadsAsTheirWorldFrameImages) {
  const auto integrator = load_integrator(GetParam());
  std::vector<RigidBody> in_body = tumbling_body();
  in_body[0].rotation = rotation_from_vector(Vec3(0.4, -0.7, 1.1));
  in_body[0].force_body = Vec3(3.0, -1.0, 0.5);
  in_body[0].torque_body = Vec3(0.2, 0.4, -0.3);
  std::vector<RigidBody> in_world = in_body;
  in_world[0].force = in_body[0].rotation * in_body[0].force_body;
  in_world[0].torque = in_body[0].rotation * in_body[0].torque_body;
  in_world[0].force_body.setZero();
  in_world[0].torque_body.setZero();
  run(*integrator, in_body, StepContext{}, 1);
  run(*integrator, in_world, StepContext{}, 1);
  // Rounding of one rotation product: 1e-14 relative to velocities of order 1.
  EXPECT_LT((in_body[0].velocity - in_world[0].velocity).norm(), 1e-14);
  EXPECT_LT((in_body[0].angular_velocity - in_world[0].angular_velocity).norm(), 1e-14);
  EXPECT_LT((in_body[0].position - in_world[0].position).norm(), 1e-14);
  // And the load did act: the step differs from one without it by dt F/m at least.
  std::vector<RigidBody> unloaded = tumbling_body();
  unloaded[0].rotation = in_body[0].rotation;
  run(*integrator, unloaded, StepContext{}, 1);
  EXPECT_GT((in_body[0].velocity - unloaded[0].velocity).norm(), 1e-4);
}

// Refusal: an option the integrator does not read is refused when it is loaded, with a message naming it.
TEST_P(IntegratorConformance, RefusesAnUnknownOption) {
  const std::string message = unknown_option_message(GetParam(), ModuleKind::integrator, "conformance_no_such_option");
  EXPECT_NE(message.find("has no option 'conformance_no_such_option'"), std::string::npos) << message;
}

// Determinism: two modules loaded separately advance the same tumbling, falling body to bit-identical
// states after 1000 steps.
TEST_P(IntegratorConformance, TwoRunsAreBitIdentical) {
  const auto first = load_integrator(GetParam());
  const auto second = load_integrator(GetParam());
  std::vector<RigidBody> a = tumbling_body();
  a[0].velocity = Vec3(0.3, -0.1, 2.0);
  a[0].force = Vec3(0.5, 0.2, 0.0);
  a[0].torque = Vec3(0.0, 0.1, -0.2);
  std::vector<RigidBody> b = a;
  run(*first, a, StepContext{}, 1000);
  run(*second, b, StepContext{}, 1000);
  EXPECT_EQ(a[0].position, b[0].position);
  EXPECT_EQ(a[0].rotation, b[0].rotation);
  EXPECT_EQ(a[0].velocity, b[0].velocity);
  EXPECT_EQ(a[0].angular_velocity, b[0].angular_velocity);
}

}  // namespace
}  // namespace impetus::conformance
