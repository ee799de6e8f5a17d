// The FCL-free manifold pieces of the `fcl` detector: clipping, segment closest points, supporting
// features, duplicate merging and reduction to the largest-area 4 points. Each test states the geometric
// fact it checks and its tolerance.
#include "impetus/detection/fcl/manifold.hpp"
#include "impetus/detection/fcl/shapes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace impetus::collision {
namespace {

constexpr double kTol = 1e-12;

SmallVec<Vec3, 32> square(double half, double z) {
  SmallVec<Vec3, 32> s;
  for (const auto& [x, y] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) s.push_back(Vec3(x * half, y * half, z));
  return s;
}

/// Area of the convex polygon through `points` (≤ 4, any order) in the z = const plane.
double hull_area_xy(const std::vector<ManifoldPoint>& pts) {
  // Sort by angle around the centroid, then shoelace.
  Vec3 c = Vec3::Zero();
  for (const auto& p : pts) c += p.point;
  c /= static_cast<double>(pts.size());
  std::vector<Vec3> v;
  for (const auto& p : pts) v.push_back(p.point);
  std::sort(v.begin(), v.end(), [&](const Vec3& a, const Vec3& b) {
    return std::atan2(a.y() - c.y(), a.x() - c.x()) < std::atan2(b.y() - c.y(), b.x() - c.x());
  });
  double area = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i)
    area += v[i].x() * v[(i + 1) % v.size()].y() - v[(i + 1) % v.size()].x() * v[i].y();
  return 0.5 * std::abs(area);
}

TEST(FclManifoldParts, ClippingASquareByARotatedSquareGivesTheOctagon) {
  // Two unit squares, one turned 45°: their intersection is a regular octagon of area 2(√2 − 1)·… for
  // half-width 1: area = 8 (√2 − 1) ≈ 3.3137.
  ClipPolygon subject;
  for (const Vec3& p : square(1.0, 0.0)) subject.push_back({p, 0});
  SmallVec<Vec3, 32> clip;
  const double r = std::sqrt(2.0);
  for (int k = 0; k < 4; ++k) {
    const double t = k * std::numbers::pi / 2;
    clip.push_back(Vec3(r * std::cos(t), r * std::sin(t), 0));
  }
  clip_polygon(subject, clip, Vec3::UnitZ());
  ASSERT_EQ(subject.size(), 8u);
  std::vector<ManifoldPoint> pts;
  for (const ClipPoint& c : subject) pts.push_back({c.p, Vec3::UnitZ(), 0.0, c.id});
  // Shoelace over the output order (it is a convex polygon in order).
  double area = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Vec3& a = pts[i].point;
    const Vec3& b = pts[(i + 1) % pts.size()].point;
    area += a.x() * b.y() - b.x() * a.y();
  }
  EXPECT_NEAR(0.5 * std::abs(area), 8.0 * (std::sqrt(2.0) - 1.0), 1e-12);
}

TEST(FclManifoldParts, ClippingAContainedPolygonKeepsItsVerticesAndIds) {
  ClipPolygon subject;
  std::uint32_t id = 7;
  for (const Vec3& p : square(0.25, 0.3)) subject.push_back({p, id++});
  clip_polygon(subject, square(1.0, 0.0), Vec3::UnitZ());
  ASSERT_EQ(subject.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(subject[i].id, 7u + i);
}

TEST(FclManifoldParts, SegmentClosestPointsOfCrossingAndParallelSegments) {
  Vec3 p, q;
  // Crossing at right angles, 1 apart in z: closest points are the crossing points.
  closest_points_segments(Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0.3, -1, 1), Vec3(0.3, 1, 1), p, q);
  EXPECT_LT((p - Vec3(0.3, 0, 0)).norm(), kTol);
  EXPECT_LT((q - Vec3(0.3, 0, 1)).norm(), kTol);
  // Disjoint collinear segments: the facing endpoints.
  closest_points_segments(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0), p, q);
  EXPECT_LT((p - Vec3(1, 0, 0)).norm(), kTol);
  EXPECT_LT((q - Vec3(2, 0, 0)).norm(), kTol);
  // Parallel, overlapping: any pair at the true distance 0.5.
  closest_points_segments(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 0.5, 0), Vec3(3, 0.5, 0), p, q);
  EXPECT_NEAR((p - q).norm(), 0.5, kTol);
}

TEST(FclManifoldParts, FaceAgainstFaceGivesTheClippedOverlapWithDepths) {
  // Reference: a's top face z = 0 (square half 1); incident: b's bottom face at z = −0.01, shifted by
  // (1.5, 0): the overlap is x ∈ [0.5, 1], y ∈ [−1, 1], every point 0.01 deep.
  Feature fa, fb;
  fa.type = fb.type = Feature::Type::polygon;
  fa.normal = Vec3::UnitZ();
  fb.normal = -Vec3::UnitZ();
  for (const Vec3& p : square(1.0, 0.0)) fa.points.push_back(p), fa.ids.push_back(0);
  for (const Vec3& p : square(1.0, -0.01)) fb.points.push_back(p + Vec3(1.5, 0, 0)), fb.ids.push_back(0);
  std::vector<ManifoldPoint> out;
  ASSERT_EQ(feature_contacts(fa, fb, Vec3::UnitZ(), 0.01, 1e-4, FeatureTolerance{}, out), 4u);
  for (const auto& c : out) {
    EXPECT_NEAR(c.depth, 0.01, kTol);
    EXPECT_NEAR(c.point.z(), -0.005, kTol);  // midway between the surfaces
    EXPECT_GE(c.point.x(), 0.5 - kTol);
    EXPECT_LE(c.point.x(), 1.0 + kTol);
    EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), kTol);
  }
  EXPECT_NEAR(hull_area_xy(out), 0.5 * 2.0, 1e-12);
}

TEST(FclManifoldParts, ReductionKeepsTheFourCornersOfAGrid) {
  // A 5×5 grid of equal-depth points on the unit square: the largest-area 4 are its corners (area 1).
  std::vector<ManifoldPoint> pts;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) pts.push_back({Vec3(i * 0.25, j * 0.25, 0), Vec3::UnitZ(), 0.01, 0});
  std::vector<ManifoldPoint> with_deep_center = pts;
  EXPECT_EQ(reduce_to_spanning(pts, 4), 21u);
  ASSERT_EQ(pts.size(), 4u);
  EXPECT_NEAR(hull_area_xy(pts), 1.0, kTol);
  // A clearly deeper point is kept: it replaces the nearest corner (area 1/2 left).
  with_deep_center[12].depth = 0.02;
  reduce_to_spanning(with_deep_center, 4);
  ASSERT_EQ(with_deep_center.size(), 4u);
  bool has_center = false;
  for (const auto& p : with_deep_center) has_center |= (p.point - Vec3(0.5, 0.5, 0)).norm() < kTol;
  EXPECT_TRUE(has_center);
  EXPECT_NEAR(hull_area_xy(with_deep_center), 0.5, kTol);
  // One point: the deepest.
  std::vector<ManifoldPoint> one = with_deep_center;
  reduce_to_spanning(one, 1);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_DOUBLE_EQ(one[0].depth, 0.02);
}

TEST(FclManifoldParts, ReductionOfRimPointsGivesASquareInscribedInTheCircle) {
  // 12 equal-depth points on a circle of radius 1: the best 4 form a square of area 2.
  std::vector<ManifoldPoint> pts;
  for (int k = 0; k < 12; ++k) {
    const double t = 2.0 * std::numbers::pi * k / 12;
    pts.push_back({Vec3(std::cos(t), std::sin(t), 0), Vec3::UnitZ(), 0.0, 0});
  }
  reduce_to_spanning(pts, 4);
  ASSERT_EQ(pts.size(), 4u);
  EXPECT_NEAR(hull_area_xy(pts), 2.0, 1e-12);
}

TEST(FclManifoldParts, CollinearPointsReduceToTheirEnds) {
  std::vector<ManifoldPoint> pts;
  for (int i = 0; i <= 10; ++i) pts.push_back({Vec3(0.1 * i, 0, 0), Vec3::UnitZ(), 0.0, 0});
  reduce_to_spanning(pts, 4);
  ASSERT_EQ(pts.size(), 2u);  // a third point would add no area: overdetermined, so not kept
  EXPECT_NEAR((pts[0].point - pts[1].point).norm(), 1.0, kTol);
}

TEST(FclManifoldParts, MergingKeepsTheDeeperOfNearDuplicates) {
  std::vector<ManifoldPoint> pts{{Vec3(0, 0, 0), Vec3::UnitZ(), 0.01, 1},
                                 {Vec3(1e-5, 0, 0), Vec3::UnitZ(), 0.02, 2},
                                 {Vec3(1, 0, 0), Vec3::UnitZ(), 0.01, 3}};
  EXPECT_EQ(merge_duplicates(pts, 1e-4), 1u);
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_EQ(pts[0].feature, 2u);
  EXPECT_DOUBLE_EQ(pts[0].depth, 0.02);
}

TEST(FclManifoldParts, BoxSupportingFeaturesArePointEdgeAndFace) {
  ShapeGeometry g = make_geometry(Box{Vec3(2, 2, 2)}, nullptr);
  const Placed box{&g, Vec3::Zero(), Mat3::Identity()};
  const FeatureTolerance tol;
  EXPECT_EQ(supporting_feature(box, Vec3::UnitZ(), tol).type, Feature::Type::polygon);
  EXPECT_EQ(supporting_feature(box, Vec3::UnitZ(), tol).points.size(), 4u);
  EXPECT_EQ(supporting_feature(box, Vec3(1, 0, 1).normalized(), tol).type, Feature::Type::segment);
  const Feature corner = supporting_feature(box, Vec3(1, 1, 1).normalized(), tol);
  ASSERT_EQ(corner.type, Feature::Type::point);
  EXPECT_LT((corner.points[0] - Vec3(1, 1, 1)).norm(), kTol);
}

TEST(FclManifoldParts, CylinderSupportingFeaturesAreRimPolygonSideLineAndRimPoint) {
  ShapeGeometry g = make_geometry(Cylinder{0.5, 2.0}, nullptr);
  const Placed cyl{&g, Vec3::Zero(), Mat3::Identity()};
  const FeatureTolerance tol;
  const Feature cap = supporting_feature(cyl, -Vec3::UnitZ(), tol);
  ASSERT_EQ(cap.type, Feature::Type::polygon);
  for (const Vec3& p : cap.points) {
    EXPECT_NEAR(p.z(), -1.0, kTol);
    EXPECT_NEAR(std::hypot(p.x(), p.y()), 0.5, kTol);
  }
  const Feature side = supporting_feature(cyl, Vec3::UnitX(), tol);
  ASSERT_EQ(side.type, Feature::Type::segment);
  EXPECT_NEAR(side.points[0].x(), 0.5, kTol);
  const Feature rim = supporting_feature(cyl, Vec3(1, 0, 1).normalized(), tol);
  ASSERT_EQ(rim.type, Feature::Type::point);
  EXPECT_LT((rim.points[0] - Vec3(0.5, 0, 1)).norm(), kTol);
}

}  // namespace
}  // namespace impetus::collision
