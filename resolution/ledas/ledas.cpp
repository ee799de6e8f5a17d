// The LEDAS resolver's step: rows from contacts and constraints, islands, and per island the velocity
// phase (paper_rounds.cpp or complementary_impact.cpp), the report into the contacts and counters, and the
// position correction (position_correction.cpp).
#include "island.hpp"
#include "lane.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>
#include <string>
#include <utility>

namespace impetus {

namespace {

bool valid_contact(const Contact& c, std::size_t body_count) {
  return c.a < body_count && c.b < body_count && c.a != c.b && all_finite(c.point) && all_finite(c.normal) &&
         std::isfinite(c.depth) && std::abs(c.normal.norm() - 1.0) < 1e-6;
}

}  // namespace

void add(LedasStats& into, const LedasStats& part) {
  into.islands += part.islands;
  into.largest_island = std::max(into.largest_island, part.largest_island);
  into.rounds = std::max(into.rounds, part.rounds);
  into.systems += part.systems;
  into.pulling_applied += part.pulling_applied;
  ledas::add(into.velocity, part.velocity);
  ledas::add(into.position, part.position);
  into.kinetic_energy_change += part.kinetic_energy_change;
  ledas::add(into.friction, part.friction);
  into.restitution_capped += part.restitution_capped;
  into.corrections_clamped += part.corrections_clamped;
  into.duplicate_constraints += part.duplicate_constraints;
  into.largest_correction = std::max(into.largest_correction, part.largest_correction);
}

LedasResolver::LedasResolver(const ModuleOptions& options) : LedasResolver(LedasSettings::from_options(options)) {}

LedasResolver::LedasResolver(const LedasSettings& settings) : settings_(settings), solver_settings_([&] {
  ledas::SolverSettings s = settings.solver;
  s.max_iterations = settings.max_rounds;
  return s;
}()) {}

LedasResolver::~LedasResolver() = default;

// A body's lane: the top bits of its index times 2⁶⁴/φ (Fibonacci hashing), so that neighbouring
// indices, as a pile's or a heap's islands have, spread over the lanes.
std::size_t LedasResolver::lane_of(BodyIndex body) {
  static_assert(kLanes == 256, "the shift below takes log2(kLanes) bits");
  return static_cast<std::size_t>((std::uint64_t{body} * 0x9E3779B97F4A7C15ULL) >> 56);
}

LedasResolver::Lane& LedasResolver::lane(std::size_t index) {
  if (lanes_.size() <= index) lanes_.resize(index + 1);
  if (!lanes_[index]) lanes_[index] = std::make_unique<Lane>(solver_settings_);
  return *lanes_[index];
}

ModuleStatus LedasResolver::accept_constraints(std::span<const Constraint> constraints) noexcept {
  for (std::size_t i = 0; i < constraints.size(); ++i) {
    try {
      if (std::string why = ledas::constraint_problem(constraints[i]); !why.empty())
        return ModuleStatus::failure("constraint #" + std::to_string(i) + ": " + why);
    } catch (...) {
      return ModuleStatus::failure("constraint #" + std::to_string(i) + ": could not be checked");
    }
  }
  return ModuleStatus::success();
}

ModuleStatus LedasResolver::accept_friction() noexcept {
  if (settings_.mode == LedasMode::paper)
    return ModuleStatus::failure(
        "ledas in paper mode does not model friction (the paper gives no friction formulas for its rounds; "
        "use mode: complementary)");
  return ModuleStatus::success();
}

void LedasResolver::resolve(std::span<RigidBody> bodies, std::span<Contact> contacts,
                            std::span<const Constraint> constraints, const StepContext& ctx,
                            ResolverCounters& counters) noexcept {
  stats_ = LedasStats{};
  try {
    resolve_all(bodies, contacts, constraints, ctx, counters);
  } catch (...) {  // out of memory: nothing may cross the plugin boundary; the step reports it
    ++counters.non_converged;
  }
  counters.rounds += stats_.systems;
  counters.pulling_impulses += stats_.pulling_applied + stats_.velocity.released;
  // A velocity problem without a solution (conflicting joint targets) fails the step's promise; a
  // position correction without one (a body squeezed between fixed bodies) is corrected as far as it
  // can be, and shows only in last_stats().position.infeasible.
  counters.rounds += stats_.friction.newton_steps + stats_.friction.interior_point_steps +
                     stats_.friction.coulomb_interior_point_steps + stats_.friction.fallback_sweeps;
  counters.non_converged += stats_.velocity.non_converged + stats_.velocity.infeasible + stats_.position.non_converged +
                            stats_.friction.non_converged;
  counters.natural_map_residual = std::max(counters.natural_map_residual, stats_.friction.residual);
  // Rank-deficient systems the minimum-norm impulses satisfied are redundant contact sets (normal);
  // only those they did not satisfy are singular (a failure).
  const std::uint64_t rank_deficient = stats_.velocity.singular + stats_.position.singular;
  const std::uint64_t failed = stats_.velocity.inconsistent + stats_.position.inconsistent;
  counters.singular_systems += failed;
  counters.redundant_systems += rank_deficient - failed;
  counters.nan_caught += stats_.velocity.nan_caught + stats_.position.nan_caught + stats_.friction.nan_caught;
  counters.work_limited += stats_.velocity.work_limited + stats_.position.work_limited;
  counters.corrections_clamped += stats_.corrections_clamped;
  counters.largest_correction = std::max(counters.largest_correction, stats_.largest_correction);
}

void LedasResolver::bodies_removed(std::span<const std::int64_t> new_index) noexcept {
  // Renumbering keeps a < b (removal preserves order), so the map's order is unchanged.
  const auto renumbered = [&](BodyIndex i) { return i < new_index.size() ? new_index[i] : std::int64_t{-1}; };
  std::size_t kept = 0;  // in place: renumbering keeps the order, so the list stays sorted
  for (const WarmStart& w : next_warm_) {
    const std::int64_t a = renumbered(w.key.a), b = renumbered(w.key.b);
    if (a >= 0 && b >= 0)
      next_warm_[kept++] = {ContactKey{static_cast<BodyIndex>(a), static_cast<BodyIndex>(b), w.key.feature}, w.impulse,
                            w.order};
  }
  next_warm_.resize(kept);
}

const LedasResolver::ContactImpulse* LedasResolver::find_warm(const ContactKey& key) const {
  const auto it = std::lower_bound(warm_.begin(), warm_.end(), key,
                                   [](const WarmStart& entry, const ContactKey& k) { return entry.key < k; });
  return it != warm_.end() && it->key == key ? &it->impulse : nullptr;
}

void LedasResolver::resolve_all(std::span<RigidBody> bodies, std::span<Contact> contacts,
                                std::span<const Constraint> constraints, const StepContext& ctx,
                                ResolverCounters& counters) {
  warm_.swap(next_warm_);
  next_warm_.clear();
  build_rows(bodies, contacts, constraints, ctx.dt, counters);
  resolution::find_islands(rows_, bodies.size(), bodies, islands_);
  body_slot_.assign(bodies.size(), -1);
  if (!settings_.islands) islands_.merge();  // one system for everything (benchmarks/model.cpp)
  // Each island goes to a lane by its first row's lower movable body (a hash of that body's index: see
  // lane_of), and the lanes run in parallel (in the caller's thread arena: the world's `threads`), each
  // on its islands in order. Islands share no movable body, so they write disjoint bodies, contacts and
  // body slots; everything else a lane writes is its own.
  // Each lane's load (Σ rows² of its islands, as a solve's cost grows faster than its rows) is counted
  // on the way, for the schedule below.
  const std::size_t n = islands_.size();
  lane_start_.assign(kLanes + 1, 0);
  lane_load_.assign(kLanes, 0.0);
  island_lane_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::span<const std::uint32_t> island = islands_.island(i);
    const resolution::ImpulseRow& first = rows_[island.front()];
    const BodyIndex body =
        bodies[first.a].fixed ? first.b : bodies[first.b].fixed ? first.a : std::min(first.a, first.b);
    const std::size_t k = lane_of(body);
    island_lane_[i] = k;
    ++lane_start_[k + 1];
    lane_load_[k] += static_cast<double>(island.size()) * static_cast<double>(island.size());
  }
  std::partial_sum(lane_start_.begin(), lane_start_.end(), lane_start_.begin());
  lane_islands_.resize(n);
  lane_next_.assign(lane_start_.begin(), lane_start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) lane_islands_[lane_next_[island_lane_[i]]++] = i;  // increasing per lane
  lane_order_.clear();
  for (std::size_t k = 0; k < kLanes; ++k) {
    if (lane_start_[k] == lane_start_[k + 1]) continue;
    lane_order_.push_back(k);
    Lane& l = lane(k);
    l.stats = LedasStats{};
    l.counters = ResolverCounters{};
    l.remembered.clear();
    l.islands_used = 0;
  }
  // Heaviest lanes first: a pile's one large island then starts at once instead of after the small ones
  // dealt before it, and the other threads take the small ones and its position correction
  // (solve_island) alongside. Only the schedule changes: each lane still solves its own islands in order.
  std::sort(lane_order_.begin(), lane_order_.end(), [&](std::size_t x, std::size_t y) {
    return lane_load_[x] > lane_load_[y] || (lane_load_[x] == lane_load_[y] && x < y);
  });
  const std::size_t used = lane_order_.size();
  const auto run_lanes = [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t j = range.begin(); j != range.end(); ++j) {
      const std::size_t k = lane_order_[j];
      for (std::size_t q = lane_start_[k]; q < lane_start_[k + 1]; ++q)
        solve_island(islands_.island(lane_islands_[q]), bodies, contacts, ctx.dt, *lanes_[k]);
    }
  };
  if (used > 1) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, used, 1), run_lanes, tbb::simple_partitioner());
  else run_lanes(tbb::blocked_range<std::size_t>(0, used, 1));
  // The lanes' results in lane order: the same sums whatever thread ran which lane.
  for (std::size_t k = 0; k < kLanes; ++k) {
    if (lane_start_[k] == lane_start_[k + 1]) continue;
    const Lane& l = *lanes_[k];
    add(stats_, l.stats);
    add(counters, l.counters);
    for (const auto& [key, impulse] : l.remembered) next_warm_.push_back({key, impulse, next_warm_.size()});
  }
  // Sorted by key, then order (std::sort, not stable_sort, which would allocate its buffer); of equal keys
  // (two contacts with one feature key) the last remembered is kept.
  std::sort(next_warm_.begin(), next_warm_.end(), [](const WarmStart& x, const WarmStart& y) {
    return x.key < y.key || (x.key == y.key && x.order < y.order);
  });
  const auto last_of_each = std::unique(next_warm_.rbegin(), next_warm_.rend(),
                                        [](const WarmStart& x, const WarmStart& y) { return x.key == y.key; });
  next_warm_.erase(next_warm_.begin(), last_of_each.base());
}

// The rows of this step: one per valid contact (eq. 5's direction, eq. 7's arms) and, in complementary
// mode, two tangent rows after it when its μ > 0; then the joints'.
void LedasResolver::build_rows(std::span<const RigidBody> bodies, std::span<Contact> contacts,
                               std::span<const Constraint> constraints, double dt, ResolverCounters& counters) {
  rows_.clear();
  info_.clear();
  row_warm_.clear();
  // At most three rows per contact and kMaxConstraintRows per constraint, reserved at once. Grown row by
  // row, the first step of a large scene copied its rows into fresh pages at every regrowth: the first
  // resolve of the pyramid K = 100 took 1,330 page faults to build its rows, 910 with the reserve (where a
  // fresh page costs ~10 µs, as on the machine of docs/benchmarks.md, 16 → 11 ms). Capacity beyond what
  // is written is never touched, and later steps keep it.
  const std::size_t most = 3 * contacts.size() + ledas::kMaxConstraintRows * constraints.size();
  rows_.reserve(most);
  info_.reserve(most);
  row_warm_.reserve(most);
  inertia_.reset(bodies.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    Contact& c = contacts[k];
    c.impulse = 0.0;
    c.tangent_impulse = Vec3::Zero();
    c.mode = ContactMode::separate;
    if (!valid_contact(c, bodies.size())) {
      ++counters.nan_caught;
      continue;
    }
    rows_.push_back(resolution::make_contact_row(bodies, inertia_, c));
    const ContactImpulse* warm = settings_.warm_start ? find_warm(ContactKey{c.a, c.b, c.feature}) : nullptr;
    const bool warmed = warm != nullptr;
    row_warm_.push_back(warmed ? warm->normal : 0.0);
    ledas::RowInfo ri;
    ri.depth = c.depth;
    ri.contact = static_cast<std::int64_t>(k);
    ri.friction = settings_.mode == LedasMode::complementary ? combined_friction(bodies[c.a], bodies[c.b]) : 0.0;
    info_.push_back(ri);
    if (ri.friction > 0.0) {
      Vec3 t[2];
      tangent_basis(c.normal, t[0], t[1]);
      for (std::uint8_t j = 0; j < 2; ++j) {
        rows_.push_back(resolution::make_row(bodies, inertia_, c.a, c.b, c.point, t[j]));
        row_warm_.push_back(warmed ? warm->tangent.dot(t[j]) : 0.0);
        ri.tangent = static_cast<std::uint8_t>(j + 1);
        info_.push_back(ri);
      }
    }
  }
  // The same joint given twice (or a thousand times) repeats its rows exactly: the velocities are those
  // of one copy (the minimum-norm split shares the impulse equally and moves nothing more), so only the
  // first copy enters the system, instead of a singular island solved at dense cubic cost.
  const std::vector<char> duplicate = ledas::duplicate_constraints(constraints);
  for (std::size_t i = 0; i < constraints.size(); ++i) {
    if (duplicate[i]) {
      ++stats_.duplicate_constraints;
      continue;
    }
    ledas::append_constraint_rows(bodies, inertia_, constraints[i], dt, rows_, info_);
  }
  row_warm_.resize(rows_.size(), 0.0);
}

// An island: its velocity phase (the impact) and its position correction. The two are independent
// problems on the same A: the correction's targets come from the contacts' depths, not from velocities,
// and it only moves positions, which the impact does not read. So on an island of at least
// kConcurrentRows rows, with a second thread in the arena, they are solved at once, each by its own
// solver; the correction is applied after both. Its result is the same bits either way.
void LedasResolver::solve_island(std::span<const std::uint32_t> rows, std::span<RigidBody> bodies,
                                 std::span<Contact> contacts, double dt, Lane& lane) {
  constexpr std::size_t kConcurrentRows = 64;  // below, a correction takes a few µs: too little to share
  ledas::Island& island = lane.next_island();
  make_island(rows, bodies, dt, island);
  bool corrected = false;
  const std::span<const RigidBody> seen(bodies);
  if (rows.size() >= kConcurrentRows && tbb::this_task_arena::max_concurrency() > 1) {
    tbb::parallel_invoke([&] { velocity_phase(island, bodies, contacts, lane); },
                         [&] { corrected = solve_correction(island, seen, lane); });
  } else {
    velocity_phase(island, bodies, contacts, lane);
    corrected = solve_correction(island, seen, lane);
  }
  if (corrected) apply_correction(island, bodies, lane);
  ++lane.counters.islands;
  ++lane.stats.islands;
  lane.stats.largest_island = std::max(lane.stats.largest_island, island.rows.size());
  lane.stats.rounds = std::max(lane.stats.rounds, island.rounds);
  for (BodyIndex body : island.bodies) body_slot_[body] = -1;
}

// The impact of one island (its mode's velocity phase), its report and its warm starts.
void LedasResolver::velocity_phase(ledas::Island& island, std::span<RigidBody> bodies, std::span<Contact> contacts,
                                   Lane& lane) {
  const double energy_before = ledas::kinetic_energy(bodies, island.bodies);
  if (settings_.mode == LedasMode::paper) velocity_paper(island, bodies, lane);
  else if (island.frictional) velocity_frictional(island, bodies, lane);
  else velocity_complementary(island, bodies, lane);
  const double energy_after = ledas::kinetic_energy(bodies, island.bodies);
  lane.stats.kinetic_energy_change += energy_after - energy_before;
  if (island.bouncing() && energy_after > energy_before * (1.0 + ledas::kRoundoff) + 1e-300)
    ++lane.counters.energy_gain_events;
  report_island(island, bodies, contacts, lane.counters);
  if (island.frictional && settings_.warm_start) remember_impulses(lane, island, contacts);
}

// After the velocity phase: each contact's total impulse (normal and tangential) and mode, and the
// counters' residual (the largest approach left below a contact's target), contacts, sticking and
// sliding, and complementarity. (The residual is accumulated in a local: the counters may alias the
// contacts written in the loop, which would keep it in memory.)
void LedasResolver::report_island(ledas::Island& island, std::span<const RigidBody> bodies, std::span<Contact> contacts,
                                  ResolverCounters& counters) {
  const ledas::Vector& v = current_velocities(island, bodies);
  double residual = counters.residual;
  std::uint64_t entered = 0, sticking = 0, sliding = 0;
  for (std::size_t i = 0; i < island.rows.size(); ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (!island.normal_row(i)) continue;
    residual = std::max(residual, island.target(ei) - v(ei));
    if (island.entered[i]) ++entered;
    Contact& c = contacts[static_cast<std::size_t>(info_[island.rows[i]].contact)];
    c.impulse = island.impulse_total(ei);
    Vec3 slip;
    if (island.mu[i] > 0.0) {  // tangent rows i + 1, i + 2 along t1, t2
      const resolution::ImpulseRow &t1 = rows_[island.rows[i + 1]], &t2 = rows_[island.rows[i + 2]];
      c.tangent_impulse = island.impulse_total(ei + 1) * t1.normal + island.impulse_total(ei + 2) * t2.normal;
      slip = v(ei + 1) * t1.normal + v(ei + 2) * t2.normal;
    } else {
      const Vec3 u = relative_velocity(c, bodies[c.a], bodies[c.b]);
      slip = u - u.dot(c.normal) * c.normal;
    }
    if (c.impulse != 0.0) {
      c.mode = slip.norm() <= settings_.tolerance ? ContactMode::stick : ContactMode::slide;
      ++(c.mode == ContactMode::stick ? sticking : sliding);
    }
  }
  counters.residual = residual;
  counters.contacts += entered;
  counters.sticking += sticking;
  counters.sliding += sliding;
  counters.complementarity_error = std::max(counters.complementarity_error, island.complementarity);
}

}  // namespace impetus
