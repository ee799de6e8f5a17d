// The broadphase's hierarchical grid against the definition: every pair of boxes that overlap (touching
// counts), once, and no other; never two fixed bodies; the pair limit honoured.
#include "impetus/detection/fcl/broadphase.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace impetus::test {
namespace {

using collision::Aabb;
using collision::Broadphase;

bool overlap(const Aabb& a, const Aabb& b) {
  return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

// Every overlapping pair, lower index first, sorted: the definition, by testing all n²/2 pairs.
std::vector<BodyPair> brute_force(const std::vector<Aabb>& boxes, const std::vector<char>& fixed) {
  std::vector<BodyPair> out;
  for (BodyIndex i = 0; i < boxes.size(); ++i)
    for (BodyIndex j = i + 1; j < boxes.size(); ++j)
      if (!(fixed[i] && fixed[j]) && overlap(boxes[i], boxes[j])) out.emplace_back(i, j);
  return out;
}

std::vector<BodyPair> collected(Broadphase& broadphase) {
  std::vector<BodyPair> pairs;
  EXPECT_TRUE(broadphase.collect(pairs, std::numeric_limits<std::size_t>::max()));
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

// Boxes of sizes spread over four decades (1 mm to 20 m; a few fixed), some touching exactly, some far
// out, one with a NaN corner, one unbounded and one whose extent overflows: the grid's levels, its
// clamped border cells and the fallbacks all meet.
std::vector<Aabb> mixed_boxes(std::mt19937_64& random, std::vector<char>& fixed, int n) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Aabb> boxes;
  for (int i = 0; i < n; ++i) {
    const double size = std::pow(10.0, -3.0 + 4.3 * unit(random) * unit(random));  // mostly small
    const Vec3 at(6.0 * unit(random), 6.0 * unit(random), 3.0 * unit(random));
    const Vec3 half = 0.5 * size * Vec3(0.2 + unit(random), 0.2 + unit(random), 0.2 + unit(random));
    boxes.push_back({at - half, at + half});
    fixed.push_back(unit(random) < 0.05 ? 1 : 0);
  }
  // Exact contact: a box whose face lies on another's.
  boxes.push_back({Vec3(boxes[0].max.x(), boxes[0].min.y(), boxes[0].min.z()),
                   Vec3(boxes[0].max.x() + 0.1, boxes[0].max.y(), boxes[0].max.z())});
  fixed.push_back(0);
  boxes.push_back({Vec3::Constant(1e9), Vec3::Constant(1e9 + 1.0)});  // far out: clamped cells
  fixed.push_back(0);
  // Far out below, at the lowest x: the first cell of the grid, clamped along y.
  boxes.push_back({Vec3(-0.5, -1e9, 1.0), Vec3(-0.4, -1e9 + 0.1, 1.1)});
  fixed.push_back(0);
  boxes.push_back({Vec3(-0.45, -1e9 + 0.05, 1.05), Vec3(-0.3, -1e9 + 0.2, 1.2)});  // overlapping it
  fixed.push_back(0);
  boxes.push_back({Vec3::Constant(std::numeric_limits<double>::quiet_NaN()), Vec3::Constant(1.0)});
  fixed.push_back(0);
  boxes.push_back({Vec3(-std::numeric_limits<double>::infinity(), 1.0, 1.0), Vec3(2.0, 2.0, 2.0)});
  fixed.push_back(0);
  // Finite corners whose extent overflows to infinity.
  boxes.push_back({Vec3(-1.5e308, 3.0, 1.0), Vec3(1.5e308, 3.2, 1.2)});
  fixed.push_back(0);
  return boxes;
}

TEST(Broadphase, FindsExactlyTheOverlappingPairsOnce) {
  std::mt19937_64 random(7);
  for (int round = 0; round < 4; ++round) {
    std::vector<char> fixed;
    std::vector<Aabb> boxes = mixed_boxes(random, fixed, 600);
    Broadphase broadphase;
    for (BodyIndex i = 0; i < boxes.size(); ++i) broadphase.add(i, fixed[i] != 0, boxes[i]);
    broadphase.finish();
    const std::vector<BodyPair> expected = brute_force(boxes, fixed);
    ASSERT_GT(expected.size(), 100u);
    EXPECT_EQ(collected(broadphase), expected) << "round " << round;
    // Moved boxes: the next collect() sees them (the movable ones move; the grid is rebuilt).
    std::uniform_real_distribution<double> shift(-0.3, 0.3);
    for (BodyIndex i = 0; i + 4 < boxes.size(); ++i) {
      if (fixed[i]) continue;
      const Vec3 d(shift(random), shift(random), shift(random));
      boxes[i] = {boxes[i].min + d, boxes[i].max + d};
      broadphase.move(i, boxes[i]);
    }
    EXPECT_EQ(collected(broadphase), brute_force(boxes, fixed)) << "round " << round << ", moved";
  }
}

TEST(Broadphase, IdenticalBodiesAtOnePointStopAtTheLimit) {
  Broadphase broadphase;
  constexpr BodyIndex kBodies = 200;
  for (BodyIndex i = 0; i < kBodies; ++i) broadphase.add(i, false, {Vec3::Zero(), Vec3::Ones()});
  broadphase.finish();
  std::vector<BodyPair> pairs;
  EXPECT_FALSE(broadphase.collect(pairs, 1000));
  EXPECT_EQ(pairs.size(), 1000u);
  pairs.clear();
  EXPECT_TRUE(broadphase.collect(pairs, kBodies * kBodies));
  EXPECT_EQ(pairs.size(), kBodies * (kBodies - 1) / 2);
}

TEST(Broadphase, TwoFixedBodiesNeverPair) {
  Broadphase broadphase;
  broadphase.add(0, true, {Vec3::Zero(), Vec3::Ones()});
  broadphase.add(1, true, {Vec3::Zero(), Vec3::Ones()});
  broadphase.add(2, false, {Vec3::Constant(0.5), Vec3::Constant(1.5)});
  broadphase.finish();
  EXPECT_EQ(collected(broadphase), (std::vector<BodyPair>{{0, 2}, {1, 2}}));
}

}  // namespace
}  // namespace impetus::test
