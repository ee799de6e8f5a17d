// The peers' translation of friction (benchmarks/peers/accuracy/): each engine given an Impetus scene with
// friction must reproduce the closed forms a Coulomb contact gives, with Impetus's rule for the μ of a pair
// (√(μ_a μ_b), docs/conventions.md, "Friction"), or refuse the scene. A wrong μ, a dropped friction or a
// force bound in place of a coefficient fails these by orders of magnitude more than their tolerances.
#include "peer_world.hpp"

#include "impetus/core/error.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/plugins/host.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace impetus::peers::accuracy {
namespace {

const std::filesystem::path kScenes = std::filesystem::path(IMPETUS_SOURCE_DIR) / "assets" / "scenes";

std::vector<PeerMethod> all_methods() {
  std::vector<PeerMethod> methods;
#ifdef IMPETUS_PEERS_BULLET
  add_bullet_methods(methods);
#endif
#ifdef IMPETUS_PEERS_ODE
  add_ode_methods(methods);
#endif
#ifdef IMPETUS_PEERS_MUJOCO
  add_mujoco_methods(methods);
#endif
  return methods;
}

/// A scene built by Impetus and a peer world made from it, stepped `steps` times; the Impetus bodies then
/// hold the engine's state.
struct PeerRun {
  PluginHost host;
  std::unique_ptr<World> world;
  std::vector<RigidBody> initial;
  PeerScene scene;
  std::string unsupported;

  PeerRun(const std::string& file, const std::vector<SceneOverride>& overrides, const PeerMethod& method) {
    world = build_world(load_scene(kScenes / file, overrides), host);
    initial.assign(world->bodies().begin(), world->bodies().end());
    scene = PeerScene{initial, world->constraints(), {}};
    scene.settings.dt = world->settings().dt;
    scene.settings.gravity = world->settings().gravity;
    unsupported = method.unsupported(scene);
  }

  RigidBody& body(const std::string& name) { return world->bodies()[*world->find_body(name)]; }

  void step(const PeerMethod& method, int steps) {
    std::unique_ptr<PeerWorld> peer = method.make(scene);
    for (int i = 0; i < steps; ++i) peer->step();
    peer->read(world->bodies());
  }
};

const double kG = 9.81;

// A sphere thrown sliding at v0 on the ground (friction_sphere.yaml: r = 0.1 m, v0 = 2 m/s) with the ground's
// μ 0.1 and the ball's 0.4: the contact's μ is √(0.1 · 0.4) = 0.2. While it slides, v = v0 − μ g t; from
// t* = 2 v0 / (7 μ g) = 0.29 s it rolls at 5/7 v0 with no slip. MuJoCo gives a contact the larger μ and
// must refuse the scene.
TEST(PeerTranslation, ASlidingSphereTakesTheGeometricMeanOfTheTwoFrictionsInEveryEngine) {
  const std::vector<SceneOverride> overrides{{"bodies.ground.friction", "0.1"}, {"bodies.ball.friction", "0.4"}};
  const double mu = 0.2, v0 = 2.0, r = 0.1;
  const std::vector<PeerMethod> methods = all_methods();
  if (methods.empty()) GTEST_SKIP() << "no peer engine compiled in";
  for (const PeerMethod& method : methods) {
    SCOPED_TRACE(method.label());
    PeerRun sliding("friction_sphere.yaml", overrides, method);
    if (method.engine == "mujoco") {
      EXPECT_NE(sliding.unsupported.find("different friction"), std::string::npos) << sliding.unsupported;
      continue;
    }
    ASSERT_EQ(sliding.unsupported, "");
    const double dt = sliding.scene.settings.dt;
    sliding.step(method, 100);  // t = 0.1 s, still sliding
    // The one contact's impulse per step is exactly m g dt and the friction μ m g dt: exact to rounding.
    EXPECT_NEAR(sliding.body("ball").velocity.x(), v0 - mu * kG * 100 * dt, 1e-9);
    EXPECT_NEAR(sliding.body("ball").angular_velocity.y(), 2.5 * mu * kG * 100 * dt / r, 1e-8);

    PeerRun rolling("friction_sphere.yaml", overrides, method);
    rolling.step(method, 1000);  // t = 1 s
    const RigidBody& ball = rolling.body("ball");
    EXPECT_NEAR(ball.velocity.x(), 5.0 / 7.0 * v0, 1e-9);
    // Rolling: the contact point (r below the center) does not slip.
    EXPECT_NEAR((ball.velocity + ball.angular_velocity.cross(Vec3(0, 0, -r))).norm(), 0.0, 1e-9);
  }
}

// MuJoCo's contacts are soft by design: its rolling sphere (equal μ, which MuJoCo translates exactly) slips
// slightly, but friction clearly acts: without it the ball would keep 2 m/s, 0.57 m/s above 5/7 v0.
TEST(PeerTranslation, MujocoRollsTheSphereWithinItsSoftContactsSlip) {
  for (const PeerMethod& method : all_methods()) {
    if (method.engine != "mujoco") continue;
    SCOPED_TRACE(method.label());
    PeerRun run("friction_sphere.yaml", {}, method);
    ASSERT_EQ(run.unsupported, "");
    run.step(method, 1000);
    EXPECT_NEAR(run.body("ball").velocity.x(), 5.0 / 7.0 * 2.0, 1e-2);
  }
}

// A unit box on a 30° slope (friction_slope.yaml tilts gravity): with μ = √(0.25 · 1) = 0.5 < tan 30° it
// slides at a = g (sin 30° − μ cos 30°); with μ = 0.7 it sticks. ODE's exact solver (dWorldStep) bounds its
// friction by μ times the normal force (dContactApprox1), so it reproduces both to its CFM's 1e-10.
TEST(PeerTranslation, OdesLcpSlidesAndSticksOnTheSlopeAsCoulombSays) {
  for (const PeerMethod& method : all_methods()) {
    if (method.label() != "ode/worldstep") continue;
    PeerRun slide("friction_slope.yaml", {{"bodies.ground.friction", "0.25"}, {"bodies.box.friction", "1.0"}}, method);
    ASSERT_EQ(slide.unsupported, "");
    slide.step(method, 1000);  // 1 s
    const double a = kG * (0.5 - 0.5 * std::sqrt(3.0) / 2.0);
    EXPECT_NEAR((slide.body("box").velocity - Vec3(a, 0, 0)).norm(), 0.0, 1e-8);

    PeerRun stick("friction_slope.yaml", {{"bodies.ground.friction", "0.7"}, {"bodies.box.friction", "0.7"}}, method);
    stick.step(method, 1000);
    EXPECT_LT(stick.body("box").velocity.norm(), 1e-8);
    return;
  }
  GTEST_SKIP() << "ODE not compiled in";
}

}  // namespace
}  // namespace impetus::peers::accuracy
