// Contact manifolds through the `fcl` detector: resting faces get 3–4 points spanning the contact face,
// lines get 2, edges crossing and corners get 1; the margin turns small gaps into negative-depth contacts.
#include "detection_test_support.hpp"

#include <numbers>
#include <set>

namespace impetus::test {
namespace {

constexpr double kTol = 1e-9;
constexpr double kPi = std::numbers::pi;

/// True if every expected point has a contact within kTol (and the counts match).
void expect_points(const std::vector<Contact>& contacts, const std::vector<Vec3>& expected, const std::string& label) {
  ASSERT_EQ(contacts.size(), expected.size()) << label;
  for (const Vec3& e : expected) {
    const bool found =
        std::any_of(contacts.begin(), contacts.end(), [&](const Contact& c) { return (c.point - e).norm() < kTol; });
    EXPECT_TRUE(found) << label << ": no contact at " << e.transpose();
  }
}

TEST(FclManifold, BoxOnAPlaneGetsItsFourBottomCorners) {
  // A 1 × 2 × 0.5 box sunk 0.01 into the ground: 4 points at its bottom corners, 0.01 deep, midway.
  const std::vector<RigidBody> bodies{ground(), make_body("box", Box{Vec3(1, 2, 0.5)}, Vec3(3, 4, 0.24))};
  const auto contacts = detect_once(bodies);
  std::vector<Vec3> corners;
  for (double x : {2.5, 3.5})
    for (double y : {3.0, 5.0}) corners.emplace_back(x, y, -0.005);
  expect_points(contacts, corners, "box on plane");
  for (const Contact& c : contacts) EXPECT_NEAR(c.depth, 0.01, 1e-12);
}

TEST(FclManifold, BoxOnABoxGetsTheFourCornersOfTheOverlap) {
  // Equal unit boxes, the upper one shifted (0.3, 0.2) and sunk 0.01: the overlap is
  // x ∈ [−0.2, 0.5], y ∈ [−0.3, 0.5] at z = 0.5.
  const std::vector<RigidBody> bodies{make_body("lower", Box{Vec3(1, 1, 1)}, Vec3::Zero()),
                                      make_body("upper", Box{Vec3(1, 1, 1)}, Vec3(0.3, 0.2, 0.99))};
  const auto contacts = detect_once(bodies);
  std::vector<Vec3> corners;
  for (double x : {-0.2, 0.5})
    for (double y : {-0.3, 0.5}) corners.emplace_back(x, y, 0.495);
  expect_points(contacts, corners, "box on box");
  for (const Contact& c : contacts) {
    EXPECT_NEAR(c.depth, 0.01, 1e-12);
    EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), 1e-12);
  }
}

TEST(FclManifold, SmallBoxOnATurnedBoxGetsFourSpanningPoints) {
  // The upper box is turned 45° about z: the clipped octagon is reduced to 4 points, no duplicates.
  const std::vector<RigidBody> bodies{
      make_body("lower", Box{Vec3(1, 1, 1)}, Vec3::Zero()),
      make_body("upper", Box{Vec3(1, 1, 1)}, Vec3(0, 0, 0.999), rotation_about(Vec3::UnitZ(), kPi / 4))};
  DetectorCounters counters;
  const auto contacts = detect_once(bodies, {}, {}, &counters);
  ASSERT_EQ(contacts.size(), 4u);
  EXPECT_EQ(counters.contacts_dropped, 4u);  // 8 octagon corners → 4
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = i + 1; j < 4; ++j) EXPECT_GT((contacts[i].point - contacts[j].point).norm(), 0.3);
}

TEST(FclManifold, TiltedBoxRestingOnAnEdgeGetsTwoPoints) {
  // A unit box turned 10° about y, its lowest edge 0.01 below the ground: 2 points along that edge.
  const Mat3 r = rotation_about(Vec3::UnitY(), 10.0 * kPi / 180.0);
  double lowest = 0.0;  // lowest corner height relative to the center
  for (double x : {-0.5, 0.5})
    for (double z : {-0.5, 0.5}) lowest = std::min(lowest, (r * Vec3(x, 0, z)).z());
  const std::vector<RigidBody> bodies{ground(), make_body("box", Box{Vec3(1, 1, 1)}, Vec3(0, 0, -lowest - 0.01), r)};
  const auto contacts = detect_once(bodies);
  ASSERT_EQ(contacts.size(), 2u);
  EXPECT_NEAR(std::abs(contacts[0].point.y() - contacts[1].point.y()), 1.0, kTol);
  for (const Contact& c : contacts) EXPECT_NEAR(c.depth, 0.01, 1e-12);
}

TEST(FclManifold, BoxesCrossingEdgeToEdgeGetOnePoint) {
  // Both boxes turned 45° about different horizontal axes: the lower one's top edge runs along y, the
  // upper one's bottom edge along x; they cross at the origin's vertical with overlap 0.01.
  const double d = std::sqrt(0.5);  // half diagonal of a unit square
  const std::vector<RigidBody> bodies{
      make_body("lower", Box{Vec3(1, 1, 1)}, Vec3::Zero(), rotation_about(Vec3::UnitY(), kPi / 4)),
      make_body("upper", Box{Vec3(1, 1, 1)}, Vec3(0, 0, 2 * d - 0.01), rotation_about(Vec3::UnitX(), kPi / 4))};
  const auto contacts = detect_once(bodies);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_LT((contacts[0].normal - Vec3::UnitZ()).norm(), 1e-9);
  EXPECT_NEAR(contacts[0].depth, 0.01, 1e-9);
  EXPECT_LT((contacts[0].point - Vec3(0, 0, d - 0.005)).norm(), 1e-9);
}

TEST(FclManifold, CapsuleLyingOnAPlaneGetsTwoPoints) {
  // Capsule r = 0.2, straight length 1, lying along x, 0.01 into the ground: its two end-cap bottoms.
  const std::vector<RigidBody> bodies{
      ground(), make_body("capsule", Capsule{0.2, 1.0}, Vec3(0, 0, 0.19), rotation_about(Vec3::UnitY(), kPi / 2))};
  const auto contacts = detect_once(bodies);
  expect_points(contacts, {Vec3(-0.5, 0, -0.005), Vec3(0.5, 0, -0.005)}, "capsule lying");
}

TEST(FclManifold, CapsuleLyingOnABoxGetsTwoPoints) {
  const std::vector<RigidBody> bodies{
      make_body("box", Box{Vec3(2, 2, 1)}, Vec3::Zero()),
      make_body("capsule", Capsule{0.2, 1.0}, Vec3(0.1, 0, 0.69), rotation_about(Vec3::UnitY(), kPi / 2))};
  const auto contacts = detect_once(bodies);
  ASSERT_EQ(contacts.size(), 2u);
  for (const Contact& c : contacts) {
    EXPECT_NEAR(c.depth, 0.01, 1e-6);
    EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), 1e-9);
  }
  EXPECT_NEAR(std::abs(contacts[0].point.x() - contacts[1].point.x()), 1.0, 1e-6);
}

TEST(FclManifold, UprightCylinderOnAPlaneGetsFourRimPointsSpanningASquare) {
  const std::vector<RigidBody> bodies{ground(), make_body("cyl", Cylinder{0.5, 1.0}, Vec3(0, 0, 0.49))};
  const auto contacts = detect_once(bodies);
  ASSERT_EQ(contacts.size(), 4u);
  for (const Contact& c : contacts) {
    EXPECT_NEAR(std::hypot(c.point.x(), c.point.y()), 0.5, 1e-12);
    EXPECT_NEAR(c.depth, 0.01, 1e-12);
  }
  // Opposite pairs are diameters: the inscribed square (area 2 r²).
  double longest = 0.0;
  for (const Contact& c : contacts) longest = std::max(longest, (c.point - contacts[0].point).norm());
  EXPECT_NEAR(longest, 1.0, 1e-12);
}

TEST(FclManifold, LyingCylinderOnAPlaneGetsTwoPoints) {
  // Radius 0.5, length 2, axis along x, 0.01 into the ground: the two ends of its lowest side line.
  const std::vector<RigidBody> bodies{
      ground(), make_body("cyl", Cylinder{0.5, 2.0}, Vec3(0, 0, 0.49), rotation_about(Vec3::UnitY(), kPi / 2))};
  expect_points(detect_once(bodies), {Vec3(-1, 0, -0.005), Vec3(1, 0, -0.005)}, "cylinder lying");
}

TEST(FclManifold, UprightCylinderOnABoxGetsFourPoints) {
  const std::vector<RigidBody> bodies{make_body("box", Box{Vec3(2, 2, 1)}, Vec3::Zero()),
                                      make_body("cyl", Cylinder{0.5, 1.0}, Vec3(0.2, 0.1, 0.99))};
  const auto contacts = detect_once(bodies);
  ASSERT_EQ(contacts.size(), 4u);
  for (const Contact& c : contacts) {
    EXPECT_NEAR(c.depth, 0.01, 1e-9);
    EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), 1e-9);
    EXPECT_NEAR(std::hypot(c.point.x() - 0.2, c.point.y() - 0.1), 0.5, 1e-9);
  }
}

TEST(FclManifold, ConvexMeshOnAPlaneUsesItsSupportingVertices) {
  // A cube mesh gets its 4 bottom vertices; an octahedron standing on a vertex gets that vertex.
  const std::vector<RigidBody> cube{
      ground(), make_body("cube", mesh_shape(cube_mesh(0.5), MeshCollision::convex), Vec3(0, 0, 0.49))};
  std::vector<Vec3> corners;
  for (double x : {-0.5, 0.5})
    for (double y : {-0.5, 0.5}) corners.emplace_back(x, y, -0.005);
  expect_points(detect_once(cube), corners, "convex cube on plane");
  const std::vector<RigidBody> octa{
      ground(), make_body("octa", mesh_shape(octahedron_mesh(0.5), MeshCollision::convex), Vec3(0, 0, 0.49))};
  expect_points(detect_once(octa), {Vec3(0, 0, -0.005)}, "octahedron on plane");
}

TEST(FclManifold, ConvexMeshOnABoxGetsTheFaceManifold) {
  const std::vector<RigidBody> bodies{make_body("box", Box{Vec3(2, 2, 1)}, Vec3::Zero()),
                                      make_body("cube", mesh_shape(cube_mesh(0.25), MeshCollision::convex),
                                                Vec3(0.3, 0, 0.74))};
  std::vector<Vec3> corners;
  for (double x : {0.05, 0.55})
    for (double y : {-0.25, 0.25}) corners.emplace_back(x, y, 0.495);
  expect_points(detect_once(bodies), corners, "convex cube on box");
}

TEST(FclManifold, MarginMakesHalfAMarginGapAContactAndTwoMarginsNone) {
  const double m = 1e-3;
  FclDetectorSettings settings;
  settings.margin = m;
  struct Case {
    const char* label;
    std::function<std::vector<RigidBody>(double gap)> scene;
    std::size_t points;
  };
  const std::vector<Case> cases{
      {"sphere-sphere",
       [](double g) {
         return std::vector{make_body("a", Sphere{0.5}, Vec3::Zero()), make_body("b", Sphere{0.5}, Vec3(1 + g, 0, 0))};
       },
       1},
      {"sphere-plane", [](double g) { return std::vector{ground(), make_body("b", Sphere{0.5}, Vec3(0, 0, 0.5 + g))}; },
       1},
      {"box-plane",
       [](double g) { return std::vector{ground(), make_body("b", Box{Vec3(1, 1, 1)}, Vec3(0, 0, 0.5 + g))}; }, 4},
      {"box-box",
       [](double g) {
         return std::vector{make_body("a", Box{Vec3(1, 1, 1)}, Vec3::Zero()),
                            make_body("b", Box{Vec3(1, 1, 1)}, Vec3(0, 0, 1 + g))};
       },
       4},
      {"cylinder-box",
       [](double g) {
         return std::vector{make_body("a", Box{Vec3(2, 2, 1)}, Vec3::Zero()),
                            make_body("b", Cylinder{0.5, 1.0}, Vec3(0, 0, 1 + g))};
       },
       4},
      {"capsule-sphere",
       [](double g) {
         return std::vector{make_body("a", Capsule{0.5, 1.0}, Vec3::Zero()),
                            make_body("b", Sphere{0.5}, Vec3(1 + g, 0, 0.2))};
       },
       1},
  };
  for (const Case& c : cases) {
    const auto near = detect_once(c.scene(0.5 * m), settings);
    ASSERT_EQ(near.size(), c.points) << c.label;
    for (const Contact& contact : near) EXPECT_NEAR(contact.depth, -0.5 * m, 1e-9) << c.label;
    EXPECT_TRUE(detect_once(c.scene(2.0 * m), settings).empty()) << c.label;
    // Exactly touching is found with the default margin too.
    EXPECT_EQ(detect_once(c.scene(0.0)).size(), c.points) << c.label << " touching";
  }
}

TEST(FclManifold, MaxContactsPerPairKeepsTheDeepest) {
  FclDetectorSettings settings;
  settings.max_contacts_per_pair = 1;
  const Mat3 tilt = rotation_about(Vec3(1, 1, 0), 0.01);
  const std::vector<RigidBody> bodies{ground(), make_body("box", Box{Vec3(1, 1, 1)}, Vec3(0, 0, 0.5), tilt)};
  const auto all = detect_once(bodies);
  const auto one = detect_once(bodies, settings);
  ASSERT_EQ(one.size(), 1u);
  double deepest = -1.0;
  for (const Contact& c : all) deepest = std::max(deepest, c.depth);
  EXPECT_DOUBLE_EQ(one[0].depth, deepest);
}

TEST(FclManifold, ZeroMaxContactsKeepsTheWholeOctagon) {
  // A unit box on another turned 45° about z: the faces overlap in a regular octagon. Every corner of
  // it is a contact point without reduction; the reduction keeps 4 of them.
  const Mat3 turned = rotation_about(Vec3::UnitZ(), std::numbers::pi / 4);
  const std::vector<RigidBody> bodies{make_body("low", Box{Vec3(1, 1, 1)}, Vec3::Zero()),
                                      make_body("high", Box{Vec3(1, 1, 1)}, Vec3(0, 0, 1 - 1e-5), turned)};
  FclDetectorSettings all;
  all.max_contacts_per_pair = 0;
  const auto octagon = detect_once(bodies, all);
  ASSERT_EQ(octagon.size(), 8u);
  // Octagon corners of a unit square and its 45° turn lie at distance 0.5 / cos(22.5°) from the axis.
  for (const Contact& c : octagon)
    EXPECT_NEAR(c.point.head<2>().norm(), 0.5 / std::cos(std::numbers::pi / 8), 1e-6);
  EXPECT_EQ(detect_once(bodies).size(), 4u);
}

}  // namespace
}  // namespace impetus::test
