// The broadphase (broadphase.hpp): a hierarchy of uniform grids, rebuilt at every collect(). Each body is
// entered once, in the cell of its box's lower corner; a level's cell is larger than each of its boxes,
// so boxes that overlap have their corners in the same or neighbouring cells. The cells are sorted by
// a key ordered as (x, y, z), so the neighbours of the cells, taken in order, come in order too: one
// cursor per neighbour direction walks the sorted cells, and no lookup is needed.
#include "impetus/detection/fcl/broadphase.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>

namespace impetus::collision {
namespace {

// A level holds boxes up to this multiple of the median box size of the bodies it is chosen from.
constexpr double kLevelSpread = 2.0;
// A level's cell is this much larger than its largest box: room for the rounding of x / size, so that
// the corners of overlapping boxes never land two cells apart.
constexpr double kCellSlack = 1.01;
// Levels at most (at least half of the bodies join each level, so 33 hold 2³² bodies); the rest, if
// any, are tested against every body.
constexpr std::size_t kMaxLevels = 40;
// Insertion sort of a level's entries in their last order: at most this many moves per entry.
constexpr std::size_t kInsertionMoves = 4;
// Up to this many bodies, every pair is tested (no grid).
constexpr std::size_t kFewBodies = 32;
// The pair search's tasks (collect()): this many cells of a level, or bodies against coarser levels.
// Small enough that a pile of a thousand bodies (one level of ~700 cells) gives a dozen tasks to share
// among the threads (with 2,048 cells per task it gave one, and the search ran on one thread); a task
// costs a binary search per direction to place its cursors.
constexpr std::size_t kCellsPerTask = 64;
constexpr std::size_t kBodiesPerTask = 128;
// Cell coordinates are clamped to [−2²⁰, 2²⁰) (21 bits each, packed into one key). Clamping keeps
// overlapping boxes' corners within one cell of each other, so boxes beyond cost more tests only
// (200 km from the origin for 10 cm bodies).
constexpr std::int64_t kCellBits = 21;
constexpr std::int64_t kCellRange = std::int64_t{1} << kCellBits;  // cells per axis
constexpr std::int64_t kCellOffset = kCellRange / 2;

inline bool boxes_overlap(const Aabb& a, const Aabb& b) {
  return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

// The cell of x along one axis, 0 … kCellRange − 1.
std::int64_t cell_of(double x, double inverse_size) {
  const double c = std::floor(x * inverse_size) + static_cast<double>(kCellOffset);
  if (!(c > 0.0)) return 0;  // also NaN
  if (!(c < static_cast<double>(kCellRange - 1))) return kCellRange - 1;
  return static_cast<std::int64_t>(c);
}

std::uint64_t pack(std::int64_t x, std::int64_t y, std::int64_t z) {
  return static_cast<std::uint64_t>((x << (2 * kCellBits)) | (y << kCellBits) | z);
}

// The 13 neighbouring cells "after" a cell (offsets lexicographically above (0, 0, 0)): with the cell
// itself, every pair of neighbouring cells is visited from exactly one of the two.
struct Offset {
  int x, y, z;
};
constexpr Offset kForward[13] = {{0, 0, 1},  {0, 1, -1}, {0, 1, 0},  {0, 1, 1},  {1, -1, -1}, {1, -1, 0}, {1, -1, 1},
                                 {1, 0, -1}, {1, 0, 0},  {1, 0, 1},  {1, 1, -1}, {1, 1, 0},   {1, 1, 1}};

}  // namespace

struct Broadphase::Impl {
  struct Entry {
    std::uint64_t key;  // the cell of the box's lower corner, packed
    BodyIndex body;
    bool operator<(const Entry& o) const { return key != o.key ? key < o.key : body < o.body; }
  };
  struct Cell {
    std::uint64_t key;
    std::uint32_t begin, end;  // its entries
  };
  // One grid: its cell size, its bodies' entries sorted by cell, and the occupied cells in order.
  struct Level {
    double inverse = 1.0;  // 1 / cell size
    std::vector<BodyIndex> members, last_members;  // this collect()'s and the last one's
    std::vector<Entry> entries;
    std::vector<Cell> cells;
  };
  // Where a search appends its pairs, lower index first, and how many it may hold.
  struct Sink {
    std::vector<BodyPair>* pairs;
    std::size_t cap;
    bool add(BodyIndex a, BodyIndex b) {
      if (pairs->size() >= cap) return false;
      pairs->emplace_back(std::min(a, b), std::max(a, b));
      return true;
    }
  };
  // A piece of the pair search: cells [begin, end) of a level (each with itself and the cells after
  // it), or members [begin, end) of a level against the coarser levels, or the unbounded boxes.
  struct Task {
    enum class Kind { within, coarser, unbounded } kind;
    std::size_t level, begin, end;
  };

  std::vector<BodyIndex> bodies;  // registered, increasing
  std::vector<char> fixed;        // by body index
  std::vector<Aabb> boxes;        // by body index
  // Scratch of collect(), kept so a stable scene allocates nothing.
  std::vector<double> extents;
  std::vector<BodyIndex> remaining, coarser, unbounded;
  std::vector<Level> levels;
  std::size_t level_count = 0;
  std::vector<Task> tasks;
  std::vector<std::vector<BodyPair>> found;  // by task

  void place_levels();
  void build_level(Level& level, double size);
  bool pairs_within(const Level& level, std::size_t begin, std::size_t end, Sink& sink) const;
  bool pairs_with_coarser(std::size_t l, std::size_t begin, std::size_t end, Sink& sink) const;
  bool pairs_unbounded(Sink& sink) const;
  bool run(const Task& task, Sink& sink) const;
  bool test(BodyIndex a, BodyIndex b, Sink& sink) const {
    return (fixed[a] && fixed[b]) || !boxes_overlap(boxes[a], boxes[b]) || sink.add(a, b);
  }
  // Every entry of cell `c` against every entry of cell `d` of the same level.
  bool cells_against(const Level& level, const Cell& c, const Cell& d, Sink& sink) const {
    for (std::uint32_t i = c.begin; i < c.end; ++i)
      for (std::uint32_t j = d.begin; j < d.end; ++j)
        if (!test(level.entries[i].body, level.entries[j].body, sink)) return false;
    return true;
  }
};

// The level's entries sorted by cell (then body), and its occupied cells. Bodies move little from one
// step to the next: when the level has the same members as at the last collect(), the entries are
// re-keyed in their last order and insertion-sorted (linear when few changed cells), falling back to a
// full sort past kInsertionMoves moves per entry.
void Broadphase::Impl::build_level(Level& level, double size) {
  level.inverse = 1.0 / size;
  const auto key_of = [&](BodyIndex body) {
    const Vec3& corner = boxes[body].min;
    return pack(cell_of(corner.x(), level.inverse), cell_of(corner.y(), level.inverse),
                cell_of(corner.z(), level.inverse));
  };
  bool sorted = false;
  if (level.members == level.last_members && level.entries.size() == level.members.size()) {
    for (Entry& e : level.entries) e.key = key_of(e.body);
    std::size_t moves = 0;
    const std::size_t budget = kInsertionMoves * level.entries.size();
    sorted = true;
    for (std::size_t i = 1; i < level.entries.size() && sorted; ++i) {
      const Entry e = level.entries[i];
      std::size_t j = i;
      for (; j > 0 && e < level.entries[j - 1]; --j) level.entries[j] = level.entries[j - 1];
      level.entries[j] = e;
      moves += i - j;
      sorted = moves <= budget;
    }
  }
  if (!sorted) {
    level.entries.clear();
    for (const BodyIndex body : level.members) level.entries.push_back({key_of(body), body});
    std::sort(level.entries.begin(), level.entries.end());
  }
  level.last_members.assign(level.members.begin(), level.members.end());
  level.cells.clear();
  for (std::uint32_t i = 0; i < level.entries.size(); ++i) {
    if (level.cells.empty() || level.cells.back().key != level.entries[i].key)
      level.cells.push_back({level.entries[i].key, i, i});
    level.cells.back().end = i + 1;
  }
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

// Levels: a level takes the bodies not yet placed whose largest box extent is at most kLevelSpread times
// the median of theirs (at least half: at most log₂ n + 1 levels, and one for bodies of similar sizes);
// its cell is kCellSlack times the largest of its boxes. A box with a non-finite corner or extent (two
// finite corners 1e308 apart) is tested against every body (NaN boxes overlap nothing).
void Broadphase::Impl::place_levels() {
  level_count = 0;
  unbounded.clear();
  remaining.clear();
  for (const BodyIndex b : bodies) {
    const Aabb& box = boxes[b];
    const bool bounded = box.min.allFinite() && box.max.allFinite() && std::isfinite((box.max - box.min).maxCoeff());
    (bounded ? remaining : unbounded).push_back(b);
  }
  while (!remaining.empty()) {
    extents.clear();
    for (const BodyIndex b : remaining) extents.push_back((boxes[b].max - boxes[b].min).maxCoeff());
    const auto middle = extents.begin() + static_cast<std::ptrdiff_t>(extents.size() / 2);
    std::nth_element(extents.begin(), middle, extents.end());
    const double bound = kLevelSpread * *middle;
    if (levels.size() <= level_count) levels.emplace_back();
    Level& level = levels[level_count++];
    level.members.clear();
    coarser.clear();
    double largest = 0.0;
    for (const BodyIndex b : remaining) {
      const double extent = (boxes[b].max - boxes[b].min).maxCoeff();
      if (extent <= bound) {
        level.members.push_back(b);
        largest = std::max(largest, extent);
      } else if (level_count < kMaxLevels) {
        coarser.push_back(b);
      } else {
        unbounded.push_back(b);  // never for a finite scene: at least half of the bodies join each level
      }
    }
    // A cell of any positive size holds boxes of zero extent.
    build_level(level, largest > 0.0 && std::isfinite(largest) ? kCellSlack * largest : 1.0);
    remaining.swap(coarser);
  }
  std::sort(unbounded.begin(), unbounded.end());
}

// Cells [begin, end) of a level: each against itself and the 13 cells after it. A cell's neighbour in a
// direction has the key key + (offset packed), which grows with the cell's own key, so one cursor per
// direction finds it by walking forward; a neighbour beyond the grid's edge does not exist.
bool Broadphase::Impl::pairs_within(const Level& level, std::size_t begin, std::size_t end, Sink& sink) const {
  const std::vector<Cell>& cells = level.cells;
  const auto key_less = [](const Cell& c, std::uint64_t key) { return c.key < key; };
  std::size_t cursor[13];
  bool placed[13] = {};  // a cursor is placed by a binary search the first time its direction is used
  for (std::size_t c = begin; c < end; ++c) {
    const Cell& cell = cells[c];
    for (std::uint32_t i = cell.begin; i < cell.end; ++i)
      for (std::uint32_t j = i + 1; j < cell.end; ++j)
        if (!test(level.entries[i].body, level.entries[j].body, sink)) return false;
    const auto x = static_cast<std::int64_t>(cell.key >> (2 * kCellBits));
    const auto y = static_cast<std::int64_t>((cell.key >> kCellBits) & (kCellRange - 1));
    const auto z = static_cast<std::int64_t>(cell.key & (kCellRange - 1));
    for (int d = 0; d < 13; ++d) {
      const Offset& o = kForward[d];
      const std::int64_t nx = x + o.x, ny = y + o.y, nz = z + o.z;
      if (nx >= kCellRange || ny < 0 || ny >= kCellRange || nz < 0 || nz >= kCellRange) continue;
      const std::uint64_t key = pack(nx, ny, nz);
      std::size_t& k = cursor[d];
      if (!placed[d]) {
        k = static_cast<std::size_t>(std::lower_bound(cells.begin() + static_cast<std::ptrdiff_t>(c), cells.end(), key,
                                                      key_less) - cells.begin());
        placed[d] = true;
      }
      while (k < cells.size() && cells[k].key < key) ++k;
      if (k < cells.size() && cells[k].key == key && !cells_against(level, cell, cells[k], sink)) return false;
    }
  }
  return true;
}

// Members [begin, end) of level l against every coarser level: the 27 cells there around their corner's
// cell (a coarser cell is larger than both boxes).
bool Broadphase::Impl::pairs_with_coarser(std::size_t l, std::size_t begin, std::size_t end, Sink& sink) const {
  const auto key_less = [](const Cell& c, std::uint64_t key) { return c.key < key; };
  for (std::size_t c = l + 1; c < level_count; ++c) {
    const Level& coarse = levels[c];
    for (std::size_t m = begin; m < end; ++m) {
      const BodyIndex a = levels[l].members[m];
      const Vec3& corner = boxes[a].min;
      const std::int64_t x = cell_of(corner.x(), coarse.inverse), y = cell_of(corner.y(), coarse.inverse),
                         z = cell_of(corner.z(), coarse.inverse);
      for (std::int64_t nx = std::max<std::int64_t>(0, x - 1); nx <= std::min(kCellRange - 1, x + 1); ++nx)
        for (std::int64_t ny = std::max<std::int64_t>(0, y - 1); ny <= std::min(kCellRange - 1, y + 1); ++ny) {
          // The three cells along z are consecutive keys.
          const std::uint64_t first = pack(nx, ny, std::max<std::int64_t>(0, z - 1));
          const std::uint64_t last = pack(nx, ny, std::min(kCellRange - 1, z + 1));
          for (auto it = std::lower_bound(coarse.cells.begin(), coarse.cells.end(), first, key_less);
               it != coarse.cells.end() && it->key <= last; ++it)
            for (std::uint32_t j = it->begin; j < it->end; ++j)
              if (!test(a, coarse.entries[j].body, sink)) return false;
        }
    }
  }
  return true;
}

// Unbounded boxes against every body.
bool Broadphase::Impl::pairs_unbounded(Sink& sink) const {
  for (const BodyIndex a : unbounded)
    for (const BodyIndex b : bodies) {
      if (b == a) continue;
      if (b < a && std::binary_search(unbounded.begin(), unbounded.end(), b)) continue;  // from b's turn
      if (!test(a, b, sink)) return false;
    }
  return true;
}

bool Broadphase::Impl::run(const Task& task, Sink& sink) const {
  switch (task.kind) {
    case Task::Kind::within: return pairs_within(levels[task.level], task.begin, task.end, sink);
    case Task::Kind::coarser: return pairs_with_coarser(task.level, task.begin, task.end, sink);
    case Task::Kind::unbounded: return pairs_unbounded(sink);
  }
  return true;
}

// The search is cut into tasks of a fixed size (the cut depends on the scene, never on the threads)
// that run in parallel, each into its own list, joined in task order. Each list may hold its share of
// the limit; if one fills up, the search is run again on one thread against the whole limit, so the
// partial list (the detector names the most crowded body from it) does not depend on the threads either.
bool Broadphase::collect(std::vector<BodyPair>& pairs, std::size_t limit) {
  Impl& s = *impl_;
  if (s.bodies.size() <= kFewBodies) {  // every pair: cheaper than building a grid
    Impl::Sink sink{&pairs, limit};
    for (std::size_t i = 0; i < s.bodies.size(); ++i)
      for (std::size_t j = i + 1; j < s.bodies.size(); ++j)
        if (!s.test(s.bodies[i], s.bodies[j], sink)) return false;
    return true;
  }
  s.place_levels();
  s.tasks.clear();
  for (std::size_t l = 0; l < s.level_count; ++l) {
    const std::size_t cells = s.levels[l].cells.size(), members = s.levels[l].members.size();
    for (std::size_t c = 0; c < cells; c += kCellsPerTask)
      s.tasks.push_back({Impl::Task::Kind::within, l, c, std::min(cells, c + kCellsPerTask)});
    if (l + 1 < s.level_count)
      for (std::size_t m = 0; m < members; m += kBodiesPerTask)
        s.tasks.push_back({Impl::Task::Kind::coarser, l, m, std::min(members, m + kBodiesPerTask)});
  }
  if (!s.unbounded.empty()) s.tasks.push_back({Impl::Task::Kind::unbounded, 0, 0, 0});
  if (limit == 0) return s.tasks.empty();
  if (s.found.size() < s.tasks.size()) s.found.resize(s.tasks.size());
  const std::size_t share = (limit - 1) / std::max<std::size_t>(1, s.tasks.size()) + 1;  // ⌈limit / tasks⌉
  std::atomic<bool> full{false};
  const auto run_tasks = [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t t = range.begin(); t != range.end(); ++t) {
      s.found[t].clear();
      Impl::Sink sink{&s.found[t], share};
      if (!s.run(s.tasks[t], sink)) full = true;
    }
  };
  if (s.tasks.size() > 1) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.tasks.size(), 1), run_tasks);
  else run_tasks(tbb::blocked_range<std::size_t>(0, s.tasks.size(), 1));
  if (full) {
    Impl::Sink sink{&pairs, limit};
    for (const Impl::Task& task : s.tasks)
      if (!s.run(task, sink)) return false;
    return true;
  }
  for (std::size_t t = 0; t < s.tasks.size(); ++t) {
    if (pairs.size() + s.found[t].size() > limit) {  // the shares add up to more than the limit
      pairs.insert(pairs.end(), s.found[t].begin(), s.found[t].begin() + static_cast<std::ptrdiff_t>(limit - pairs.size()));
      return false;
    }
    pairs.insert(pairs.end(), s.found[t].begin(), s.found[t].end());
  }
  return true;
}

}  // namespace impetus::collision
