// Every shape pair through the `fcl` detector, in both argument orders: the normal points out of a into
// b ((x_b − x_a)·n > 0, and equals the known direction), and the depth equals a known overlap.
#include "detection_test_support.hpp"

#include "impetus/detection/fcl/analytic.hpp"

#include <functional>
#include <limits>
#include <numbers>
#include <random>

namespace impetus::test {
namespace {

constexpr double kOverlap = 0.01;  // m, every stacked pair below overlaps by this along z
constexpr double kDepthTol = 1e-6; // m: closed forms and face normals are exact; curved pairs are within ~1e-6 m

/// A named shape and the distance from its center to its top (= to its bottom: all are symmetric).
struct Kind {
  const char* name;
  std::function<Shape()> make;
  double half_height;
};

std::vector<Kind> kinds() {
  return {
      {"sphere", [] { return Shape(Sphere{0.5}); }, 0.5},
      {"box", [] { return Shape(Box{Vec3(1.0, 0.8, 1.0)}); }, 0.5},
      {"capsule", [] { return Shape(Capsule{0.3, 0.6}); }, 0.6},
      {"cylinder", [] { return Shape(Cylinder{0.4, 1.0}); }, 0.5},
      {"convex", [] { return Shape(mesh_shape(cube_mesh(0.5), MeshCollision::convex)); }, 0.5},
      {"triangles", [] { return Shape(mesh_shape(cube_mesh(0.5), MeshCollision::triangles)); }, 0.5},
  };
}

/// Checks the contacts of a pair whose known overlap is kOverlap along +z from `lower` to `upper`.
void check_stacked(const std::vector<Contact>& contacts, const std::vector<RigidBody>& bodies, BodyIndex lower,
                   const std::string& label, double depth_tol) {
  ASSERT_FALSE(contacts.empty()) << label;
  for (const Contact& c : contacts) {
    ASSERT_EQ(c.a, 0u) << label;
    ASSERT_EQ(c.b, 1u) << label;
    const Vec3 expected = lower == c.a ? Vec3::UnitZ() : Vec3(-Vec3::UnitZ());
    EXPECT_GT((bodies[c.b].position - bodies[c.a].position).dot(c.normal), 0.0) << label;
    EXPECT_LT((c.normal - expected).norm(), 1e-6) << label << " normal " << c.normal.transpose();
    EXPECT_NEAR(c.depth, kOverlap, depth_tol) << label;
    EXPECT_NEAR(std::abs(c.normal.norm() - 1.0), 0.0, 1e-12) << label;
  }
}

TEST(FclPairs, EveryBoundedPairInBothOrdersHasTheRightNormalAndDepth) {
  for (const Kind& lo : kinds()) {
    for (const Kind& hi : kinds()) {
      const RigidBody lower = make_body("lower", lo.make(), Vec3::Zero());
      const RigidBody upper =
          make_body("upper", hi.make(), Vec3(0.0, 0.0, lo.half_height + hi.half_height - kOverlap));
      const double tol = kDepthTol;
      const std::string label = std::string(lo.name) + " under " + hi.name;
      {
        const std::vector<RigidBody> bodies{lower, upper};
        check_stacked(detect_once(bodies), bodies, 0, label + " (lower is a)", tol);
      }
      {
        const std::vector<RigidBody> bodies{upper, lower};
        check_stacked(detect_once(bodies), bodies, 1, label + " (lower is b)", tol);
      }
    }
  }
}

TEST(FclPairs, EveryShapeOnAPlaneInBothOrders) {
  for (const Kind& k : kinds()) {
    const RigidBody body = make_body("body", k.make(), Vec3(0.1, -0.2, k.half_height - kOverlap));
    for (bool plane_first : {true, false}) {
      const std::vector<RigidBody> bodies = plane_first ? std::vector{ground(), body} : std::vector{body, ground()};
      check_stacked(detect_once(bodies), bodies, plane_first ? 0 : 1,
                    std::string(k.name) + (plane_first ? " on plane (plane is a)" : " on plane (plane is b)"), 1e-12);
    }
  }
}

TEST(FclPairs, SphereSphereIsExact) {
  // Centers 0.9 apart along (1, 2, 2)/3, radii 0.5 and 0.45: depth 0.05, point midway between surfaces.
  const Vec3 u = Vec3(1, 2, 2) / 3.0;
  const std::vector<RigidBody> bodies{make_body("a", Sphere{0.5}, Vec3(1, 1, 1)),
                                      make_body("b", Sphere{0.45}, Vec3(1, 1, 1) + 0.9 * u)};
  const auto contacts = detect_once(bodies);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_LT((contacts[0].normal - u).norm(), 1e-15);
  EXPECT_NEAR(contacts[0].depth, 0.05, 1e-15);
  const Vec3 mid = 0.5 * ((Vec3(1, 1, 1) + 0.5 * u) + (bodies[1].position - 0.45 * u));
  EXPECT_LT((contacts[0].point - mid).norm(), 1e-15);
}

TEST(FclPairs, SphereOnAPlaneTouchesAtItsLowestPoint) {
  const std::vector<RigidBody> bodies{ground(), make_body("ball", Sphere{0.5}, Vec3(2, 3, 0.49))};
  const auto contacts = detect_once(bodies);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_LT((contacts[0].point - Vec3(2, 3, -0.005)).norm(), 1e-15);
  EXPECT_NEAR(contacts[0].depth, 0.01, 1e-15);
}

TEST(FclPairs, SphereAgainstABoxEdgeAndCorner) {
  // Sphere r = 0.5 near the box's (+x, +z) edge, center at distance 0.49 from it along (1, 0, 1)/√2.
  const Vec3 u = Vec3(1, 0, 1).normalized();
  const Vec3 edge(0.5, 0.1, 0.5);
  for (bool sphere_first : {false, true}) {
    const RigidBody box = make_body("box", Box{Vec3(1, 1, 1)}, Vec3::Zero());
    const RigidBody ball = make_body("ball", Sphere{0.5}, edge + 0.49 * u);
    const std::vector<RigidBody> bodies = sphere_first ? std::vector{ball, box} : std::vector{box, ball};
    const auto contacts = detect_once(bodies);
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_LT((contacts[0].normal - (sphere_first ? -u : u)).norm(), 1e-12);
    EXPECT_NEAR(contacts[0].depth, 0.01, 1e-12);
    EXPECT_LT((contacts[0].point - (edge + 0.5 * (0.49 - 0.5) * u)).norm(), 1e-12);
  }
}

TEST(FclPairs, CylinderAgainstCylinderSideBySideGivesTheirCommonLine) {
  // Two lying cylinders (axes along x), radius 0.5, centers 0.99 apart in y: depth 0.01, 2 points.
  const Mat3 lying = rotation_about(Vec3::UnitY(), std::numbers::pi / 2);
  const std::vector<RigidBody> bodies{make_body("a", Cylinder{0.5, 2.0}, Vec3::Zero(), lying),
                                      make_body("b", Cylinder{0.5, 2.0}, Vec3(0.5, 0.99, 0), lying)};
  const auto contacts = detect_once(bodies);
  ASSERT_EQ(contacts.size(), 2u);
  for (const Contact& c : contacts) {
    EXPECT_LT((c.normal - Vec3::UnitY()).norm(), 1e-12);  // the radial candidate axis is exact
    EXPECT_NEAR(c.depth, 0.01, 1e-12);
  }
  EXPECT_NEAR(std::abs(contacts[0].point.x() - contacts[1].point.x()), 1.5, 1e-6);  // overlap x ∈ [−0.5, 1]
}

TEST(FclPairs, TriangleMeshOnTriangleMeshFindsTheContactWithOutwardNormals) {
  const std::vector<RigidBody> bodies{
      make_body("a", mesh_shape(cube_mesh(0.5), MeshCollision::triangles), Vec3::Zero()),
      make_body("b", mesh_shape(cube_mesh(0.5), MeshCollision::triangles), Vec3(0.2, 0.1, 0.99))};
  const auto contacts = detect_once(bodies);
  ASSERT_FALSE(contacts.empty());
  EXPECT_LE(contacts.size(), 4u);
  for (const Contact& c : contacts) EXPECT_GT(c.normal.z(), 0.5) << c.normal.transpose();  // out of a into b
}

}  // namespace
}  // namespace impetus::test

namespace impetus::test {
namespace {

TEST(FclPairs, RandomPairsHaveFiniteOutwardNormalsAndConsistentDepths) {
  // Random poses of every pair near contact. For every contact: a finite unit normal; the
  // orientation out of a (the overlap along n is smaller than along −n: the explicit check); and a
  // depth within the margin that never exceeds the overlap of the shapes along n.
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto random_rotation = [&] { return Mat3(Quat(u(rng), u(rng), u(rng), u(rng)).normalized()); };
  const FclDetectorSettings settings;
  std::size_t checked = 0;
  for (const Kind& ka : kinds()) {
    for (const Kind& kb : kinds()) {
      // (The triangle mesh here is a cube, so the convex checks apply to it too.)
      for (int trial = 0; trial < 40; ++trial) {
        const Vec3 dir = Vec3(u(rng), u(rng), u(rng)).normalized();
        const double distance = (ka.half_height + kb.half_height) * (0.75 + 0.3 * (u(rng) + 1.0) / 2.0);
        std::vector<RigidBody> bodies{make_body("a", ka.make(), Vec3::Zero(), random_rotation()),
                                      make_body("b", kb.make(), distance * dir, random_rotation())};
        FclDetector detector(settings);
        ASSERT_TRUE(detector.set_bodies(bodies, {}).ok);
        std::vector<Contact> contacts;
        DetectorCounters counters;
        detector.detect(bodies, StepContext{}, contacts, counters);
        EXPECT_EQ(detector.last_profile().fcl_failures, 0u);
        std::vector<collision::ShapeGeometry> g;
        for (const RigidBody& b : bodies) {
          std::shared_ptr<collision::MeshData> mesh;
          if (const auto* m = std::get_if<MeshShape>(&b.shape)) mesh = collision::make_mesh_data(*m->mesh, true);
          g.push_back(collision::make_geometry(b.shape, mesh));
        }
        const collision::Placed pa{&g[0], bodies[0].position, bodies[0].rotation};
        const collision::Placed pb{&g[1], bodies[1].position, bodies[1].rotation};
        for (const Contact& c : contacts) {
          const std::string label = std::string(ka.name) + "-" + kb.name + " trial " + std::to_string(trial);
          ASSERT_TRUE(c.normal.allFinite() && c.point.allFinite() && std::isfinite(c.depth)) << label;
          EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12) << label;
          const double along = collision::overlap_along(pa, pb, c.normal);
          EXPECT_LT(along, collision::overlap_along(pa, pb, -c.normal)) << label;
          EXPECT_GE(c.depth, -settings.margin - 1e-12) << label;
          EXPECT_LE(c.depth, along + 1e-6) << label;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 500u);
}

TEST(FclPairs, CapsuleBoxAxisIsTheLeastOverlapOverEveryDirection) {
  // capsule_box_axis (no FCL) on random poses from deep penetration to a clear gap. Two checks that do
  // not use its candidates: (1) no direction overlaps less than the axis it returns (tried on 4000 random
  // directions per pose), so it finds the true minimum over directions; (2) when the core segment stays
  // out of the box, minus that minimum is the distance from the core to the box (sampled at 20001
  // points, m) minus the radius.
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto random_rotation = [&] { return Mat3(Quat(u(rng), u(rng), u(rng), u(rng)).normalized()); };
  const collision::ShapeGeometry capsule = collision::make_geometry(Capsule{0.2, 0.8}, nullptr);
  const collision::ShapeGeometry box = collision::make_geometry(Box{Vec3(1.0, 0.6, 0.4)}, nullptr);
  std::vector<Vec3> directions;
  for (int i = 0; i < 4000; ++i) directions.push_back(Vec3(u(rng), u(rng), u(rng)).normalized());
  int outside = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const collision::Placed pc{&capsule, Vec3(u(rng), u(rng), u(rng)) * (0.2 + 0.6 * (trial % 4)), random_rotation()};
    const collision::Placed pb{&box, Vec3::Zero(), random_rotation()};
    for (bool capsule_first : {true, false}) {
      const collision::Placed& a = capsule_first ? pc : pb;
      const collision::Placed& b = capsule_first ? pb : pc;
      const collision::AxisResult axis = collision::capsule_box_axis(a, b);
      ASSERT_TRUE(axis.valid);
      EXPECT_NEAR(axis.normal.norm(), 1.0, 1e-12);
      EXPECT_NEAR(axis.overlap, collision::overlap_along(a, b, axis.normal), 1e-12);
      for (const Vec3& n : directions) ASSERT_LE(axis.overlap, collision::overlap_along(a, b, n) + 1e-12) << trial;
      if (!capsule_first) continue;
      // The core in the box frame, sampled.
      const Vec3 h = box.half_extents, half = capsule.half_length * pc.axis();
      double nearest = std::numeric_limits<double>::infinity();
      for (int i = 0; i <= 20000; ++i) {
        const Vec3 p = pb.R.transpose() * (pc.x - half + (i / 10000.0) * half - pb.x);
        nearest = std::min(nearest, (p - p.cwiseMax(-h).cwiseMin(h)).norm());
      }
      if (nearest < 1e-3) continue;  // the core cuts into the box: (1) is the check there
      ++outside;
      // Sampling at spacing Δ = 4e-5 m misses an interior minimum by at most Δ²/(2·distance) < 1e-6 m.
      EXPECT_NEAR(-axis.overlap, nearest - capsule.radius, 1e-6) << trial;
    }
  }
  EXPECT_GT(outside, 50);
}

// Shapes lying square on each other, as they come to rest in a scene: a cylinder, a convex cube, a
// box, a capsule and a sphere, each with its axis along x, y or z, the upper one sunk by 1 µm or 1 mm
// into the lower one, square or turned by 1e-7 rad, in both argument orders. Every pair that has no
// closed form (a cylinder or a convex mesh in it) goes through FCL; FCL's signed distance (EPA) aborted
// the process on such contacts (FCL issue 322), which the detector no longer calls. The least overlap
// is then along z: the deepest contact has depth d and normal ±z.
TEST(FclPairs, CurvedAndConvexShapesLyingSquareOnEachOther) {
  struct Square {
    const char* name;
    std::function<Shape()> make;
    std::function<double(const Mat3&)> half_height;  // half its extent along world z, turned by R
  };
  const std::vector<Square> shapes{
      {"cylinder", [] { return Shape(Cylinder{0.4, 1.0}); },
       [](const Mat3& R) { return 0.5 * std::abs(R(2, 2)) + 0.4 * std::sqrt(std::max(0.0, 1.0 - R(2, 2) * R(2, 2))); }},
      {"convex", [] { return Shape(mesh_shape(cube_mesh(0.5), MeshCollision::convex)); },
       [](const Mat3& R) { return 0.5 * R.row(2).cwiseAbs().sum(); }},
      {"box", [] { return Shape(Box{Vec3(1.0, 0.8, 0.6)}); },
       [](const Mat3& R) { return R.row(2).cwiseAbs().dot(Vec3(0.5, 0.4, 0.3)); }},
      {"capsule", [] { return Shape(Capsule{0.3, 0.6}); }, [](const Mat3& R) { return 0.3 * std::abs(R(2, 2)) + 0.3; }},
      {"sphere", [] { return Shape(Sphere{0.5}); }, [](const Mat3&) { return 0.5; }},
  };
  const std::vector<Mat3> square{Mat3::Identity(), rotation_about(Vec3::UnitX(), std::numbers::pi / 2),
                                 rotation_about(Vec3::UnitY(), std::numbers::pi / 2)};
  std::size_t checked = 0;
  for (std::size_t lo = 0; lo < shapes.size(); ++lo) {
    for (std::size_t hi = 0; hi < shapes.size(); ++hi) {
      if (lo > 1 && hi > 1) continue;  // closed forms, tested above
      for (const Mat3& Rl : square) {
        for (const Mat3& Ru : square) {
          for (const double turn : {0.0, 1e-7}) {
            for (const double d : {1e-6, 1e-3}) {
              const Mat3 R = Ru * rotation_about(Vec3(1, 2, 3), turn);
              const double z = shapes[lo].half_height(Rl) + shapes[hi].half_height(R) - d;
              const RigidBody lower = make_body("lower", shapes[lo].make(), Vec3::Zero(), Rl);
              const RigidBody upper = make_body("upper", shapes[hi].make(), Vec3(0, 0, z), R);
              const std::string label = std::string(shapes[hi].name) + " on " + shapes[lo].name + ", sunk " +
                                        std::to_string(d) + ", turned " + std::to_string(turn);
              for (bool lower_first : {true, false}) {
                const std::vector<RigidBody> bodies = lower_first ? std::vector{lower, upper} : std::vector{upper, lower};
                const std::vector<Contact> contacts = detect_once(bodies);
                ASSERT_FALSE(contacts.empty()) << label;
                const Contact& deepest = *std::max_element(
                    contacts.begin(), contacts.end(), [](const Contact& l, const Contact& r) { return l.depth < r.depth; });
                const Vec3 up = lower_first ? Vec3::UnitZ() : Vec3(-Vec3::UnitZ());
                // 1e-7 rad of turn moves a point 1 m off the axis by 1e-7 m.
                EXPECT_NEAR(deepest.depth, d, 2e-7) << label;
                EXPECT_LT((deepest.normal - up).norm(), 1e-6) << label << ": " << deepest.normal.transpose();
                ++checked;
              }
            }
          }
        }
      }
    }
  }
  EXPECT_EQ(checked, 16u * 9u * 2u * 2u * 2u);
}

// Curved pairs through FCL at random poses, sunk up to 5 cm into each other: the deepest contact's depth
// is the least overlap over all directions. The reference: the lowest of 4000 random directions,
// refined by a pattern search on the sphere (an upper bound on the least overlap). Checked one way, with
// the detector at most 1e-6 m above the reference: MPR's direction alone was up to 7 mm above it, and a
// cylinder's support function within 1e-8 rad of its axis (before it was computed in the body frame)
// up to 1e-5 m.
TEST(FclPairs, CurvedPairsFindTheLeastOverlapAtRandomShallowPoses) {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto random_rotation = [&] { return Mat3(Quat(u(rng), u(rng), u(rng), u(rng)).normalized()); };
  std::vector<Vec3> directions;
  for (int i = 0; i < 4000; ++i) directions.push_back(Vec3(u(rng), u(rng), u(rng)).normalized());
  const std::vector<std::pair<Shape, Shape>> pairs{{Cylinder{0.4, 1.0}, Box{Vec3(1.0, 0.8, 0.6)}},
                                                   {Cylinder{0.4, 1.0}, Cylinder{0.1, 2.0}},
                                                   {Cylinder{0.4, 1.0}, Capsule{0.2, 0.8}},
                                                   {Cylinder{0.3, 0.5}, Cylinder{0.3, 0.5}}};
  int checked = 0;
  for (const auto& [shape_a, shape_b] : pairs) {
    const collision::ShapeGeometry ga = collision::make_geometry(shape_a, nullptr);
    const collision::ShapeGeometry gb = collision::make_geometry(shape_b, nullptr);
    for (int trial = 0; trial < 1000; ++trial) {
      const collision::Placed a{&ga, Vec3::Zero(), random_rotation()};
      collision::Placed b{&gb, Vec3::Zero(), random_rotation()};
      const Vec3 along = Vec3(u(rng), u(rng), u(rng)).normalized();
      b.x = (0.3 + 0.6 * 0.5 * (u(rng) + 1.0)) * along;
      Vec3 n = directions[0];
      double least = collision::overlap_along(a, b, n);
      for (const Vec3& d : directions)
        if (const double o = collision::overlap_along(a, b, d); o < least) least = o, n = d;
      if (least <= 0.0 || least > 0.05) continue;  // apart, or not a shallow contact
      int moves = 0;
      for (double step = 0.05, turn = 0.0; step > 1e-10 && moves < 2000;) {
        const Vec3 e1 = n.unitOrthogonal(), e2 = n.cross(e1);
        bool moved = false;
        for (int k = 0; k < 16; ++k) {
          const double angle = turn + k * std::numbers::pi / 8.0;
          const Vec3 m = (n + step * (std::cos(angle) * e1 + std::sin(angle) * e2)).normalized();
          if (const double o = collision::overlap_along(a, b, m); o < least - 1e-15) least = o, n = m, moved = true;
        }
        if (moved) ++moves;
        else step *= 0.5, turn += 0.618;
      }
      if (least <= 1e-6) continue;  // apart, or touching
      const std::vector<RigidBody> bodies{make_body("a", shape_a, a.x, a.R), make_body("b", shape_b, b.x, b.R)};
      const std::vector<Contact> contacts = detect_once(bodies);
      ASSERT_FALSE(contacts.empty()) << trial << ": the least overlap found " << least;
      double deepest = -1.0;
      for (const Contact& c : contacts) deepest = std::max(deepest, c.depth);
      EXPECT_LE(deepest, least + 1e-6) << trial << ": the least overlap found " << least;
      EXPECT_GE(deepest, 0.0) << trial;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

/// A fixed convex plate 2 m × 2 m × 1 cm (8 vertices, 6 faces) with its top face at z = 0.
RigidBody thin_plate(MeshCollision collision) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) v.emplace_back((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 0.005 : -0.005);
  const auto mesh =
      mesh_from_faces(v, {{0, 2, 4, 6}, {1, 3, 5, 7}, {0, 1, 4, 5}, {2, 3, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7}});
  return make_body("plate", mesh_shape(mesh, collision), Vec3(0, 0, -0.005), Mat3::Identity(), true);
}

// A 2 cm ball on a thin convex plate, touching exactly, overlapping by 1e-12 m and 1e-5 m, and 5e-5 m
// above it, at several places: one contact, normal +z and depth to 1e-9. FCL's EPA gave a normal 84° off
// for the exact touch (depth 1.13 m) before every face of a small hull became a candidate axis.
TEST(FclPairs, BallTouchingAThinConvexPlate) {
  for (const double gap : {0.0, -1e-12, -1e-5, 5e-5}) {
    for (const Vec3& at : {Vec3(0.1, 0.2, 0), Vec3(0.7, -0.3, 0), Vec3(0, 0, 0), Vec3(-0.95, 0.9, 0)}) {
      SCOPED_TRACE("gap " + std::to_string(gap) + " at " + std::to_string(at.x()) + ", " + std::to_string(at.y()));
      const std::vector<RigidBody> bodies{thin_plate(MeshCollision::convex),
                                          make_body("ball", Sphere{0.02}, at + Vec3(0, 0, 0.02 + gap))};
      const std::vector<Contact> contacts = detect_once(bodies);
      ASSERT_EQ(contacts.size(), 1u);
      EXPECT_LT((contacts[0].normal - Vec3::UnitZ()).norm(), 1e-9) << contacts[0].normal.transpose();
      EXPECT_NEAR(contacts[0].depth, -gap, 1e-9);
    }
  }
}

// Speculative contacts at the detector (detection/fcl/README.md, "Fast bodies"): a 2 cm ball 10 cm above
// a thin plate, at dt = 1 ms.
TEST(FclSpeculative, AFastBallIsMetAStepAheadAndASlowOneIsNot) {
  StepContext ctx;
  ctx.dt = 1e-3;
  for (const MeshCollision collision : {MeshCollision::convex, MeshCollision::triangles}) {
    for (const bool speculative : {true, false}) {
      std::vector<RigidBody> bodies{thin_plate(collision), make_body("ball", Sphere{0.02}, Vec3(0.1, 0.2, 0.12))};
      FclDetectorSettings settings;
      settings.speculative = speculative;
      FclDetector detector(settings);
      ASSERT_TRUE(detector.set_bodies(bodies, {}).ok);
      const auto detect = [&](const Vec3& velocity) {
        bodies[1].velocity = velocity;
        std::vector<Contact> contacts;
        DetectorCounters counters;
        detector.detect(bodies, ctx, contacts, counters);
        return std::pair{contacts, counters.speculative_pairs};
      };
      // 300 m/s down: it would cross 30 cm this step. With the look-ahead the face is a contact with
      // depth −0.1 m, normal +z (and the triangle mesh's neighbouring edge, further); without, nothing.
      const auto [down, down_pairs] = detect(Vec3(0, 0, -300));
      if (speculative) {
        EXPECT_EQ(down_pairs, 1u);
        ASSERT_FALSE(down.empty());
        const auto nearest = std::max_element(down.begin(), down.end(),
                                              [](const Contact& l, const Contact& r) { return l.depth < r.depth; });
        EXPECT_NEAR(nearest->depth, -0.1, 1e-12);
        EXPECT_LT((nearest->normal - Vec3::UnitZ()).norm(), 1e-12);
      } else {
        EXPECT_EQ(down_pairs, 0u);
        EXPECT_TRUE(down.empty());
      }
      // 300 m/s sideways: the gap never closes, so conservative advancement drops the pair's contacts.
      const auto [side, side_pairs] = detect(Vec3(300, 0, 0));
      EXPECT_TRUE(side.empty());
      // 90 m/s down: 9 cm this step, short of the 10 cm gap: no contact either.
      const auto [short_of, short_pairs] = detect(Vec3(0, 0, -90));
      EXPECT_TRUE(short_of.empty());
      // 2 m/s down from 1 mm above: 2 mm per step, less than half the hull's 5 mm inner radius, so the
      // hull gets no look-ahead (the ball sinks 1 mm and the position correction lifts it); the triangle
      // mesh counts as thin anywhere and meets the ball on its face.
      bodies[1].position.z() = 0.021;
      const auto [slow, slow_pairs] = detect(Vec3(0, 0, -2));
      const bool ahead = speculative && collision == MeshCollision::triangles;
      EXPECT_EQ(slow_pairs, ahead ? 1u : 0u);
      ASSERT_EQ(slow.size(), ahead ? 1u : 0u);
      if (ahead) {
        EXPECT_NEAR(slow[0].depth, -0.001, 1e-12);
      }
    }
  }
}

}  // namespace
}  // namespace impetus::test
