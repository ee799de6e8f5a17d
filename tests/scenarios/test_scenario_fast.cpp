// Fast bodies, end to end through the fcl detector's speculative contacts (detection/fcl/README.md,
// "Fast bodies"): nothing passes through anything at any speed the step allows, a body stops on the
// surface it hits (not short of it), a bounce adds no energy, and a body that only passes close by is
// left alone. Every scene here tunnels with `speculative: false`, which is checked too, so the tests can
// fail.
#include "scenario_support.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace impetus::scenario {
namespace {

// Positions are exact to rounding: the gap the detector measures is closed in one step of x += v dt.
constexpr double kTol = 1e-9;

struct Resolver {
  const char* label;
  std::vector<SceneOverride> overrides;
};

std::vector<Resolver> resolvers() {
  return {{"ledas", {}},
          {"ledas paper", {{"modules.resolver.mode", "paper"}}},
          {"mirtich", {{"modules.resolver", "mirtich"}}}};
}

std::vector<SceneOverride> with(std::vector<SceneOverride> base, const std::vector<SceneOverride>& more) {
  base.insert(base.end(), more.begin(), more.end());
  return base;
}

std::string vec(double x, double y, double z) {
  return "[" + std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z) + "]";
}

// A scene written in the test, built through the real plugins; `dir` holds any mesh it names.
struct TextRun {
  PluginHost host;
  Scene scene;
  std::unique_ptr<World> world;
  TextRun(const std::string& yaml, const std::filesystem::path& dir, const std::vector<SceneOverride>& overrides)
      : scene(load_scene_text(yaml, "fast.yaml", dir, overrides)), world(build_world(scene, host)) {}
  RigidBody& body(const std::string& name) { return world->bodies()[world->find_body(name).value()]; }
};

// bullet_wall.yaml: a 2 cm ball at 10 … 1000 m/s (1 to 100 times its diameter per step) against a
// fixed wall 5 cm thick, face at x = 1. With restitution 0 the ball stops on the face, never beyond it
// at any step, and its kinetic energy never rises.
TEST(FastBodies, BallsStopOnTheFaceOfAThinWallAtAnySpeed) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  for (const Resolver& r : resolvers()) {
    for (const double speed : {10.0, 100.0, 200.0, 1000.0}) {
      SCOPED_TRACE(std::string(r.label) + ", " + std::to_string(speed) + " m/s");
      SceneRun run("bullet_wall.yaml", with(r.overrides, {{"bodies.bullet.velocity", vec(speed, 0, 0)}}));
      const int steps = static_cast<int>(1.0 / (speed * 1e-3)) + 10;
      double energy = kinetic_energy(*run.world);
      std::uint64_t speculative = 0;
      for (int i = 0; i < steps; ++i) {
        const StepStatus& status = run.world->step();
        ASSERT_TRUE(status.ok) << status.message;
        speculative += status.detector.speculative_pairs;
        ASSERT_LE(run.body("bullet").position.x() + 0.01, 1.0 + kTol) << "step " << i;
        const double now = kinetic_energy(*run.world);
        ASSERT_LE(now, energy * (1 + 1e-12)) << "step " << i;
        energy = now;
      }
      EXPECT_NEAR(run.body("bullet").position.x(), 0.99, kTol);
      EXPECT_NEAR(run.body("bullet").velocity.norm(), 0.0, kTol);
      // Even 10 m/s moves the ball its own radius per step, more than half of it: every speed here is fast.
      EXPECT_GT(speculative, 0u);
    }
  }
}

// The same wall with the look-ahead off: at 200 m/s the ball is never seen touching it and flies through
// (what the issue reported). This is the failure the other tests rule out.
TEST(FastBodies, WithoutSpeculativeContactsTheBallPassesThrough) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"});
  SceneRun run("bullet_wall.yaml", {{"modules.detector.speculative", "false"}});
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(run.world->step().ok);
  EXPECT_GT(run.body("bullet").position.x(), 1.05);
  EXPECT_NEAR(run.body("bullet").velocity.x(), 200.0, kTol);
}

// A 10 × 5 × 5 cm brick at 1000 m/s (10 brick lengths per step) face on against the same wall: it
// stops flat on the face, without turning.
TEST(FastBodies, ABrickAtAThousandMetresPerSecondStopsOnTheFace) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  for (const Resolver& r : resolvers()) {
    SCOPED_TRACE(r.label);
    SceneRun run("bullet_wall.yaml", with(r.overrides, {{"bodies.bullet.shape", "{box: {size: [0.1, 0.05, 0.05]}}"},
                                                         {"bodies.bullet.velocity", vec(1000, 0, 0)}}));
    // The sequential sweep stops once no corner approaches faster than its tolerance (1e-6 m/s): over
    // ten steps that leaves at most 1e-8 m of drift into the face.
    const bool sequential = std::string(r.label) == "mirtich";
    const double v_tol = sequential ? 1e-6 : kTol, x_tol = sequential ? 1e-8 : kTol;
    for (int i = 0; i < 10; ++i) {
      const StepStatus& status = run.world->step();
      ASSERT_TRUE(status.ok) << status.message;
      ASSERT_LE(run.body("bullet").position.x() + 0.05, 1.0 + x_tol) << "step " << i;
    }
    EXPECT_NEAR(run.body("bullet").position.x(), 0.95, x_tol);
    EXPECT_NEAR(run.body("bullet").velocity.norm(), 0.0, v_tol);
    EXPECT_NEAR(run.body("bullet").angular_velocity.norm(), 0.0, 100 * v_tol);  // 1 m/s ≈ 40 rad/s at a corner
  }
}

// A bounce off the wall (e = 0.5) at 500 m/s leaves at e times the approach speed and never gains
// energy; the ball turns back at most one step's travel early (resting.hpp, "Gaps") and never beyond
// the face.
TEST(FastBodies, ABounceAtSpeedKeepsTheCoefficientAndAddsNoEnergy) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  for (const Resolver& r : resolvers()) {
    SCOPED_TRACE(r.label);
    SceneRun run("bullet_wall.yaml", with(r.overrides, {{"bodies.bullet.velocity", vec(500, 0, 0)},
                                                         {"bodies.bullet.restitution", "0.5"}}));
    double nearest = 1.0;
    for (int i = 0; i < 8; ++i) {
      ASSERT_TRUE(run.world->step().ok);
      const double face_gap = 1.0 - (run.body("bullet").position.x() + 0.01);
      ASSERT_GE(face_gap, -kTol) << "step " << i;
      nearest = std::min(nearest, face_gap);
    }
    EXPECT_NEAR(run.body("bullet").velocity.x(), -250.0, 1e-9 * 500);
    EXPECT_LT(nearest, 500 * 1e-3);
  }
}

// A 10 cm ball dropped at 500 m/s onto the ground plane from 1 m (5 m per step): it lands on the plane
// (restitution 0) and stays there.
TEST(FastBodies, ABallAtFiveHundredMetresPerSecondLandsOnThePlane) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  const std::string yaml = R"(
dt: 0.001
gravity: [0, 0, -9.81]
modules: {integrator: momentum, detector: {plugin: fcl, margin: 1.0e-4}, resolver: ledas}
bodies:
  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1], offset: 0}}}
  - {name: ball, shape: {sphere: {radius: 0.1}}, mass: 1, position: [0, 0, 1.1], velocity: [0, 0, -500], restitution: 0}
)";
  for (const Resolver& r : resolvers()) {
    SCOPED_TRACE(r.label);
    TextRun run(yaml, ".", r.overrides);
    for (int i = 0; i < 20; ++i) {
      ASSERT_TRUE(run.world->step().ok);
      ASSERT_GE(run.body("ball").position.z(), 0.1 - 1e-6) << "step " << i;  // gravity over one step: 1e-5
    }
    EXPECT_NEAR(run.body("ball").position.z(), 0.1, 1e-4);
    EXPECT_NEAR(run.body("ball").velocity.z(), 0.0, 0.02);  // one step of gravity
  }
}

// A closed mesh plate 1 cm thick (an OBJ, placed by its centre of mass so that its top face is at z = 0),
// as a triangle mesh and as a convex hull, and a 2 cm ball at 300 m/s (30 cm per step): the ball stops
// on the plate's top face.
TEST(FastBodies, ABallStopsOnAThinMeshPlateAsTrianglesOrHull) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("impetus_fast_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ofstream obj(dir / "plate.obj");
    obj << "v -1 -1 -0.01\nv 1 -1 -0.01\nv 1 1 -0.01\nv -1 1 -0.01\n"
           "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
           "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
           "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
  }
  const std::string yaml = R"(
dt: 0.001
gravity: [0, 0, 0]
modules: {integrator: momentum, detector: {plugin: fcl, margin: 1.0e-4}, resolver: ledas}
bodies:
  - {name: plate, fixed: true, shape: {mesh: {file: plate.obj, collision: triangles}}, position: [0, 0, -0.005]}
  - {name: ball, shape: {sphere: {radius: 0.02}}, mass: 0.1, position: [0.1, 0.2, 1.02], velocity: [0, 0, -300], restitution: 0}
)";
  for (const char* collision : {"triangles", "convex"}) {
    for (const bool speculative : {true, false}) {
      for (const Resolver& r : resolvers()) {
        // On the triangle mesh the ball also has a speculative contact with the neighbouring triangle's
        // edge, 15 mm further and tilted; the paper's rounds make every contact that would close an
        // equality, and leave the ball 1 mm short with 2.8 m/s sideways (resolution/ledas/README.md,
        // "Gap contacts").
        if (std::string(r.label) == "ledas paper" && std::string(collision) == "triangles") continue;
        SCOPED_TRACE(std::string(r.label) + ", " + collision + (speculative ? "" : ", speculative: false"));
        TextRun run(yaml, dir,
                    with(r.overrides, {{"modules.detector.speculative", speculative ? "true" : "false"},
                                       {"bodies.plate.shape.mesh.collision", collision}}));
        for (int i = 0; i < 10; ++i) ASSERT_TRUE(run.world->step().ok);
        if (speculative) {
          EXPECT_NEAR(run.body("ball").position.z(), 0.02, kTol);
          EXPECT_NEAR(run.body("ball").velocity.norm(), 0.0, kTol);
        } else {
          EXPECT_LT(run.body("ball").position.z(), -0.01);  // through the plate
        }
      }
    }
  }
  std::filesystem::remove_all(dir);
}

// A convex hull as the fast body: an icosphere 1 cm in radius (assets/meshes/icosphere_2.obj at scale
// 0.01) at 500 m/s against the 5 cm wall stops with its foremost vertex on the face.
TEST(FastBodies, AConvexHullStopsOnTheFaceOfAThinWall) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  for (const Resolver& r : resolvers()) {
    SCOPED_TRACE(r.label);
    for (const bool speculative : {true, false}) {
      SceneRun run("bullet_wall.yaml",
                   with(r.overrides, {{"bodies.bullet.shape", "{mesh: {file: ../meshes/icosphere_2.obj, scale: 0.01}}"},
                                      {"bodies.bullet.velocity", vec(500, 0, 0)},
                                      {"modules.detector.speculative", speculative ? "true" : "false"}}));
      const RigidBody& bullet = run.body("bullet");
      double front = 0.0;  // the hull's farthest point along +x from its centre of mass
      for (const Vec3& v : std::get<MeshShape>(bullet.shape).collision_mesh()->vertices)
        front = std::max(front, (bullet.rotation * v).x());
      ASSERT_GT(front, 0.009);
      for (int i = 0; i < 6; ++i) ASSERT_TRUE(run.world->step().ok);
      if (speculative) {
        EXPECT_NEAR(run.body("bullet").position.x() + front, 1.0, kTol);
        EXPECT_NEAR(run.body("bullet").velocity.norm(), 0.0, kTol);
      } else {
        EXPECT_GT(run.body("bullet").position.x(), 1.05);
      }
    }
  }
}

// A plank 1 m × 2 cm × 2 cm (square, so the spin axis is not the unstable middle one) spinning at
// 200 rad/s about its centre (its tips at 100 m/s; 0.2 rad per step), 0.4 m from a fixed post 2 cm
// square: the post's centre stays on the side of the plank it started on while it is alongside it, and
// the contacts never add kinetic energy.
TEST(FastBodies, ASpinningPlankDoesNotPassThroughAPost) {
  IMPETUS_REQUIRE_PLUGINS({"integrator", "splitting"}, {"detector", "fcl"}, {"resolver", "ledas"},
                          {"resolver", "mirtich"});
  // The splitting integrator: the plank's moments are 1250:1, and after the hit it spins at 52 rad/s
  // with a slight tumble, which `momentum`'s explicit turn amplifies (integrators/momentum/README.md).
  const std::string yaml = R"(
dt: 0.001
gravity: [0, 0, 0]
modules: {integrator: splitting, detector: {plugin: fcl, margin: 1.0e-4}, resolver: ledas}
bodies:
  - {name: post, fixed: true, shape: {box: {size: [0.02, 0.02, 1]}}, position: [0.4, 0, 0]}
  - name: plank
    shape: {box: {size: [1, 0.02, 0.02]}}
    mass: 1
    orientation: [0.9689124217106447, 0, 0, -0.24740395925452294]   # -0.5 rad about z
    angular_velocity: [0, 0, 200]
    restitution: 0
)";
  for (const bool speculative : {true, false}) {
    for (const Resolver& r : resolvers()) {
      SCOPED_TRACE(std::string(r.label) + (speculative ? "" : ", speculative: false"));
      TextRun run(yaml, ".", with(r.overrides, {{"modules.detector.speculative", speculative ? "true" : "false"}}));
      // Where the post's centre is seen from the plank, in the plane of the spin (world xy): along the
      // plank's long axis, and across it (signed). Across is unaffected by the plank rolling about its
      // long axis, as `mirtich` leaves it doing.
      const Vec3 post(0.4, 0, 0);
      const auto seen = [&] {
        const RigidBody& plank = run.body("plank");
        const Vec3 u = plank.rotation.col(0), d = post - plank.position;
        return std::pair<double, double>{u.dot(d), u.cross(d).z()};
      };
      const double side = seen().second > 0 ? 1.0 : -1.0;
      ASSERT_GT(std::abs(seen().second), 0.1);
      bool crossed = false;
      for (int i = 0; i < 40; ++i) {
        const StepStatus& status = run.world->step();
        ASSERT_TRUE(status.ok) << status.message;
        // The contacts never add energy, to rounding (the resolve stage's change; the integration is the
        // integrator's own business).
        if (speculative) {
          ASSERT_LE(status.resolve_kinetic_energy_change, 1e-9 * kinetic_energy(*run.world)) << "step " << i;
        }
        // Alongside the plank they are apart while the post's centre is at least the plank's half
        // thickness plus the post's half width (face on) from the plank's axis; 2 mm is allowed.
        const auto [along, across] = seen();
        if (std::abs(along) < 0.5 - 0.02 && side * across < 0.02 - 2e-3) crossed = true;
      }
      EXPECT_EQ(crossed, !speculative);
    }
  }
}

// Bullets 1 cm in radius past the top edge of a thin fixed plate (x from 0.99 to 1.01, top at z = 0) at
// 500 m/s: one whose path clears the edge by 2 mm flies on untouched (its closest point is ahead of it,
// but it never reaches it; a look-ahead along the closest normal alone would stop it there); one whose
// centre passes 2 mm below the edge stops on the plate's face.
TEST(FastBodies, ABulletGrazingAnEdgeFliesOnAndOneClippingItStops) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  const std::string yaml = R"(
dt: 0.001
gravity: [0, 0, 0]
modules: {integrator: momentum, detector: {plugin: fcl, margin: 1.0e-4}, resolver: ledas}
bodies:
  - {name: plate, fixed: true, shape: {box: {size: [0.02, 1, 0.5]}}, position: [1, 0, -0.25]}
  - {name: bullet, shape: {sphere: {radius: 0.01}}, mass: 0.01, position: [0.3, 0, 0.012], velocity: [500, 0, 0], restitution: 0}
)";
  for (const Resolver& r : resolvers()) {
    SCOPED_TRACE(r.label);
    TextRun clear(yaml, ".", r.overrides);
    for (int i = 0; i < 6; ++i) ASSERT_TRUE(clear.world->step().ok);
    EXPECT_EQ(clear.body("bullet").velocity, Vec3(500, 0, 0));
    EXPECT_GT(clear.body("bullet").position.x(), 2.0);

    TextRun clip(yaml, ".", with(r.overrides, {{"bodies.bullet.position", "[0.3, 0, -0.002]"}}));
    for (int i = 0; i < 6; ++i) {
      ASSERT_TRUE(clip.world->step().ok);
      ASSERT_LE(clip.body("bullet").position.x(), 0.98 + kTol) << "step " << i;
    }
    EXPECT_NEAR(clip.body("bullet").position.x(), 0.98, kTol);
    EXPECT_NEAR(clip.body("bullet").velocity.norm(), 0.0, kTol);
  }
}

}  // namespace
}  // namespace impetus::scenario
