// Meshes in scenes: the body frame at the center of mass (position places it), mass from density or
// given, inertia from Mirtich's method, collision chosen by convexity unless the scene says, one
// import per (file, scale), errors naming scene line and column and the mesh file and defect,
// warnings located likewise; and the bundled meshes_drop.yaml run with both resolvers.
#include "asset_test_support.hpp"

#include "impetus/assets/mesh_body.hpp"
#include "impetus/core/error.hpp"
#include "impetus/engine/metrics.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/plugins/host.hpp"

#include <cstdio>
#include <filesystem>

namespace impetus::test {
namespace {

const std::string kMeshDir = std::string(IMPETUS_SOURCE_DIR) + "/assets/meshes";

Scene load(const std::string& yaml) { return load_scene_text(yaml, "scene.yaml", kMeshDir); }

std::string load_error(const std::string& yaml) {
  try {
    load(yaml);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "the scene loaded";
  return {};
}

const MeshShape& mesh_of(const RigidBody& body) { return std::get<MeshShape>(body.shape); }

TEST(MeshScene, BodyFrameIsAtTheCenterOfMass) {
  const Scene scene = load(R"(bodies:
  - name: bracket
    shape: {mesh: {file: l_bracket.obj}}
    density: 2700
    position: [1, 2, 3]
)");
  const RigidBody& body = scene.bodies.at(0);
  const assets::MeshBody reference = assets::load_mesh_body(mesh_path("l_bracket.obj"));
  EXPECT_EQ(body.position, Vec3(1, 2, 3));
  EXPECT_DOUBLE_EQ(body.mass, 2700.0 * reference.unit.volume);
  EXPECT_LT(relative_error(body.inertia_body, 2700.0 * reference.unit.inertia), 1e-15);
  EXPECT_LT(relative_error(body.inv_inertia_body, body.inertia_body.inverse()), 1e-12);
  const MeshShape& mesh = mesh_of(body);
  ASSERT_TRUE(mesh.mesh && mesh.hull);
  EXPECT_LT(assets::polyhedral_mass_properties(*mesh.mesh).center_of_mass.norm(), 1e-15);
  EXPECT_EQ(mesh.collision, MeshCollision::triangles);  // not convex, and the scene did not say
  EXPECT_EQ(mesh.collision_mesh(), mesh.mesh.get());
}

TEST(MeshScene, ConvexMeshCollidesAsItsHullAndTheSceneMayOverride) {
  const Scene scene = load(R"(bodies:
  - {name: a, shape: {mesh: {file: cube.stl}}, mass: 3}
  - {name: b, shape: {mesh: {file: l_bracket.obj, collision: convex}}, mass: 1}
  - {name: c, shape: {mesh: {file: cube.obj, collision: triangles}}, mass: 1}
)");
  EXPECT_EQ(mesh_of(scene.bodies[0]).collision, MeshCollision::convex);
  EXPECT_EQ(mesh_of(scene.bodies[0]).collision_mesh(), mesh_of(scene.bodies[0]).hull.get());
  EXPECT_DOUBLE_EQ(scene.bodies[0].mass, 3.0);
  EXPECT_LT(relative_error(scene.bodies[0].inertia_body, Mat3::Identity() * 3.0 / 6.0), 1e-15);
  EXPECT_EQ(mesh_of(scene.bodies[1]).collision, MeshCollision::convex);
  EXPECT_EQ(mesh_of(scene.bodies[1]).collision_mesh(), mesh_of(scene.bodies[1]).hull.get());
  EXPECT_EQ(mesh_of(scene.bodies[2]).collision, MeshCollision::triangles);
}

// Bodies naming the same file and scale share one import (the same geometry object), however the
// path is written; another scale is another import.
TEST(MeshScene, OneImportPerFileAndScale) {
  const Scene scene = load(R"(bodies:
  - {name: a, shape: {mesh: {file: cube.obj}}, mass: 1}
  - {name: b, shape: {mesh: {file: ./cube.obj}}, mass: 1}
  - {name: c, shape: {mesh: {file: ../meshes/cube.obj, scale: 2}}, mass: 1}
  - {name: d, shape: {mesh: {file: two_boxes.gltf, part: right}}, mass: 1}
)");
  EXPECT_EQ(mesh_of(scene.bodies[0]).mesh, mesh_of(scene.bodies[1]).mesh);
  EXPECT_NE(mesh_of(scene.bodies[0]).mesh, mesh_of(scene.bodies[2]).mesh);
  EXPECT_LT(relative_error(scene.bodies[2].inertia_body, Mat3::Identity() * 4.0 / 6.0), 1e-15);  // m (2a)² / 6
  EXPECT_EQ(mesh_of(scene.bodies[3]).mesh->vertices.size(), 8u);
}

TEST(MeshScene, ErrorsNameTheSceneLocationTheMeshFileAndTheDefect) {
  EXPECT_EQ(load_error("bodies:\n  - {name: p, density: 1, shape: {mesh: {file: broken/open_cube.obj}}}\n")
                .rfind("scene.yaml:2:48: " + kMeshDir + "/broken/open_cube.obj: 4 boundary edges: the mesh is not closed", 0),
            0u);
  EXPECT_EQ(load_error("bodies:\n  - {name: p, density: 1, shape: {mesh: {file: part.obj}}}\n"),
            "scene.yaml:2:48: " + kMeshDir + "/part.obj: no such mesh file");
  EXPECT_EQ(load_error("bodies:\n  - {name: p, density: 1, shape: {mesh: {file: cube.obj, scael: 2}}}\n"),
            "scene.yaml:2:58: unknown key 'scael' in mesh; expected one of: file, scale, collision, part; did you "
            "mean 'scale'?");
  EXPECT_EQ(load_error("bodies:\n  - {name: p, density: 1, shape: {mesh: {file: two_boxes.obj, part: mid}}}\n"),
            "scene.yaml:2:48: " + kMeshDir + "/two_boxes.obj: no part named 'mid'; its parts are 'left', 'right'");
}

// A fixable problem is a warning located in the scene, reported once however many bodies use it.
TEST(MeshScene, WarningsAreLocatedAndReportedOnce) {
  const Scene scene = load(R"(bodies:
  - {name: a, shape: {mesh: {file: broken/inverted_cube.obj}}, mass: 1}
  - {name: b, shape: {mesh: {file: broken/inverted_cube.obj}}, mass: 1}
)");
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_EQ(scene.warnings[0], "scene.yaml:2:36: " + kMeshDir +
                                   "/broken/inverted_cube.obj: the mesh is wound inward (its triangles run clockwise "
                                   "seen from outside); flipped it");
  EXPECT_DOUBLE_EQ(scene.bodies[0].inertia_body(0, 0), 1.0 / 6.0);
}

// meshes_drop.yaml: which mesh collides how, and the shared import.
TEST(MeshScene, BundledDropSceneLoads) {
  const Scene scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/meshes_drop.yaml");
  ASSERT_EQ(scene.bodies.size(), 6u);
  EXPECT_TRUE(scene.warnings.empty());
  EXPECT_EQ(mesh_of(scene.bodies[1]).collision, MeshCollision::triangles);  // bracket
  EXPECT_EQ(mesh_of(scene.bodies[2]).collision, MeshCollision::triangles);  // handle
  EXPECT_EQ(mesh_of(scene.bodies[3]).collision, MeshCollision::convex);     // crate
  EXPECT_EQ(mesh_of(scene.bodies[4]).mesh, mesh_of(scene.bodies[5]).mesh);  // the two cubes
}

// Lowest point of a mesh body in the world (m).
double lowest_point(const RigidBody& body) {
  double z = INFINITY;
  for (const Vec3& v : mesh_of(body).mesh->vertices) z = std::min(z, (body.position + body.rotation * v).z());
  return z;
}

// The drop scene runs 3 s with each resolver: every step succeeds, nothing falls through the ground
// or gains energy, and the bodies end up on it (the cube on the other cube).
TEST(MeshScene, DropSceneRunsWithBothResolvers) {
  for (const char* resolver : {"ledas", "mirtich"}) {
    std::string missing;
    for (const std::string& plugin :
         std::vector<std::string>{"impetus_detector_fcl.so", std::string("impetus_resolver_") + resolver + ".so"})
      if (!std::filesystem::exists(std::filesystem::path(IMPETUS_PLUGIN_DIR) / plugin)) missing += " " + plugin;
    if (!missing.empty()) {
      std::printf("[ scene    ] skipping %s: plugin(s) not built yet:%s\n", resolver, missing.c_str());
      continue;
    }
    PluginHost host;
    const Scene scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/meshes_drop.yaml",
                                   {{"modules.resolver", resolver}});
    std::unique_ptr<World> world = build_world(scene, host);
    const double start = total_energy(measure(*world));
    double max_penetration = 0.0, lowest = INFINITY;
    for (int step = 0; step < 1500; ++step) {
      const StepStatus& status = world->step();
      ASSERT_TRUE(status.ok) << resolver << " step " << step << ": " << status.message;
      max_penetration = std::max(max_penetration, measure(*world).max_penetration);
      for (const RigidBody& b : world->bodies())
        if (!b.fixed) lowest = std::min(lowest, lowest_point(b));
    }
    const WorldMetrics end = measure(*world);
    std::printf("[ scene    ] meshes_drop with %s: max penetration %.3g m, lowest point %.3g m, energy %.4g -> %.4g J\n",
                resolver, max_penetration, lowest, start, total_energy(end));
    EXPECT_GT(lowest, -0.01) << resolver;
    EXPECT_LT(max_penetration, 0.01) << resolver;
    EXPECT_LE(total_energy(end), start * (1 + 1e-6) + 1e-6) << resolver;
    for (const RigidBody& b : world->bodies()) {
      if (b.fixed) continue;
      const double support = b.name == "cube_high" ? 0.2 : 0.0;  // it lands on cube_low
      EXPECT_NEAR(lowest_point(b), support, 0.01) << resolver << ": " << b.name << " has not come to rest";
    }
  }
}

// The T handle spun about its intermediate principal axis (plus a 1 % nudge) in free flight: the
// spin is unstable, so the handle flips over and back (Dzhanibekov effect) while its angular momentum
// stays put. Exercises the whole mesh → body path with the momentum integrator.
TEST(MeshScene, THandleTumblesAboutItsIntermediateAxis) {
  if (!std::filesystem::exists(std::filesystem::path(IMPETUS_PLUGIN_DIR) / "impetus_integrator_momentum.so"))
    GTEST_SKIP() << "integrator momentum not built";
  const Mat3 axes = assets::load_mesh_body(mesh_path("t_handle.obj")).unit.principal_axes;
  const Vec3 spin = 5.0 * axes.col(1) + 0.05 * axes.col(0);
  const std::string yaml = "dt: 0.001\ngravity: [0, 0, 0]\nmodules: {integrator: momentum, detector: none, resolver: none}\n"
                           "bodies:\n  - {name: t, shape: {mesh: {file: t_handle.obj}}, density: 1200, angular_velocity: [" +
                           std::to_string(spin.x()) + ", " + std::to_string(spin.y()) + ", " + std::to_string(spin.z()) + "]}\n";
  PluginHost host;
  std::unique_ptr<World> world = build_world(load(yaml), host);
  const RigidBody& t = world->bodies()[0];
  const Vec3 L0 = t.inertia_world() * t.angular_velocity;
  double lowest = 1.0;  // the intermediate axis's component along its starting direction
  for (int step = 0; step < 8000; ++step) {
    ASSERT_TRUE(world->step().ok);
    lowest = std::min(lowest, (t.rotation * axes.col(1)).dot(axes.col(1)));
  }
  const Vec3 L = t.inertia_world() * t.angular_velocity;
  std::printf("[ scene    ] T handle: intermediate axis reached cos = %.3f of its start; |ΔL|/|L| = %.2g\n", lowest,
              (L - L0).norm() / L0.norm());
  EXPECT_LT(lowest, -0.9);  // it turned over
  EXPECT_LT((L - L0).norm(), 1e-9 * L0.norm());
}

}  // namespace
}  // namespace impetus::test
