// Quickhull: the hull is closed, wound outward, convex, contains every input point, and has the
// volume the geometry says; coplanar and far-away inputs work; flat inputs are refused.
#include "asset_test_support.hpp"

#include "impetus/assets/convex_hull.hpp"
#include "impetus/assets/mesh_body.hpp"
#include "impetus/assets/mesh_validation.hpp"
#include "impetus/core/error.hpp"

#include <random>

namespace impetus::test {
namespace {

using assets::convex_hull;

// Every point is behind (or on) every hull face plane, to `tolerance` (m).
void expect_contains(const TriangleMesh& hull, const std::vector<Vec3>& points, double tolerance) {
  for (const auto& t : hull.triangles) {
    const Vec3 n = (hull.vertices[t[1]] - hull.vertices[t[0]]).cross(hull.vertices[t[2]] - hull.vertices[t[0]]).normalized();
    double worst = -INFINITY;
    for (const Vec3& p : points) worst = std::max(worst, n.dot(p - hull.vertices[t[0]]));
    EXPECT_LE(worst, tolerance);
  }
}

void expect_closed_and_outward(const TriangleMesh& hull) {
  TriangleMesh copy = hull;
  const auto r = assets::validate_mesh(copy);
  EXPECT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.flipped_shells, 0u);
}

// A cube's corners plus points inside and on its faces: 8 hull vertices, volume 1.
TEST(ConvexHull, CubeWithInteriorAndFacePoints) {
  std::vector<Vec3> points = box_mesh(Vec3::Zero(), Vec3::Ones()).vertices;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 200; ++i) points.emplace_back(unit(random), unit(random), unit(random));
  for (int i = 0; i < 50; ++i) points.emplace_back(unit(random), unit(random), 1.0);  // on the top face
  const TriangleMesh hull = convex_hull(points);
  expect_closed_and_outward(hull);
  EXPECT_EQ(hull.vertices.size(), 8u);
  EXPECT_NEAR(assets::signed_volume(hull), 1.0, 1e-14);
  expect_contains(hull, points, 1e-12);
}

// Random points in a ball, a million metres out: closed, convex, every point inside.
TEST(ConvexHull, RandomPointsFarFromTheOrigin) {
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  std::vector<Vec3> points;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 d(normal(random), normal(random), normal(random));
    points.push_back(Vec3(1e6, -2e6, 5e5) + d.normalized() * std::cbrt(std::uniform_real_distribution<double>()(random)));
  }
  const TriangleMesh hull = convex_hull(points);
  expect_closed_and_outward(hull);
  expect_contains(hull, points, 1e-8);
  EXPECT_LT(assets::signed_volume(hull), 4.0 / 3.0 * std::numbers::pi);
  EXPECT_GT(assets::signed_volume(hull), 0.8 * 4.0 / 3.0 * std::numbers::pi);
}

// Convex bundled meshes are their own hulls (same volume); the L bracket's hull is the extruded hull
// of its L profile: (0,0), (0.4,0), (0.4,0.1), (0.1,0.3), (0,0.3), area 0.09, depth 0.2.
TEST(ConvexHull, BundledMeshes) {
  for (const char* name : {"cube.obj", "box.stl", "tetrahedron.glb", "icosphere_3.obj", "cylinder.obj"}) {
    const assets::MeshBody body = assets::load_mesh_body(mesh_path(name));
    ASSERT_TRUE(body.hull) << name;
    expect_closed_and_outward(*body.hull);
    EXPECT_TRUE(body.convex) << name;
    EXPECT_LT(relative_error(assets::signed_volume(*body.hull), body.unit.volume), 1e-12) << name;
  }
  for (const char* name : {"l_bracket.obj", "t_handle.obj", "torus.obj"}) {
    const assets::MeshBody body = assets::load_mesh_body(mesh_path(name));
    ASSERT_TRUE(body.hull) << name;
    expect_closed_and_outward(*body.hull);
    EXPECT_FALSE(body.convex) << name;
    expect_contains(*body.hull, body.mesh->vertices, 1e-12);
  }
  const assets::MeshBody bracket = assets::load_mesh_body(mesh_path("l_bracket.obj"));
  EXPECT_LT(relative_error(assets::signed_volume(*bracket.hull), 0.09 * 0.2), 1e-6);  // float32 vertices
}

TEST(ConvexHull, FlatInputIsRefused) {
  EXPECT_THROW(convex_hull({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0.5, 0.5, 0)}), Error);
  EXPECT_THROW(convex_hull({Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(3, 3, 3)}), Error);
  EXPECT_THROW(convex_hull({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}), Error);
}

}  // namespace
}  // namespace impetus::test
