// The broadphase (broadphase.hpp): a hierarchy of uniform grids, rebuilt at every collect() by a counting
// sort of (cell, body) entries into hashed buckets.
#include "impetus/detection/fcl/broadphase.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace impetus::collision {
namespace {

// A body whose box spans more cells than this goes to a coarser level. 27: a body up to twice the
// cell size, wherever it lies.
constexpr std::int64_t kMaxCellsPerBody = 27;
// Cell coordinates are clamped to ±kCellLimit (boxes 2⁴⁰ cells from the origin share the border cells:
// only more box tests, never a missed pair).
// Levels at most (at least half of the bodies join each level, so 33 hold 2³² bodies); the rest, if any,
// are tested against every body.
constexpr std::size_t kMaxLevels = 40;
constexpr double kCellLimit = 1099511627776.0;  // 2⁴⁰

inline bool boxes_overlap(const Aabb& a, const Aabb& b) {
  return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

std::int64_t cell_of(double x, double inverse_size) {
  const double c = std::floor(x * inverse_size);
  if (!(c > -kCellLimit)) return static_cast<std::int64_t>(-kCellLimit);  // also NaN
  if (!(c < kCellLimit)) return static_cast<std::int64_t>(kCellLimit);
  return static_cast<std::int64_t>(c);
}

std::uint64_t bucket_hash(std::int64_t x, std::int64_t y, std::int64_t z) {
  std::uint64_t h = static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ULL;
  h ^= static_cast<std::uint64_t>(y) * 0xC2B2AE3D27D4EB4FULL + (h << 6) + (h >> 2);
  h ^= static_cast<std::uint64_t>(z) * 0x165667B19E3779F9ULL + (h << 6) + (h >> 2);
  return h ^ (h >> 29);
}

}  // namespace

struct Broadphase::Impl {
  struct Entry {
    std::int64_t x, y, z;  // the cell
    BodyIndex body;
  };
  // One grid: its cell size, its bodies' entries sorted into hashed buckets.
  struct Level {
    double inverse = 1.0;  // 1 / cell size
    std::uint64_t mask = 0;
    std::vector<BodyIndex> members;
    std::vector<Entry> sorted;
    std::vector<std::uint32_t> start;  // bucket b's entries: sorted[start[b] .. start[b + 1])
  };
  std::vector<BodyIndex> bodies;  // registered, increasing
  std::vector<char> fixed;        // by body index
  std::vector<Aabb> boxes;        // by body index
  // Scratch of collect(), kept so a stable scene allocates nothing.
  std::vector<double> extents;
  std::vector<BodyIndex> remaining, coarser, unbounded;
  std::vector<Entry> entries;
  std::vector<Level> levels;
  std::size_t level_count = 0;

  void build_level(Level& level, double size);
  // Calls visit(body) for every body of `level` whose entry is in the cell (x, y, z); stops when it returns false.
  template <typename Visit>
  bool in_cell(const Level& level, std::int64_t x, std::int64_t y, std::int64_t z, Visit&& visit) const {
    const std::uint64_t b = bucket_hash(x, y, z) & level.mask;
    for (std::uint32_t k = level.start[b]; k < level.start[b + 1]; ++k) {
      const Entry& e = level.sorted[k];
      if (e.x == x && e.y == y && e.z == z && !visit(e.body)) return false;
    }
    return true;
  }
};

// The level's entries (one per cell a member's box covers) counting-sorted into buckets by the hash of
// their cell; a bucket keeps its entries in the members' order.
void Broadphase::Impl::build_level(Level& level, double size) {
  level.inverse = 1.0 / size;
  entries.clear();
  for (const BodyIndex body : level.members) {
    const Aabb& box = boxes[body];
    const std::int64_t x0 = cell_of(box.min.x(), level.inverse), x1 = cell_of(box.max.x(), level.inverse);
    const std::int64_t y0 = cell_of(box.min.y(), level.inverse), y1 = cell_of(box.max.y(), level.inverse);
    const std::int64_t z0 = cell_of(box.min.z(), level.inverse), z1 = cell_of(box.max.z(), level.inverse);
    for (std::int64_t x = x0; x <= x1; ++x)
      for (std::int64_t y = y0; y <= y1; ++y)
        for (std::int64_t z = z0; z <= z1; ++z) entries.push_back({x, y, z, body});
  }
  std::size_t buckets = 16;
  while (buckets < 2 * entries.size()) buckets *= 2;
  level.mask = buckets - 1;
  level.start.assign(buckets + 1, 0);
  for (const Entry& e : entries) ++level.start[(bucket_hash(e.x, e.y, e.z) & level.mask) + 1];
  for (std::size_t b = 0; b < buckets; ++b) level.start[b + 1] += level.start[b];
  level.sorted.resize(entries.size());
  for (const Entry& e : entries) level.sorted[level.start[bucket_hash(e.x, e.y, e.z) & level.mask]++] = e;
  for (std::size_t b = buckets; b > 0; --b) level.start[b] = level.start[b - 1];  // restore the starts
  level.start[0] = 0;
}

Broadphase::Broadphase() : impl_(std::make_unique<Impl>()) {}
Broadphase::~Broadphase() = default;

void Broadphase::clear() { impl_ = std::make_unique<Impl>(); }

void Broadphase::add(BodyIndex index, bool fixed, const Aabb& box) {
  Impl& s = *impl_;
  if (s.boxes.size() <= index) {
    s.boxes.resize(index + 1, Aabb{Vec3::Zero(), Vec3::Zero()});
    s.fixed.resize(index + 1, 0);
  }
  s.boxes[index] = box;
  s.fixed[index] = fixed ? 1 : 0;
  s.bodies.push_back(index);
}

void Broadphase::finish() {
  Impl& s = *impl_;
  std::sort(s.bodies.begin(), s.bodies.end());
  s.extents.reserve(s.bodies.size());
  s.remaining.reserve(s.bodies.size());
  s.coarser.reserve(s.bodies.size());
}

void Broadphase::move(BodyIndex index, const Aabb& box) { impl_->boxes[index] = box; }

// Levels: the cell size of a level is twice the median of the largest box extents of the bodies not yet
// placed; a body whose box spans at most kMaxCellsPerBody cells joins it, the others go on to the next
// (at least half join, so there are at most log₂ n + 1 levels; one for bodies of similar sizes). A box
// with a non-finite extent is tested against every body (NaN boxes overlap nothing). A pair is reported once: from the finer of the
// two bodies' levels, in the cell (of the coarser level) that holds the lower corner of the boxes'
// intersection, which both boxes cover.
bool Broadphase::collect(std::vector<BodyPair>& pairs, std::size_t limit) {
  Impl& s = *impl_;
  s.level_count = 0;
  s.unbounded.clear();
  s.remaining.clear();
  for (const BodyIndex b : s.bodies) {
    const Aabb& box = s.boxes[b];
    if (box.min.allFinite() && box.max.allFinite()) s.remaining.push_back(b);
    else s.unbounded.push_back(b);
  }
  while (!s.remaining.empty()) {
    s.extents.clear();
    for (const BodyIndex b : s.remaining) s.extents.push_back((s.boxes[b].max - s.boxes[b].min).maxCoeff());
    const auto middle = s.extents.begin() + static_cast<std::ptrdiff_t>(s.extents.size() / 2);
    std::nth_element(s.extents.begin(), middle, s.extents.end());
    double size = 2.0 * *middle;
    if (!(size > 0.0) || !std::isfinite(size)) size = 1.0;
    const double inverse = 1.0 / size;
    if (s.levels.size() <= s.level_count) s.levels.emplace_back();
    Impl::Level& level = s.levels[s.level_count++];
    level.members.clear();
    s.coarser.clear();
    for (const BodyIndex b : s.remaining) {
      const Aabb& box = s.boxes[b];
      std::int64_t span = 1;
      for (int axis = 0; axis < 3; ++axis)
        span *= std::min<std::int64_t>(cell_of(box.max(axis), inverse) - cell_of(box.min(axis), inverse) + 1,
                                       kMaxCellsPerBody + 1);
      if (span <= kMaxCellsPerBody) level.members.push_back(b);
      else if (s.level_count < kMaxLevels) s.coarser.push_back(b);
      else s.unbounded.push_back(b);  // never for a finite scene: at least half of the bodies join each level
    }
    s.build_level(level, size);
    s.remaining.swap(s.coarser);
  }
  std::sort(s.unbounded.begin(), s.unbounded.end());
  const auto report = [&](BodyIndex a, BodyIndex b) {
    if (pairs.size() >= limit) return false;
    pairs.emplace_back(std::min(a, b), std::max(a, b));
    return true;
  };
  for (std::size_t l = 0; l < s.level_count; ++l) {
    const Impl::Level& level = s.levels[l];
    // Within the level: the entries of each cell against each other.
    for (std::size_t b = 0; b + 1 < level.start.size(); ++b) {
      for (std::uint32_t i = level.start[b]; i + 1 < level.start[b + 1]; ++i) {
        const Impl::Entry& ei = level.sorted[i];
        const Aabb& bi = s.boxes[ei.body];
        for (std::uint32_t j = i + 1; j < level.start[b + 1]; ++j) {
          const Impl::Entry& ej = level.sorted[j];
          if (ej.x != ei.x || ej.y != ei.y || ej.z != ei.z) continue;  // another cell in this bucket
          if (s.fixed[ei.body] && s.fixed[ej.body]) continue;
          const Aabb& bj = s.boxes[ej.body];
          if (!boxes_overlap(bi, bj)) continue;
          const Vec3 corner = bi.min.cwiseMax(bj.min);
          if (cell_of(corner.x(), level.inverse) != ei.x || cell_of(corner.y(), level.inverse) != ei.y ||
              cell_of(corner.z(), level.inverse) != ei.z)
            continue;  // reported from the cell of the intersection's lower corner
          if (!report(ei.body, ej.body)) return false;
        }
      }
    }
    // Against the coarser levels: the cells of those levels this level's boxes cover.
    for (std::size_t c = l + 1; c < s.level_count; ++c) {
      const Impl::Level& coarse = s.levels[c];
      for (const BodyIndex a : level.members) {
        const Aabb& ba = s.boxes[a];
        const std::int64_t x0 = cell_of(ba.min.x(), coarse.inverse), x1 = cell_of(ba.max.x(), coarse.inverse);
        const std::int64_t y0 = cell_of(ba.min.y(), coarse.inverse), y1 = cell_of(ba.max.y(), coarse.inverse);
        const std::int64_t z0 = cell_of(ba.min.z(), coarse.inverse), z1 = cell_of(ba.max.z(), coarse.inverse);
        for (std::int64_t x = x0; x <= x1; ++x)
          for (std::int64_t y = y0; y <= y1; ++y)
            for (std::int64_t z = z0; z <= z1; ++z) {
              const bool go_on = s.in_cell(coarse, x, y, z, [&](BodyIndex b) {
                if (s.fixed[a] && s.fixed[b]) return true;
                const Aabb& bb = s.boxes[b];
                if (!boxes_overlap(ba, bb)) return true;
                const Vec3 corner = ba.min.cwiseMax(bb.min);
                if (cell_of(corner.x(), coarse.inverse) != x || cell_of(corner.y(), coarse.inverse) != y ||
                    cell_of(corner.z(), coarse.inverse) != z)
                  return true;
                return report(a, b);
              });
              if (!go_on) return false;
            }
      }
    }
  }
  // Unbounded boxes against every body (NaN boxes overlap nothing).
  for (const BodyIndex a : s.unbounded)
    for (const BodyIndex b : s.bodies) {
      if (b == a || (s.fixed[a] && s.fixed[b])) continue;
      if (b < a && std::binary_search(s.unbounded.begin(), s.unbounded.end(), b)) continue;  // from b's turn
      if (boxes_overlap(s.boxes[a], s.boxes[b]) && !report(a, b)) return false;
    }
  return true;
}

}  // namespace impetus::collision
