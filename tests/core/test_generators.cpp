// The benchmark generators (docs/conventions.md, "Benchmark scenes"): body counts and contact counts of
// the paper's table, and the exact geometry of every contact.
#include "impetus/engine/generators.hpp"

#include "scene_test_support.hpp"

#include <cmath>
#include <numbers>

namespace impetus {
namespace {

constexpr double kTolerance = 1e-12;  // m, on every distance (coordinates are O(10) m)

struct Counts {
  int spheres = 0;
  int sphere_contacts = 0;  // pairs closer than 2r
  int plane_contacts = 0;   // spheres reaching into a plane
};

// Counts overlapping pairs and checks that every one overlaps by exactly the specified amount.
Counts count_contacts(const std::vector<RigidBody>& bodies, double r, double overlap) {
  Counts c;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const auto* si = std::get_if<Sphere>(&bodies[i].shape);
    if (!si) continue;
    ++c.spheres;
    for (std::size_t j = i + 1; j < bodies.size(); ++j) {
      if (const auto* sj = std::get_if<Sphere>(&bodies[j].shape)) {
        const double d = (bodies[i].position - bodies[j].position).norm();
        if (d < si->radius + sj->radius) {
          ++c.sphere_contacts;
          EXPECT_NEAR(d, 2.0 * r * (1.0 - overlap), kTolerance) << bodies[i].name << " – " << bodies[j].name;
        }
      } else if (const auto* plane = std::get_if<Plane>(&bodies[j].shape)) {
        // Signed distance of the center from the plane n·p = offset (positive outside the solid).
        const double h = plane->normal.dot(bodies[i].position) - plane->offset;
        if (h < si->radius) {
          ++c.plane_contacts;
          EXPECT_NEAR(h, r * (1.0 - overlap), kTolerance) << bodies[i].name << " – " << bodies[j].name;
        }
      }
    }
  }
  return c;
}

TEST(Generators, PyramidHasThePapersBodyAndContactCounts) {
  // K rows: K(K+1)/2 spheres, 3K(K−1)/2 sphere–sphere contacts (the paper's 9, 18, 135, 570), K ground contacts.
  const int rows[] = {3, 4, 10, 20};
  const int spheres[] = {6, 10, 55, 210};
  const int contacts[] = {9, 18, 135, 570};
  for (int k = 0; k < 4; ++k) {
    PyramidParams p;
    p.rows = rows[k];
    const std::vector<RigidBody> bodies = make_pyramid(p);
    ASSERT_EQ(bodies.size(), static_cast<std::size_t>(spheres[k] + 1)) << "rows " << rows[k];
    const Counts c = count_contacts(bodies, p.radius, p.overlap);
    EXPECT_EQ(c.spheres, spheres[k]);
    EXPECT_EQ(c.sphere_contacts, contacts[k]) << "rows " << rows[k];
    EXPECT_EQ(c.plane_contacts, rows[k]);
    EXPECT_EQ(bodies.back().name, "ground");
    EXPECT_TRUE(bodies.back().fixed);
  }
}

TEST(Generators, PyramidSpheresRestOnTheirTwoSupporters) {
  PyramidParams p;
  p.rows = 4;
  p.radius = 0.3;
  p.overlap = 1e-3;
  const std::vector<RigidBody> bodies = make_pyramid(p);
  // Row 1, sphere 0 sits on row 0 spheres 0 and 1, 2r(1 − overlap) from each, and in the x–z plane.
  const auto at = [&](int row, int i) -> const RigidBody& {
    int index = 0;
    for (int j = 0; j < row; ++j) index += p.rows - j;
    return bodies.at(static_cast<std::size_t>(index + i));
  };
  EXPECT_EQ(at(1, 0).name, "pyramid_r1_0");
  EXPECT_EQ(at(3, 0).name, "pyramid_r3_0");
  const double s = 2 * p.radius * (1 - p.overlap);
  EXPECT_NEAR((at(1, 0).position - at(0, 0).position).norm(), s, kTolerance);
  EXPECT_NEAR((at(1, 0).position - at(0, 1).position).norm(), s, kTolerance);
  EXPECT_NEAR(at(0, 0).position.z(), p.radius * (1 - p.overlap), kTolerance);
  EXPECT_NEAR(at(3, 0).position.x(), 1.5 * s, kTolerance);
  EXPECT_NEAR(at(3, 0).position.z() - at(0, 0).position.z(), 3 * std::sqrt(3.0) / 2 * s, kTolerance);
  for (const RigidBody& b : bodies) EXPECT_EQ(b.position.y(), 0.0) << b.name;
}

TEST(Generators, PyramidSpheresGetMassVelocityAndRestitution) {
  PyramidParams p;
  p.rows = 2;
  p.mass = 2.0;
  p.restitution = 0.5;
  const std::vector<RigidBody> bodies = make_pyramid(p);
  for (std::size_t i = 0; i + 1 < bodies.size(); ++i) {
    EXPECT_EQ(bodies[i].mass, 2.0);
    EXPECT_NEAR(bodies[i].inertia_body(0, 0), 0.4 * 2.0 * 0.25, 1e-12);  // 2/5 m r²
    EXPECT_EQ(bodies[i].velocity, Vec3(0, 0, -1));
    EXPECT_EQ(bodies[i].material.restitution, 0.5);
  }
  p.ground = false;
  EXPECT_EQ(make_pyramid(p).size(), 3u);
}

TEST(Generators, LineHasNContactsAndTheWallAfterTheLastSphere) {
  for (int n : {1, 10, 100}) {
    LineParams p;
    p.count = n;
    const std::vector<RigidBody> bodies = make_line(p);
    ASSERT_EQ(bodies.size(), static_cast<std::size_t>(n + 1));
    const Counts c = count_contacts(bodies, p.radius, p.overlap);
    EXPECT_EQ(c.sphere_contacts, n - 1);
    EXPECT_EQ(c.plane_contacts, 1);  // only the last sphere touches the wall
    const RigidBody& wall = bodies.back();
    EXPECT_EQ(wall.name, "wall");
    EXPECT_TRUE(wall.fixed);
    const Plane& plane = std::get<Plane>(wall.shape);
    EXPECT_EQ(plane.normal, Vec3(-1, 0, 0));
    const double x_last = bodies[n - 1].position.x();
    EXPECT_NEAR(-plane.offset, x_last + p.radius * (1 - p.overlap), kTolerance);
    EXPECT_EQ(bodies[0].velocity, Vec3(1, 0, 0));
    for (int i = 1; i < n; ++i) EXPECT_EQ(bodies[i].velocity, Vec3::Zero()) << bodies[i].name;
    EXPECT_EQ(bodies[n - 1].name, "line_" + std::to_string(n - 1));
  }
}

TEST(Generators, OutOfRangeParametersNameTheField) {
  PyramidParams p;
  p.rows = 0;
  try {
    make_pyramid(p);
    FAIL() << "expected a GeneratorError";
  } catch (const GeneratorError& e) {
    EXPECT_EQ(e.field(), "rows");
  }
  LineParams l;
  l.overlap = 1.0;
  EXPECT_THROW(make_line(l), GeneratorError);
  l.overlap = 0.0;
  l.mass = std::nan("");
  EXPECT_THROW(make_line(l), GeneratorError);
}

TEST(Generators, SceneGeneratorsPassTheirParameters) {
  const Scene scene = test::load(R"(generators:
  - line: {count: 5, radius: 0.25, mass: 3, wall: false, velocity: [2, 0, 0], restitution: 1, overlap: 0}
  - pyramid: {rows: 2, radius: 0.1, velocity: [0, 0, 0], ground: true}
)");
  ASSERT_EQ(scene.bodies.size(), 5u + 3u + 1u);
  EXPECT_EQ(scene.bodies[0].name, "line_0");
  EXPECT_EQ(scene.bodies[0].velocity, Vec3(2, 0, 0));
  EXPECT_EQ(scene.bodies[0].mass, 3.0);
  EXPECT_EQ(scene.bodies[0].material.restitution, 1.0);
  EXPECT_NEAR(scene.bodies[4].position.x(), 4 * 0.5, kTolerance);  // touching exactly: overlap 0
  EXPECT_EQ(scene.bodies[5].name, "pyramid_r0_0");
  EXPECT_EQ(scene.bodies[5].velocity, Vec3::Zero());
  EXPECT_EQ(scene.bodies.back().name, "ground");
}

}  // namespace
}  // namespace impetus
