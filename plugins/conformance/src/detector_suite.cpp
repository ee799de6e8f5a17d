// The detector conformance suite: the promises of impetus/modules/detector.hpp and contact.hpp, checked
// on a detector loaded from its .so. Convention: a < b, the unit normal points out of a into b, depth > 0
// overlaps and < 0 is a gap within the detector's margin; the list is sorted deterministically.
#include "impetus/conformance/conformance.hpp"

#include <cmath>
#include <utility>

namespace impetus::conformance {
namespace {

constexpr double kExact = 1e-12;  // closed forms: rounding only

/// set_bodies, then one detect at the bodies' poses; fails the test if set_bodies refuses.
std::vector<Contact> detect(CollisionDetector& detector, const std::vector<RigidBody>& bodies,
                            DetectorCounters* counters = nullptr) {
  const ModuleStatus status = detector.set_bodies(bodies, {});
  EXPECT_TRUE(status.ok) << status.message;
  std::vector<Contact> contacts;
  DetectorCounters local;
  detector.detect(bodies, StepContext{}, contacts, counters != nullptr ? *counters : local);
  return contacts;
}

/// A movable body of `shape` at `position` (mass properties do not matter to a detector).
RigidBody placed(const Shape& shape, const Vec3& position, const Mat3& rotation = Mat3::Identity()) {
  RigidBody b = principal_body(1.0, Vec3::Ones());
  b.shape = shape;
  b.position = position;
  b.rotation = rotation;
  return b;
}

// Law: a sphere of radius r whose center is at height r − d above the ground z = 0 gives one contact:
// a = the ground, b = the sphere, n = +z, depth = d, and a point below the center between the two
// surfaces (z in [−d, 0]). d = 1e-3 and 0.05 m; 1e-12.
TEST_P(DetectorConformance, SphereOnAPlane) {
  const auto detector = load_detector(GetParam());
  for (const double d : {1e-3, 0.05}) {
    SCOPED_TRACE("depth " + std::to_string(d));
    const Vec3 center(0.3, -0.2, 0.5 - d);
    DetectorCounters counters;
    const std::vector<Contact> contacts = detect(*detector, {ground(), placed(Sphere{0.5}, center)}, &counters);
    ASSERT_EQ(contacts.size(), 1u);
    const Contact& c = contacts[0];
    EXPECT_EQ(c.a, 0u);
    EXPECT_EQ(c.b, 1u);
    EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), kExact);
    EXPECT_NEAR(c.depth, d, kExact);
    EXPECT_LT((c.point.head<2>() - center.head<2>()).norm(), kExact);
    EXPECT_GE(c.point.z(), -d - kExact);
    EXPECT_LE(c.point.z(), kExact);
    EXPECT_EQ(counters.contacts, 1u);
  }
}

// Law: two overlapping spheres (radii 0.5 and 0.3, centres 0.7 apart along a tilted axis u) give one
// contact with n = u (out of the lower-index body), depth 0.1, on the segment between the centres. 1e-12.
TEST_P(DetectorConformance, TwoSpheres) {
  const auto detector = load_detector(GetParam());
  const Vec3 u = Vec3(1.0, -2.0, 0.5).normalized();
  const Vec3 xa(0.1, 0.2, 0.3);
  const std::vector<Contact> contacts = detect(*detector, {placed(Sphere{0.5}, xa), placed(Sphere{0.3}, xa + 0.7 * u)});
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].a, 0u);
  EXPECT_EQ(contacts[0].b, 1u);
  EXPECT_LT((contacts[0].normal - u).norm(), kExact);
  EXPECT_NEAR(contacts[0].depth, 0.1, kExact);
  const Vec3 along = contacts[0].point - xa;
  EXPECT_LT((along - along.dot(u) * u).norm(), kExact);
  EXPECT_GE(along.dot(u), 0.4 - kExact);
  EXPECT_LE(along.dot(u), 0.5 + kExact);
}

// Law: a box resting flat on the ground, its bottom face sunk by d, touches over its whole bottom face:
// a manifold of 4 points at the face's corners (x, y to 1e-12), each with n = +z (out of the ground)
// and depth d (1e-12). The box is turned about z so the corners are not axis-aligned.
TEST_P(DetectorConformance, BoxOnAPlaneGivesTheFourCornerManifold) {
  const auto detector = load_detector(GetParam());
  const double d = 1e-3;
  const Vec3 size(1.0, 0.6, 0.4);
  const Mat3 turn = Eigen::AngleAxisd(0.4, Vec3::UnitZ()).toRotationMatrix();
  const Vec3 center(0.5, 0.2, 0.5 * size.z() - d);
  const std::vector<Contact> contacts = detect(*detector, {ground(), placed(Box{size}, center, turn)});
  ASSERT_EQ(contacts.size(), 4u);
  std::vector<bool> matched(4, false);
  for (const Contact& c : contacts) {
    EXPECT_EQ(c.a, 0u);
    EXPECT_EQ(c.b, 1u);
    EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), kExact);
    EXPECT_NEAR(c.depth, d, kExact);
    for (int k = 0; k < 4; ++k) {
      const Vec3 corner = center + turn * Vec3((k & 1 ? 0.5 : -0.5) * size.x(), (k & 2 ? 0.5 : -0.5) * size.y(), 0.0);
      if ((c.point.head<2>() - corner.head<2>()).norm() < kExact) matched[k] = true;
    }
  }
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(matched[k]) << "no contact at corner " << k;
}

/// Spheres, boxes and capsules in a heap on the ground, all touching something.
std::vector<RigidBody> heap() {
  std::vector<RigidBody> bodies{ground()};
  for (int i = 0; i < 4; ++i) {
    const Mat3 r = Eigen::AngleAxisd(0.3 * i + 0.1, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    bodies.push_back(placed(Box{Vec3(0.6, 0.5, 0.4)}, Vec3(0.55 * i, 0.0, 0.15), r));
    bodies.push_back(placed(Sphere{0.3}, Vec3(0.55 * i + 0.2, 0.35, 0.28)));
    bodies.push_back(placed(Capsule{0.2, 0.5}, Vec3(0.55 * i - 0.1, -0.4, 0.18), r));
  }
  return bodies;
}

// Law: the list is sorted by (a, b), every contact has a < b, a unit normal, and (x_b − x_a)·n > 0 for
// pairs of movable bodies; two detections by two modules loaded separately give bit-identical lists
// (bodies, points, normals, depths, features, order).
TEST_P(DetectorConformance, ContactOrderIsDeterministic) {
  const auto first = load_detector(GetParam());
  const auto second = load_detector(GetParam());
  const std::vector<RigidBody> bodies = heap();
  const std::vector<Contact> x = detect(*first, bodies);
  const std::vector<Contact> again = detect(*first, bodies);
  const std::vector<Contact> y = detect(*second, bodies);
  ASSERT_GT(x.size(), 10u) << "the heap should touch in many places";
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_LT(x[i].a, x[i].b);
    EXPECT_NEAR(x[i].normal.norm(), 1.0, kExact);
    if (!bodies[x[i].a].fixed) {
      EXPECT_GT((bodies[x[i].b].position - bodies[x[i].a].position).dot(x[i].normal), 0.0);
    }
    if (i > 0) {
      EXPECT_LE(std::pair(x[i - 1].a, x[i - 1].b), std::pair(x[i].a, x[i].b)) << "not sorted at " << i;
    }
  }
  for (const std::vector<Contact>* other : {&again, &y}) {
    ASSERT_EQ(other->size(), x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      const Contact& p = x[i];
      const Contact& q = (*other)[i];
      EXPECT_TRUE(p.a == q.a && p.b == q.b && p.point == q.point && p.normal == q.normal && p.depth == q.depth &&
                  p.feature == q.feature)
          << "contact " << i << " differs";
    }
  }
}

// Law (claim `margin`): with the option margin = m, a gap g < m is a contact of depth −g (1e-12) and a
// gap g > m is none. Sphere over the ground and box over the ground, m = 1e-3, g = m/2 and 2m.
TEST_P(DetectorConformance, GapsWithinTheMarginAreContacts) {
  if (!GetParam().claims_capability("margin"))
    GTEST_SKIP() << GetParam().label << " does not claim the option `margin`";
  const double margin = 1e-3;
  const auto detector = load_detector(GetParam(), {{"margin", "1e-3"}});
  for (const double gap : {0.5 * margin, 2.0 * margin}) {
    SCOPED_TRACE("gap " + std::to_string(gap));
    const std::vector<Contact> sphere_gap = detect(*detector, {ground(), placed(Sphere{0.5}, Vec3(0, 0, 0.5 + gap))});
    const std::vector<Contact> box_gap = detect(*detector, {ground(), placed(Box{Vec3(1, 1, 1)}, Vec3(0, 0, 0.5 + gap))});
    if (gap < margin) {
      ASSERT_EQ(sphere_gap.size(), 1u);
      EXPECT_NEAR(sphere_gap[0].depth, -gap, kExact);
      ASSERT_EQ(box_gap.size(), 4u);
      for (const Contact& c : box_gap) EXPECT_NEAR(c.depth, -gap, kExact);
    } else {
      EXPECT_TRUE(sphere_gap.empty());
      EXPECT_TRUE(box_gap.empty());
    }
  }
}

// Refusal: an option the detector does not read is refused when it is loaded, with a message naming it.
TEST_P(DetectorConformance, RefusesAnUnknownOption) {
  const std::string message = unknown_option_message(GetParam(), ModuleKind::detector, "conformance_no_such_option");
  EXPECT_NE(message.find("has no option 'conformance_no_such_option'"), std::string::npos) << message;
}

}  // namespace
}  // namespace impetus::conformance
