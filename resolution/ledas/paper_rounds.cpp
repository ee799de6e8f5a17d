// The paper mode (sec. 3.2): rounds in which only the approaching rows enter, A_SS p = b_S is solved as
// equalities, (1 + e) p applied, and every row re-checked, until none approaches.
#include "island.hpp"
#include "lane.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace impetus {

using ledas::RowIndex;
using ledas::Vector;
using resolution::ImpulseRow;

namespace {

// The rows' velocities through the rounds. The rounds are many (an inelastic line of N bodies: about
// 10 N²), so a row's velocity is re-evaluated only when a round moved one of its bodies, as the
// Jacobian product v_n = n·(v_b − v_a) + (r_b×n)·ω_b − (r_a×n)·ω_a (eq. 5 with (ω×r)·n = ω·(r×n)),
// the fixed bodies' share computed once.
class RoundVelocities {
 public:
  RoundVelocities(const ledas::Island& island, std::span<const ImpulseRow> rows, std::span<const RigidBody> bodies)
      : island_(island), rows_(rows), bodies_(bodies), fixed_share_(island.rows.size(), 0.0),
        row_stamp_(island.rows.size(), 0), body_stamp_(island.bodies.size(), 0) {
    const std::size_t m = island.rows.size();
    const auto& slots = island.incidence.slots;
    for (std::size_t i = 0; i < m; ++i) {
      const ImpulseRow& r = rows[island.rows[i]];
      if (slots[i][0] < 0) fixed_share_[i] -= bodies[r.a].velocity_at(r.point).dot(r.normal);
      if (slots[i][1] < 0) fixed_share_[i] += bodies[r.b].velocity_at(r.point_b).dot(r.normal);
    }
    stale_.reserve(m);
    v.resize(static_cast<Eigen::Index>(m));
    for (std::size_t i = 0; i < m; ++i) v(static_cast<Eigen::Index>(i)) = velocity(i);
  }

  /// Marks stale the rows of the bodies that the rows `moved` act on (each once).
  void mark_moved(std::span<const RowIndex> moved) {
    ++stamp_;
    stale_.clear();
    for (RowIndex i : moved)
      for (const std::int32_t s : island_.incidence.slots[i]) {
        if (s < 0 || body_stamp_[static_cast<std::size_t>(s)] == stamp_) continue;
        body_stamp_[static_cast<std::size_t>(s)] = stamp_;
        for (const std::uint32_t row : island_.incidence.rows_of(s))
          if (row_stamp_[row] != stamp_) {
            row_stamp_[row] = stamp_;
            stale_.push_back(row);
          }
      }
  }
  /// Re-evaluates the stale rows' velocities.
  void refresh() {
    for (std::uint32_t i : stale_) v(i) = velocity(i);
  }
  /// The rows the last mark_moved() made stale.
  const std::vector<std::uint32_t>& stale() const { return stale_; }

  Vector v;  ///< every row's v_n (m/s), current after refresh()

 private:
  double velocity(std::size_t i) const {
    const ImpulseRow& r = rows_[island_.rows[i]];
    const auto& slots = island_.incidence.slots;
    double u = fixed_share_[i];
    if (slots[i][0] >= 0) u -= resolution::movable_share_a(r, bodies_[r.a]);
    if (slots[i][1] >= 0) u += resolution::movable_share_b(r, bodies_[r.b]);
    return u;
  }

  const ledas::Island& island_;
  std::span<const ImpulseRow> rows_;
  std::span<const RigidBody> bodies_;  // read at their current velocities
  std::vector<double> fixed_share_;    // per row: the fixed bodies' share of v_n
  std::vector<std::uint64_t> row_stamp_, body_stamp_;
  std::vector<std::uint32_t> stale_;   // rows whose velocity the last round changed
  std::uint64_t stamp_ = 0;
};

// What a round's check found.
struct RoundCheck {
  bool approaching = false;     // a contact approaches (or closes its gap within the step)
  bool joint_violated = false;  // a joint row is off its target
};

// Selects a round's subset: the joint rows and the approaching contacts, with their solve targets. The
// first round checks every row; after that the joint rows and the contacts the last round moved
// (`stale`, its subset among them). Any other contact kept its velocity and did not approach (it would
// have been in the subset), so it does not now: a round costs O(rows it touches), not O(m). A scan of
// every row is cheaper than sorting the candidates unless they are few.
RoundCheck select_subset(const ledas::Island& island, const Vector& v, double tolerance, bool scan,
                         std::span<const RowIndex> joint_rows, std::span<const std::uint32_t> stale, Vector& target,
                         std::vector<RowIndex>& subset) {
  RoundCheck check;
  const std::size_t joints = joint_rows.size();
  const std::size_t count = scan ? island.rows.size() : joints + stale.size();
  for (std::size_t q = 0; q < count; ++q) {
    const std::size_t i = scan ? q : q < joints ? joint_rows[q] : stale[q - joints];
    if (!scan && q >= joints && island.equality[i]) continue;  // a joint row, checked above
    const auto ei = static_cast<Eigen::Index>(i);
    if (island.equality[i]) {
      check.joint_violated = check.joint_violated || std::abs(v(ei) - island.target(ei)) > tolerance;
      target(ei) = island.target(ei);
      subset.push_back(static_cast<RowIndex>(i));
    } else if (v(ei) < island.target(ei) - tolerance) {  // approaching (or closing its gap)
      check.approaching = true;
      subset.push_back(static_cast<RowIndex>(i));
      target(ei) = ledas::solve_target(island.target(ei), true, island.restitution(ei));
    }
  }
  if (!scan) {  // solve_subset takes increasing rows; a round's subset is mostly a few: insertion sort
    if (subset.size() > 16) std::sort(subset.begin(), subset.end());
    else
      for (std::size_t a = 1; a < subset.size(); ++a)
        for (std::size_t b = a; b > 0 && subset[b - 1] > subset[b]; --b) std::swap(subset[b - 1], subset[b]);
  }
  return check;
}

// With restitution, complementarity is measured after each round's inelastic phase; only the last
// round's counts, and only the rows that round moved differ from the final state, so their velocity and
// target at that point are kept.
class InelasticState {
 public:
  explicit InelasticState(std::size_t m) : v_(static_cast<Eigen::Index>(m)), target_(static_cast<Eigen::Index>(m)) {}
  /// Keeps the velocities and targets of the rows `moved` after a round's inelastic phase.
  void record(std::span<const std::uint32_t> moved, const Vector& v, const Vector& target) {
    for (const std::uint32_t i : moved) {
      v_(i) = v(i);
      target_(i) = target(i);
    }
    moved_.assign(moved.begin(), moved.end());
  }
  /// Measures the island's complementarity at the last round's inelastic state: the final velocities
  /// `v` and the rows' own targets, except on the rows that round moved.
  void measure(ledas::Island& island, const Vector& v) const {
    Vector at_v = v, at_target = island.target;
    for (const std::uint32_t i : moved_) {
      at_v(i) = v_(i);
      at_target(i) = target_(i);
    }
    island.measure_complementarity(at_v, at_target);
  }

 private:
  Vector v_, target_;
  std::vector<std::uint32_t> moved_;
};

// The paper's rounds over one island (sec. 3.2): only approaching contacts enter; A p = b as equalities;
// (1 + e) p; re-check every contact; repeat until none approaches. Joint rows ride along in every round.
// Each round is kept cheap without changing what it computes: velocities re-evaluated only where a round
// moved a body (RoundVelocities), the subset's system split into its independent blocks (solve_subset),
// nothing allocated per round.
class PaperRounds {
 public:
  PaperRounds(ledas::Island& island, std::span<const ImpulseRow> rows, std::span<const ledas::RowInfo> info,
              const LedasSettings& settings, ledas::IslandSolver& solver, LedasStats& stats,
              std::span<RigidBody> bodies)
      : island_(island), rows_(rows), info_(info), settings_(settings), solver_(solver), stats_(stats),
        bodies_(bodies), velocities_(island, rows, bodies), bouncing_(island.bouncing()),
        inelastic_(bouncing_ ? island.rows.size() : 0) {
    const std::size_t m = island.rows.size();
    for (std::size_t i = 0; i < m; ++i) position_joints_ = position_joints_ || info[island.rows[i]].position_level;
    target_ = island.target;
    rhs_ = Vector::Zero(static_cast<Eigen::Index>(m));
    p_ = rhs_;
    subset_.reserve(m);
    for (std::size_t i = 0; i < m; ++i)
      if (island.equality[i]) joint_rows_.push_back(static_cast<RowIndex>(i));
  }

  // The rounds, then the island's complementarity at the last inelastic state.
  void run(ResolverCounters& counters) {
    const Vector& v = velocities_.v;
    const std::size_t m = island_.rows.size();
    for (std::uint64_t round = 0;; ++round) {
      const bool refine_joints =
          position_joints_ && ledas::retarget_joints(island_, rows_, info_, v, bodies_) && round > 0;
      for (RowIndex i : subset_) target_(i) = island_.target(i);  // last round's solve targets
      subset_.clear();
      const bool scan = round == 0 || 8 * (joint_rows_.size() + velocities_.stale().size()) >= m;
      const RoundCheck check = select_subset(island_, v, settings_.tolerance, scan, joint_rows_,
                                             velocities_.stale(), target_, subset_);
      if (!check.approaching && !refine_joints && (round > 0 || !check.joint_violated)) break;
      if (round == settings_.max_rounds) {
        ++counters.non_converged;
        break;
      }
      for (RowIndex i : subset_) rhs_(i) = target_(i) - v(i);
      solver_.solve_subset(island_.a, rhs_, subset_, p_, stats_.velocity);
      ++stats_.systems;
      apply_round();
      ++island_.rounds;
    }
    if (island_.rounds == 0) return;
    if (!bouncing_) island_.measure_complementarity(v, target_);  // the last inelastic state is the final one
    else inelastic_.measure(island_, v);
  }

 private:
  // One round's impulses: the inelastic phase p, then the restitution phase e p (as finish_round, on the
  // subset only: the other rows' impulses are zero). Counts pulling impulses; leaves p zero.
  void apply_round() {
    double largest = 0.0;
    for (RowIndex i : subset_) largest = std::max(largest, std::abs(p_(i)));
    const double roundoff = ledas::kRoundoff * largest;
    for (RowIndex i : subset_) {
      if (!island_.equality[i] && p_(i) < -roundoff) ++stats_.pulling_applied;
      island_.entered[i] = 1;
    }
    for (RowIndex i : subset_) {
      resolution::apply_row_impulse(rows_[island_.rows[i]], p_(i), bodies_);
      island_.impulse_inelastic(i) += p_(i);
    }
    velocities_.mark_moved(subset_);
    velocities_.refresh();
    if (bouncing_) {
      inelastic_.record(velocities_.stale(), velocities_.v, target_);
      for (RowIndex i : subset_)
        if (island_.restitution(i) != 0.0)
          resolution::apply_row_impulse(rows_[island_.rows[i]], island_.restitution(i) * p_(i), bodies_);
      velocities_.refresh();
    }
    for (RowIndex i : subset_) {
      island_.impulse_total(i) += (1.0 + island_.restitution(i)) * p_(i);
      p_(i) = 0.0;
    }
  }

  ledas::Island& island_;
  std::span<const ImpulseRow> rows_;
  std::span<const ledas::RowInfo> info_;
  const LedasSettings& settings_;
  ledas::IslandSolver& solver_;
  LedasStats& stats_;
  std::span<RigidBody> bodies_;
  RoundVelocities velocities_;
  bool bouncing_;
  InelasticState inelastic_;
  bool position_joints_ = false;  // the island has position-level joint rows
  Vector target_, rhs_, p_;       // this round's solve targets, right-hand side and impulses
  std::vector<RowIndex> subset_, joint_rows_;
};

}  // namespace

void LedasResolver::velocity_paper(ledas::Island& island, std::span<RigidBody> bodies, Lane& lane) {
  island.velocity_current = false;  // the rounds keep their own velocities
  PaperRounds(island, rows_, info_, settings_, lane.solver, lane.stats, bodies).run(lane.counters);
}

}  // namespace impetus
