#include "ledas/ledas.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <utility>

namespace impetus {

using ledas::RowIndex;
using ledas::SparseMatrix;
using ledas::Vector;
using resolution::ImpulseRow;

namespace {

// Relative rounding below which a negative impulse is not counted as pulling, and an energy rise not
// counted as a gain.
constexpr double kRoundoff = 1e-12;
// Position-correction problems are in metres; a violation below this is rounding.
constexpr double kPositionTolerance = 1e-12;
// Position-level joints are re-linearized round after round until the predicted gap is below this (m),
// or stops halving.
constexpr double kJointTolerance = 1e-9;

// Which movable bodies an island's rows join, both ways: per row its bodies' slots in the island's
// list of movable bodies (−1 for a fixed body), per body its rows (local indices, increasing; a row
// joining a body to itself listed once). Built once per island; the matrix, the paper mode's stale-row
// tracking and the complementary mode's start set read it.
struct Incidence {
  std::vector<std::array<std::int32_t, 2>> slots;
  std::vector<std::uint32_t> body_start, body_rows;

  Incidence() = default;
  Incidence(std::span<const ImpulseRow> rows, std::span<const std::uint32_t> island, std::size_t movable,
            std::span<const std::int32_t> slot_of_body) {
    const std::size_t m = island.size();
    slots.resize(m);
    body_start.assign(movable + 1, 0);
    for (std::size_t i = 0; i < m; ++i) {
      const ImpulseRow& r = rows[island[i]];
      slots[i] = {slot_of_body[r.a], slot_of_body[r.b]};
      for (std::size_t k = 0; k < 2; ++k)
        if (listed(i, k)) ++body_start[static_cast<std::size_t>(slots[i][k]) + 1];
    }
    for (std::size_t s = 0; s < movable; ++s) body_start[s + 1] += body_start[s];
    body_rows.resize(body_start.back());
    std::vector<std::uint32_t> fill(body_start.begin(), body_start.end() - 1);
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t k = 0; k < 2; ++k)
        if (listed(i, k)) body_rows[fill[static_cast<std::size_t>(slots[i][k])]++] = static_cast<std::uint32_t>(i);
  }
  // Whether row i's side k is a movable body not already listed for it as side 0.
  bool listed(std::size_t i, std::size_t k) const { return slots[i][k] >= 0 && !(k == 1 && slots[i][0] == slots[i][1]); }
  // The rows of body slot s.
  std::span<const std::uint32_t> rows_of(std::int32_t s) const {
    if (s < 0) return {};
    return {body_rows.data() + body_start[static_cast<std::size_t>(s)],
            body_rows.data() + body_start[static_cast<std::size_t>(s) + 1]};
  }
};

// A of eq. 7 over an island's rows (local indices), both triangles stored. A_ik ≠ 0 only where rows i
// and k share a movable body, so column k is the union of the row lists of k's (at most two) movable
// bodies, written in compressed form directly (no triplets, no sort of pairs). Each coupling is
// computed once, on and below the diagonal (i ≥ k); an entry above it (i < k) is copied from column i,
// whose entries below the diagonal are met in increasing row order as k grows. So A is exactly
// symmetric.
SparseMatrix assemble_matrix(std::span<const ImpulseRow> rows, std::span<const std::uint32_t> island,
                             const Incidence& incidence) {
  const std::size_t m = island.size();
  const auto list = [&](std::size_t k, std::size_t side) {
    return incidence.listed(k, side) ? incidence.rows_of(incidence.slots[k][side]) : std::span<const std::uint32_t>();
  };
  const auto em = static_cast<Eigen::Index>(m);
  SparseMatrix a(em, em);
  std::size_t nonzeros = 0;
  for (std::size_t k = 0; k < m; ++k) nonzeros += list(k, 0).size() + list(k, 1).size();
  a.resizeNonZeros(static_cast<Eigen::Index>(nonzeros));
  int* outer = a.outerIndexPtr();
  int* inner = a.innerIndexPtr();
  double* value = a.valuePtr();
  std::vector<int> below(m);  // per column: where its next entry below the diagonal goes
  int q = 0;
  for (std::size_t k = 0; k < m; ++k) {
    outer[k] = q;
    const std::span<const std::uint32_t> x = list(k, 0), y = list(k, 1);
    std::size_t u = 0, v = 0;
    while (u < x.size() || v < y.size()) {  // merge two increasing lists; rows sharing both bodies once
      std::uint32_t i;
      if (v == y.size() || (u < x.size() && x[u] < y[v])) i = x[u++];
      else if (u == x.size() || y[v] < x[u]) i = y[v++];
      else i = x[u++], ++v;
      inner[q] = static_cast<int>(i);
      if (i < k) {
        value[q] = value[below[i]++];  // A_ik = A_ki, computed in column i
      } else {
        value[q] = resolution::coupling(rows[island[i]], rows[island[k]]);
        if (i == k) below[k] = q + 1;
      }
      ++q;
    }
  }
  outer[m] = q;
  a.resizeNonZeros(q);
  return a;
}

double kinetic_energy(std::span<const RigidBody> bodies, std::span<const BodyIndex> which) {
  double e = 0.0;
  for (BodyIndex i : which) {
    const RigidBody& b = bodies[i];
    const Vec3 spin_body = b.rotation.transpose() * b.angular_velocity;  // ½ ωᵀ R J Rᵀ ω without forming R J Rᵀ
    e += 0.5 * b.mass * b.velocity.squaredNorm() + 0.5 * spin_body.dot(b.inertia_body * spin_body);
  }
  return e;
}

bool valid_contact(const Contact& c, std::size_t body_count) {
  return c.a < body_count && c.b < body_count && c.a != c.b && all_finite(c.point) && all_finite(c.normal) &&
         std::isfinite(c.depth) && std::abs(c.normal.norm() - 1.0) < 1e-6;
}

}  // namespace

/// One island's working data (local row i is global row rows[i]).
struct LedasResolver::Island {
  std::vector<std::uint32_t> rows;
  SparseMatrix a;                  // eq. 7
  std::vector<BodyIndex> bodies;   // movable bodies
  Incidence incidence;             // rows ↔ movable bodies (slots in `bodies`)
  std::vector<char> equality;      // joint rows
  Vector target;                   // v_n⁺ bound: min(0, depth)/dt for contacts, RowInfo::target for joints
  Vector restitution;              // effective e per row (0 for joint rows)
  Vector impulse_inelastic;        // Σ p over rounds
  Vector impulse_total;            // Σ (1 + e) p over rounds
  std::vector<char> entered;       // the row took part in a system
  double complementarity = 0.0;
  std::uint64_t rounds = 0;
  double dt = 0.0;
  double joint_gap = std::numeric_limits<double>::infinity();  // last predicted position-joint gap (m)

  // Every row's v_n at the bodies' velocities, valid while `velocity_current` (cleared by whatever
  // changes the island's body velocities without recomputing it).
  Vector velocity;
  bool velocity_current = false;

  // complementarity = max over contact rows of |Σ p · (v_n − target)| at velocities v (after an
  // inelastic phase). Accumulated in a local: the member would be kept in memory through the loop.
  void measure_complementarity(const Vector& v, const Vector& target_now) {
    double worst = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      if (!equality[i]) worst = std::max(worst, std::abs(impulse_inelastic(ei) * (v(ei) - target_now(ei))));
    }
    complementarity = worst;
  }
};

// The rows' velocities v_n (eq. 5) at the bodies' current velocities, recomputed only when stale.
const Vector& LedasResolver::current_velocities(Island& island, std::span<const RigidBody> bodies) const {
  if (!island.velocity_current) {
    island.velocity.resize(static_cast<Eigen::Index>(island.rows.size()));
    for (std::size_t i = 0; i < island.rows.size(); ++i)
      island.velocity(static_cast<Eigen::Index>(i)) = ledas::row_velocity(rows_[island.rows[i]], info_[island.rows[i]], bodies);
    island.velocity_current = true;
  }
  return island.velocity;
}

LedasSettings LedasSettings::from_options(const ModuleOptions& options) {
  LedasSettings s;
  s.mode = options.choice("mode", "complementary", {"paper", "complementary"}) == "paper" ? LedasMode::paper
                                                                                         : LedasMode::complementary;
  s.tolerance = options.number("tolerance", s.tolerance, 0.0, 1.0);
  s.start_set = options.choice("start_set", "impact", {"impact", "touching"}) == "touching" ? LedasStartSet::touching
                                                                                         : LedasStartSet::impact;
  s.max_rounds = static_cast<std::uint64_t>(
      options.integer("max_rounds", static_cast<long long>(s.max_rounds), 1, 1'000'000'000));
  s.solver.dense_limit = static_cast<std::size_t>(
      options.integer("dense_limit", static_cast<long long>(s.solver.dense_limit), 1, 100'000));
  s.solver.polish_limit = static_cast<std::size_t>(
      options.integer("polish_limit", static_cast<long long>(s.solver.polish_limit), 0, 100'000));
  s.solver.rank_tolerance = options.number("rank_tolerance", s.solver.rank_tolerance, 1e-16, 1e-2);
  s.solver.update_limit = static_cast<std::size_t>(
      options.integer("update_limit", static_cast<long long>(s.solver.update_limit), 0, 10'000));
  s.solver.regularization = options.number("regularization", s.solver.regularization, 1e-16, 1e-2);
  s.solver.search_regularization =
      options.number("search_regularization", s.solver.search_regularization, 0.0, 1e-1);
  s.solver.sharpen_refinement = options.boolean("sharpen_refinement", s.solver.sharpen_refinement);
  s.solver.max_iterations = s.max_rounds;
  s.islands = options.boolean("islands", s.islands);
  s.resting = resolution::RestingSettings::from_options(options);
  return s;
}

LedasResolver::LedasResolver(const ModuleOptions& options) : LedasResolver(LedasSettings::from_options(options)) {}

LedasResolver::LedasResolver(const LedasSettings& settings) : settings_(settings), solver_([&] {
  ledas::SolverSettings s = settings.solver;
  s.max_iterations = settings.max_rounds;
  return s;
}()) {}

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
  counters.non_converged += stats_.velocity.non_converged + stats_.velocity.infeasible + stats_.position.non_converged;
  counters.singular_systems += stats_.velocity.singular + stats_.position.singular;
  counters.nan_caught += stats_.velocity.nan_caught + stats_.position.nan_caught;
}

void LedasResolver::resolve_all(std::span<RigidBody> bodies, std::span<Contact> contacts,
                                std::span<const Constraint> constraints, const StepContext& ctx,
                                ResolverCounters& counters) {
  rows_.clear();
  info_.clear();
  inertia_.reset(bodies.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    Contact& c = contacts[k];
    c.impulse = 0.0;
    if (!valid_contact(c, bodies.size())) {
      ++counters.nan_caught;
      continue;
    }
    rows_.push_back(resolution::make_contact_row(bodies, inertia_, c));
    ledas::RowInfo ri;
    ri.point_b = c.point;
    ri.depth = c.depth;
    ri.contact = static_cast<std::int64_t>(k);
    info_.push_back(ri);
  }
  for (const Constraint& c : constraints) ledas::append_constraint_rows(bodies, inertia_, c, ctx.dt, rows_, info_);

  std::vector<std::vector<std::uint32_t>> islands = resolution::find_islands(rows_, bodies.size(), bodies);
  body_slot_.assign(bodies.size(), -1);
  if (!settings_.islands && islands.size() > 1) {  // one system for everything (benchmarks/model.cpp)
    std::vector<std::uint32_t> all;
    for (const auto& island : islands) all.insert(all.end(), island.begin(), island.end());
    std::sort(all.begin(), all.end());
    islands.assign(1, std::move(all));
  }
  for (std::vector<std::uint32_t>& rows : islands) {
    Island island = make_island(std::move(rows), bodies, ctx.dt);
    const double energy_before = kinetic_energy(bodies, island.bodies);
    if (settings_.mode == LedasMode::paper) velocity_paper(island, bodies, counters);
    else velocity_complementary(island, bodies, counters);
    const double energy_after = kinetic_energy(bodies, island.bodies);
    stats_.kinetic_energy_change += energy_after - energy_before;
    const bool bouncing = island.restitution.size() > 0 && island.restitution.maxCoeff() > 0.0;
    if (bouncing && energy_after > energy_before * (1.0 + kRoundoff) + 1e-300) ++counters.energy_gain_events;

    // Residual: the largest approach left below each contact's target, after the velocity phase.
    // (Accumulated in locals: the counters may alias the contacts written in the loop, which would
    // keep them in memory.)
    const Vector& v = current_velocities(island, bodies);
    double residual = counters.residual;
    std::uint64_t entered = 0;
    for (std::size_t i = 0; i < island.rows.size(); ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      if (island.equality[i]) continue;
      residual = std::max(residual, island.target(ei) - v(ei));
      if (island.entered[i]) ++entered;
      contacts[static_cast<std::size_t>(info_[island.rows[i]].contact)].impulse = island.impulse_total(ei);
    }
    counters.residual = residual;
    counters.contacts += entered;
    counters.complementarity_error = std::max(counters.complementarity_error, island.complementarity);

    correct_positions(island, bodies);
    ++counters.islands;
    ++stats_.islands;
    stats_.largest_island = std::max(stats_.largest_island, island.rows.size());
    stats_.rounds = std::max(stats_.rounds, island.rounds);
    for (BodyIndex body : island.bodies) body_slot_[body] = -1;
  }
}

// An island's system: A (eq. 7), each row's target and restitution.
LedasResolver::Island LedasResolver::make_island(std::vector<std::uint32_t> rows, std::span<const RigidBody> bodies,
                                                 double dt) {
  Island island;
  island.rows = std::move(rows);
  island.dt = dt;
  const std::size_t m = island.rows.size();
  const auto em = static_cast<Eigen::Index>(m);
  // The island's movable bodies, increasing, each marked with its slot (reset after the island in resolve_all).
  for (std::uint32_t g : island.rows)
    for (BodyIndex body : {rows_[g].a, rows_[g].b})
      if (!bodies[body].fixed && body_slot_[body] < 0) {
        body_slot_[body] = 0;
        island.bodies.push_back(body);
      }
  std::sort(island.bodies.begin(), island.bodies.end());
  for (std::size_t s = 0; s < island.bodies.size(); ++s) body_slot_[island.bodies[s]] = static_cast<std::int32_t>(s);
  island.incidence = Incidence(rows_, island.rows, island.bodies.size(), body_slot_);
  island.a = assemble_matrix(rows_, island.rows, island.incidence);
  island.equality.resize(m);
  island.target.resize(em);
  island.restitution = Vector::Zero(em);
  island.impulse_inelastic = Vector::Zero(em);
  island.impulse_total = Vector::Zero(em);
  island.entered.assign(m, 0);
  for (std::size_t i = 0; i < m; ++i) {
    const ledas::RowInfo& ri = info_[island.rows[i]];
    island.equality[i] = ri.equality;
    // Speculative gap: the contact may approach until the gap closes at the end of the step.
    island.target(static_cast<Eigen::Index>(i)) = ri.equality ? ri.target : std::min(0.0, ri.depth) / dt;
  }

  // Restitution per island: the bounce threshold is judged on the island's fastest approach, because
  // touching contacts carry the restitution phase too (resolution/common/resting.hpp).
  const Vector& v = current_velocities(island, bodies);
  double impact_speed = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (!island.equality[i] && v(ei) <= island.target(ei) + settings_.tolerance)
      impact_speed = std::max(impact_speed, -v(ei));
  }
  for (std::size_t i = 0; i < m; ++i)
    if (!island.equality[i])
      island.restitution(static_cast<Eigen::Index>(i)) =
          resolution::effective_restitution(rows_[island.rows[i]], impact_speed, settings_.resting);
  return island;
}

// The target a row is solved for this round. A gap contact that closes within the step and bounces
// (e > 0) is an impact now: target 0, so (1 + e) p returns its full energy.
namespace {
double solve_target(double base_target, bool closing, double restitution) {
  return closing && restitution > 0.0 ? 0.0 : base_target;
}
}  // namespace

// Position-level joint rows (eqs. 9–10): the target v_n⁺ = v_n − s⁺/dt comes from a prediction at the
// current velocities, linear in the impulse only to first order (eq. 2's rotation is not linear in ω).
// Re-targeting at the start of every round makes the rounds a Newton-like iteration on the gap after
// the step. Returns whether another round is worth it: the gap is above kJointTolerance and still
// shrinking (by half at least; it shrinks by about |ω| dt per round).
bool LedasResolver::retarget_joints(Island& island, const Vector& v, std::span<const RigidBody> bodies) const {
  double gap = 0.0;
  for (std::size_t i = 0; i < island.rows.size(); ++i) {
    const ledas::RowInfo& ri = info_[island.rows[i]];
    if (!ri.position_level) continue;
    const double s = ledas::predicted_separation(rows_[island.rows[i]], ri, bodies, island.dt);
    island.target(static_cast<Eigen::Index>(i)) = v(static_cast<Eigen::Index>(i)) - s / island.dt;
    gap = std::max(gap, std::abs(s));
  }
  const bool refine = gap > kJointTolerance && gap < 0.5 * island.joint_gap;
  island.joint_gap = gap;
  return refine;
}

// The paper's rounds (sec. 3.2): only approaching contacts enter; A p = b as equalities; (1 + e) p;
// re-check every contact; repeat until none approaches. Joint rows ride along in every round.
// The rounds are many (line N = 100: ~10⁵), so each is kept cheap without changing what it computes:
// a row's velocity is re-evaluated only when the round moved one of its bodies, as the Jacobian
// product v_n = n·(v_b − v_a) + (r_b×n)·ω_b − (r_a×n)·ω_a (eq. 5 with (ω×r)·n = ω·(r×n); fixed bodies'
// share precomputed), the subset's system is split into its independent blocks (solve_subset), and
// nothing is allocated per round.
void LedasResolver::velocity_paper(Island& island, std::span<RigidBody> bodies, ResolverCounters& counters) {
  const std::size_t m = island.rows.size();
  const std::size_t nb = island.bodies.size();
  island.velocity_current = false;  // the rounds keep their own velocities
  // Per row: the fixed bodies' share of v_n.
  const auto& slots = island.incidence.slots;
  std::vector<double> fixed_share(m, 0.0);
  for (std::size_t i = 0; i < m; ++i) {
    const ImpulseRow& r = rows_[island.rows[i]];
    const ledas::RowInfo& ri = info_[island.rows[i]];
    if (slots[i][0] < 0) fixed_share[i] -= bodies[r.a].velocity_at(r.point).dot(r.normal);
    if (slots[i][1] < 0) fixed_share[i] += bodies[r.b].velocity_at(ri.point_b).dot(r.normal);
  }
  const auto velocity = [&](std::size_t i) {
    const ImpulseRow& r = rows_[island.rows[i]];
    double u = fixed_share[i];
    if (slots[i][0] >= 0) {
      const RigidBody& a = bodies[r.a];
      u -= r.normal.dot(a.velocity) + r.arm_a.dot(a.angular_velocity);
    }
    if (slots[i][1] >= 0) {
      const RigidBody& b = bodies[r.b];
      u += r.normal.dot(b.velocity) + r.arm_b.dot(b.angular_velocity);
    }
    return u;
  };
  std::vector<std::uint64_t> row_stamp(m, 0), body_stamp(nb, 0);
  std::vector<std::uint32_t> stale;  // rows whose velocity the round changed
  stale.reserve(m);
  std::uint64_t stamp = 0;
  Vector v(static_cast<Eigen::Index>(m));
  for (std::size_t i = 0; i < m; ++i) v(static_cast<Eigen::Index>(i)) = velocity(i);
  const auto mark_moved = [&](std::span<const RowIndex> rows) {  // the rows of the bodies `rows` move
    ++stamp;
    stale.clear();
    for (RowIndex i : rows)
      for (const std::int32_t s : slots[i]) {
        if (s < 0 || body_stamp[static_cast<std::size_t>(s)] == stamp) continue;
        body_stamp[static_cast<std::size_t>(s)] = stamp;
        for (const std::uint32_t row : island.incidence.rows_of(s))
          if (row_stamp[row] != stamp) {
            row_stamp[row] = stamp;
            stale.push_back(row);
          }
      }
  };
  const auto refresh = [&] {
    for (std::uint32_t i : stale) v(i) = velocity(i);
  };
  const bool bouncing = island.restitution.size() > 0 && island.restitution.maxCoeff() > 0.0;
  bool position_joints = false;
  for (std::size_t i = 0; i < m; ++i) position_joints = position_joints || info_[island.rows[i]].position_level;
  Vector target = island.target, rhs = Vector::Zero(static_cast<Eigen::Index>(m)), p = rhs;
  std::vector<RowIndex> subset, joint_rows;
  subset.reserve(m);
  for (std::size_t i = 0; i < m; ++i)
    if (island.equality[i]) joint_rows.push_back(static_cast<RowIndex>(i));
  // With restitution, complementarity is measured after each round's inelastic phase; only the last
  // round's counts, and only the rows that round moved differ from the final state, so their velocity
  // and target at that point are kept (inelastic_v, inelastic_target for the rows of moved_last).
  Vector inelastic_v, inelastic_target;
  std::vector<std::uint32_t> moved_last;
  if (bouncing) {
    inelastic_v.resize(static_cast<Eigen::Index>(m));
    inelastic_target.resize(static_cast<Eigen::Index>(m));
  }
  for (std::uint64_t round = 0;; ++round) {
    const bool refine_joints = position_joints && retarget_joints(island, v, bodies) && round > 0;
    for (RowIndex i : subset) target(i) = island.target(i);  // last round's solve targets
    subset.clear();
    bool approaching = false, joint_violated = false;
    // The rows a round checks: every row in the first; after that the joint rows and the contacts the
    // last round moved (its subset among them). Any other contact kept its velocity and did not
    // approach (it would have been in the subset), so it does not now: a round costs O(rows it
    // touches), not O(m) (line N = 10 000, e = 1: 19 999 rounds). A scan of every row is cheaper than
    // sorting the candidates unless they are few.
    const std::size_t joints = joint_rows.size();
    const bool scan = round == 0 || 8 * (joints + stale.size()) >= m;
    const std::size_t count = scan ? m : joints + stale.size();
    for (std::size_t q = 0; q < count; ++q) {
      const std::size_t i = scan ? q : q < joints ? joint_rows[q] : stale[q - joints];
      if (!scan && q >= joints && island.equality[i]) continue;  // a joint row, checked above
      const auto ei = static_cast<Eigen::Index>(i);
      if (island.equality[i]) {
        joint_violated = joint_violated || std::abs(v(ei) - island.target(ei)) > settings_.tolerance;
        target(ei) = island.target(ei);
        subset.push_back(static_cast<RowIndex>(i));
      } else if (v(ei) < island.target(ei) - settings_.tolerance) {  // approaching (or closing its gap)
        approaching = true;
        subset.push_back(static_cast<RowIndex>(i));
        target(ei) = solve_target(island.target(ei), true, island.restitution(ei));
      }
    }
    if (!scan) {  // solve_subset takes increasing rows; a round's subset is mostly a few
      if (subset.size() > 16) std::sort(subset.begin(), subset.end());
      else
        for (std::size_t a = 1; a < subset.size(); ++a)
          for (std::size_t b = a; b > 0 && subset[b - 1] > subset[b]; --b) std::swap(subset[b - 1], subset[b]);
    }
    if (!approaching && !refine_joints && (round > 0 || !joint_violated)) break;
    if (round == settings_.max_rounds) {
      ++counters.non_converged;
      break;
    }
    for (RowIndex i : subset) rhs(i) = target(i) - v(i);
    solver_.solve_subset(island.a, rhs, subset, p, stats_.velocity);
    ++stats_.systems;
    double largest = 0.0;
    for (RowIndex i : subset) largest = std::max(largest, std::abs(p(i)));
    const double roundoff = kRoundoff * largest;
    for (RowIndex i : subset) {
      if (!island.equality[i] && p(i) < -roundoff) ++stats_.pulling_applied;
      island.entered[i] = 1;
    }
    // The inelastic phase p, then the restitution phase e p (as finish_round, on the subset only: the
    // other rows' impulses are zero).
    for (RowIndex i : subset) {
      resolution::apply_row_impulse(rows_[island.rows[i]], p(i), bodies);
      island.impulse_inelastic(i) += p(i);
    }
    mark_moved(subset);
    refresh();
    if (bouncing) {
      for (const std::uint32_t i : stale) {
        inelastic_v(i) = v(i);
        inelastic_target(i) = target(i);
      }
      moved_last.assign(stale.begin(), stale.end());
      for (RowIndex i : subset)
        if (island.restitution(i) != 0.0) resolution::apply_row_impulse(rows_[island.rows[i]], island.restitution(i) * p(i), bodies);
      refresh();
    }
    for (RowIndex i : subset) {
      island.impulse_total(i) += (1.0 + island.restitution(i)) * p(i);
      p(i) = 0.0;
    }
    ++island.rounds;
  }
  if (island.rounds == 0) return;
  if (!bouncing) {  // the state after the last inelastic phase is the final one
    island.measure_complementarity(v, target);
    return;
  }
  // The last round's inelastic state: the final velocities and the rows' own targets, except on the
  // rows that round moved.
  Vector at_inelastic_v = v, at_inelastic_target = island.target;
  for (const std::uint32_t i : moved_last) {
    at_inelastic_v(i) = inelastic_v(i);
    at_inelastic_target(i) = inelastic_target(i);
  }
  island.measure_complementarity(at_inelastic_v, at_inelastic_target);
}

// The exact impact (a linear complementarity problem), then (1 + e) p. Restitution can make a contact
// approach again (a separating contact pushed shut gets −e v_n⁻), so the round repeats while any does.
void LedasResolver::velocity_complementary(Island& island, std::span<RigidBody> bodies, ResolverCounters& counters) {
  const std::size_t m = island.rows.size();
  ledas::ComplementarityProblem problem;
  problem.matrix = &island.a;
  problem.equality = island.equality;
  problem.start.resize(m);
  problem.tolerance = settings_.tolerance;
  for (std::uint64_t round = 0;; ++round) {
    const Vector& v = current_velocities(island, bodies);  // (finish_round changes it: not used after)
    bool needed = retarget_joints(island, v, bodies) && round > 0;
    Vector target = island.target;
    for (std::size_t i = 0; i < m; ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      if (island.equality[i]) {
        problem.start[i] = 1;
        needed = needed || (round == 0 && std::abs(v(ei) - island.target(ei)) > settings_.tolerance);
        continue;
      }
      const bool touching = v(ei) <= island.target(ei) + settings_.tolerance;  // approaching or touching
      problem.start[i] = touching;
      needed = needed || v(ei) < island.target(ei) - settings_.tolerance;
      target(ei) = solve_target(island.target(ei), touching, island.restitution(ei));
      if (touching) island.entered[i] = 1;
    }
    if (!needed) break;
    if (round == settings_.max_rounds) {
      ++counters.non_converged;
      break;
    }
    if (settings_.start_set == LedasStartSet::impact) narrow_start_set(island, v, problem.start);
    problem.rhs = target - v;
    const std::uint64_t before = stats_.velocity.iterations;
    const Vector p = solver_.solve_complementarity(problem, stats_.velocity);
    stats_.systems += stats_.velocity.iterations - before;
    for (std::size_t i = 0; i < m; ++i)
      if (p(static_cast<Eigen::Index>(i)) != 0.0) island.entered[i] = 1;
    finish_round(island, p, target, bodies);
    ++island.rounds;
  }
}

// The complementary mode's start set (README.md, "The start set"): of the touching contacts, only those
// that can pass the impact on. The impact's sources are the movable bodies of the approaching contacts
// and of the joint rows off their target; every movable body's distance from them is counted in hops
// over the rows of the start set (breadth-first). A touching contact between two movable bodies at the
// same distance runs across the front along which the impact travels: the bodies behind a front are
// pushed apart along it, not together (a pyramid's horizontal contacts, boxes side by side on a floor),
// so such a contact almost always separates. Started in, it is a redundant row the first solve must
// factorize and the search must then release (pyramid K = 20: 190 of 590 rows, and most of the
// factorization's fill); left out, it joins at the next iteration if it would approach. Contacts with a
// fixed body and contacts between bodies the impact does not reach keep their places (in; out: nothing
// pushes them).
void LedasResolver::narrow_start_set(const Island& island, const Vector& v, std::vector<char>& start) {
  const std::size_t m = island.rows.size();
  const auto& slots = island.incidence.slots;
  const auto driving = [&](std::size_t i) {
    const auto ei = static_cast<Eigen::Index>(i);
    return island.equality[i] ? std::abs(v(ei) - island.target(ei)) > settings_.tolerance
                              : v(ei) < island.target(ei) - settings_.tolerance;
  };
  hops_.assign(island.bodies.size(), -1);
  queue_.clear();
  for (std::size_t i = 0; i < m; ++i)
    if (driving(i))
      for (const std::int32_t s : slots[i])
        if (s >= 0 && hops_[static_cast<std::size_t>(s)] < 0) {
          hops_[static_cast<std::size_t>(s)] = 0;
          queue_.push_back(s);
        }
  for (std::size_t head = 0; head < queue_.size(); ++head) {
    const std::int32_t s = queue_[head];
    for (const std::uint32_t i : island.incidence.rows_of(s)) {
      if (!start[i]) continue;
      const std::int32_t other = slots[i][0] == s ? slots[i][1] : slots[i][0];
      if (other >= 0 && hops_[static_cast<std::size_t>(other)] < 0) {
        hops_[static_cast<std::size_t>(other)] = hops_[static_cast<std::size_t>(s)] + 1;
        queue_.push_back(other);
      }
    }
  }
  for (std::size_t i = 0; i < m; ++i) {
    const std::int32_t a = slots[i][0], b = slots[i][1];
    if (start[i] && !island.equality[i] && a >= 0 && b >= 0 &&
        hops_[static_cast<std::size_t>(a)] == hops_[static_cast<std::size_t>(b)] && !driving(i))
      start[i] = 0;
  }
}

// Applies one round: the inelastic impulses p (eq. 3), measures complementarity on that state, then the
// restitution phase e p (sec. 3.2: the total is (1 + e) p). Joint rows have e = 0.
void LedasResolver::finish_round(Island& island, const Vector& p, const Vector& target, std::span<RigidBody> bodies) {
  const std::size_t m = island.rows.size();
  for (std::size_t i = 0; i < m; ++i) resolution::apply_row_impulse(rows_[island.rows[i]], p(static_cast<Eigen::Index>(i)), bodies);
  island.impulse_inelastic += p;
  island.velocity_current = false;
  const Vector& v = current_velocities(island, bodies);
  island.measure_complementarity(v, target);
  for (std::size_t i = 0; i < m; ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (island.restitution(ei) != 0.0) {
      resolution::apply_row_impulse(rows_[island.rows[i]], island.restitution(ei) * p(ei), bodies);
      island.velocity_current = false;
    }
    island.impulse_total(ei) += (1.0 + island.restitution(ei)) * p(ei);
  }
}

// Resting contact (resolution/common/resting.hpp): pseudo-impulses q ≥ 0 with A q ≥ target and
// complementarity move positions only; joint rows hold (target 0) so the correction does not drag them.
void LedasResolver::correct_positions(Island& island, std::span<RigidBody> bodies) {
  const std::size_t m = island.rows.size();
  ledas::ComplementarityProblem problem;
  problem.matrix = &island.a;
  problem.equality = island.equality;
  problem.start.resize(m);
  problem.rhs = Vector::Zero(static_cast<Eigen::Index>(m));
  problem.tolerance = kPositionTolerance;
  bool needed = false;
  for (std::size_t i = 0; i < m; ++i) {
    if (island.equality[i]) continue;
    const double t = resolution::correction_target(info_[island.rows[i]].depth, settings_.resting);
    problem.rhs(static_cast<Eigen::Index>(i)) = t;
    // q = 0 already meets a target within the problem's tolerance (w = −t ≥ −tolerance): a contact
    // overlapping by the slop plus rounding (a generated pyramid at rest) asks for no solve.
    problem.start[i] = t > kPositionTolerance;
    needed = needed || t > kPositionTolerance;
  }
  if (!needed) return;
  const Vector q = solver_.solve_complementarity(problem, stats_.position);
  for (std::size_t i = 0; i < m; ++i)
    if (const double qi = q(static_cast<Eigen::Index>(i)); qi != 0.0)
      resolution::apply_row_displacement(rows_[island.rows[i]], qi, bodies);
}

}  // namespace impetus
