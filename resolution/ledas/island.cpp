// Building an island's system: its movable bodies and their incidence, A of eq. 7, each row's target;
// the rows' velocities; the position-level joints' targets.
#include "island.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace impetus {

namespace {
// Position-level joints are re-linearized round after round until the predicted gap is below this (m),
// or stops halving.
constexpr double kJointTolerance = 1e-9;
}  // namespace

namespace ledas {

void Island::measure_complementarity(const Vector& v, const Vector& target_now) {
  double worst = 0.0;  // a local: the member would be kept in memory through the loop
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (normal_row(i)) worst = std::max(worst, std::abs(impulse_inelastic(ei) * (v(ei) - target_now(ei))));
  }
  complementarity = worst;
}

// A_ik ≠ 0 only where rows i and k share a movable body, so column k is the union of the row lists of
// k's (at most two) movable bodies, written in compressed form directly (no triplets, no sort of pairs).
// Each coupling is computed once, on and below the diagonal (i ≥ k); an entry above it (i < k) is copied
// from column i, whose entries below the diagonal are met in increasing row order as k grows. So A is
// exactly symmetric.
void assemble_matrix(std::span<const resolution::ImpulseRow> rows, std::span<const std::uint32_t> island,
                     const resolution::Incidence& incidence, SparseMatrix& a, std::vector<int>& below) {
  const std::size_t m = island.size();
  const auto em = static_cast<Eigen::Index>(m);
  a.resize(em, em);  // keeps the entries' storage
  std::size_t nonzeros = 0;
  for (std::size_t k = 0; k < m; ++k) nonzeros += incidence.side_rows(k, 0).size() + incidence.side_rows(k, 1).size();
  a.resizeNonZeros(static_cast<Eigen::Index>(nonzeros));
  int* outer = a.outerIndexPtr();
  int* inner = a.innerIndexPtr();
  double* value = a.valuePtr();
  below.resize(m);  // per column: where its next entry below the diagonal goes
  int q = 0;
  for (std::size_t k = 0; k < m; ++k) {
    outer[k] = q;
    const std::span<const std::uint32_t> x = incidence.side_rows(k, 0), y = incidence.side_rows(k, 1);
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
}

bool wants_body_space(const Island& island, std::size_t rows, const SolverSettings& settings) {
  return settings.interior_point_rows > 0 && rows >= settings.interior_point_rows &&
         rows > 6 * island.bodies.size() &&
         std::none_of(island.equality.begin(), island.equality.end(), [](char e) { return e != 0; });
}

// Row k's v_n = (u_b − u_a)·n at its points: −(n, r_a × n) on body a's coordinates (v, ω), +(n, r_b × n)
// on b's; fixed bodies have no block. A row with the same body on both sides has the sum on one block.
void assemble_body_space(std::span<const resolution::ImpulseRow> rows, const Island& island,
                         std::span<const RowIndex> local, std::span<const RigidBody> bodies, BodySpace& out) {
  const std::size_t m = local.empty() ? island.rows.size() : local.size();
  out.blocks.resize(m);
  out.jacobian.resize(m);
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t i = local.empty() ? j : local[j];
    const resolution::ImpulseRow& row = rows[island.rows[i]];
    std::array<std::int32_t, 2> sides = island.incidence.slots[i];
    std::array<double, 12>& g = out.jacobian[j];
    for (int d = 0; d < 3; ++d) {
      g[d] = -row.normal(d), g[3 + d] = -row.arm_a(d);
      g[6 + d] = row.normal(d), g[9 + d] = row.arm_b(d);
    }
    if (sides[0] < 0) {  // only side b is movable: it becomes the first
      std::copy(g.begin() + 6, g.end(), g.begin());
      sides = {sides[1], -1};
    } else if (sides[1] == sides[0]) {
      for (int d = 0; d < 6; ++d) g[d] += g[6 + d];
      sides[1] = -1;
    }
    if (sides[1] < 0) std::fill(g.begin() + 6, g.end(), 0.0);
    out.blocks[j] = sides;
  }
  out.mass.resize(island.bodies.size());
  out.inertia.resize(island.bodies.size());
  for (std::size_t s = 0; s < island.bodies.size(); ++s) {
    const RigidBody& body = bodies[island.bodies[s]];
    out.mass[s] = body.mass;
    out.inertia[s] = body.inertia_world();
  }
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

}  // namespace ledas

// An island's system: its movable bodies, A (eq. 7), each row's target and restitution.
void LedasResolver::make_island(std::span<const std::uint32_t> rows, std::span<const RigidBody> bodies, double dt,
                                ledas::Island& island) {
  island.rows.assign(rows.begin(), rows.end());
  island.dt = dt;
  island.bodies.clear();
  island.frictional = false;
  island.complementarity = 0.0;
  island.rounds = 0;
  island.joint_gap = std::numeric_limits<double>::infinity();
  island.velocity_current = false;
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
  island.incidence.assign(rows_, island.rows, island.bodies.size(), body_slot_);
  ledas::assemble_matrix(rows_, island.rows, island.incidence, island.a, island.scratch);
  island.equality.resize(m);
  island.role.resize(m);
  island.mu.assign(m, 0.0);
  island.target.resize(em);
  island.restitution = ledas::Vector::Zero(em);
  island.impulse_inelastic = ledas::Vector::Zero(em);
  island.impulse_total = ledas::Vector::Zero(em);
  island.entered.assign(m, 0);
  for (std::size_t i = 0; i < m; ++i) {
    const ledas::RowInfo& ri = info_[island.rows[i]];
    island.equality[i] = ri.equality;
    island.role[i] = ri.equality ? ledas::RowRole::equality : ri.tangent ? ledas::RowRole::tangent : ledas::RowRole::normal;
    if (island.role[i] == ledas::RowRole::normal) island.mu[i] = ri.friction;
    island.frictional = island.frictional || ri.tangent != 0;
    // Speculative gap: the contact may approach until the gap closes at the end of the step.
    island.target(static_cast<Eigen::Index>(i)) =
        ri.equality ? ri.target : ri.tangent ? 0.0 : resolution::gap_target(ri.depth, dt);
  }
  assign_restitution(island, bodies);
}

// The rows' velocities v_n (eq. 5) at the bodies' current velocities, recomputed only when stale.
const ledas::Vector& LedasResolver::current_velocities(ledas::Island& island, std::span<const RigidBody> bodies) const {
  if (!island.velocity_current) {
    island.velocity.resize(static_cast<Eigen::Index>(island.rows.size()));
    for (std::size_t i = 0; i < island.rows.size(); ++i)
      island.velocity(static_cast<Eigen::Index>(i)) = resolution::row_velocity(rows_[island.rows[i]], bodies);
    island.velocity_current = true;
  }
  return island.velocity;
}

// Position-level joint rows (eqs. 9–10): the target v_n⁺ = v_n − s⁺/dt comes from a prediction at the
// current velocities, linear in the impulse only to first order (eq. 2's rotation is not linear in ω).
// Re-targeting at the start of every round makes the rounds a Newton-like iteration on the gap after
// the step. Returns whether another round is worth it: the gap is above kJointTolerance and still
// shrinking (by half at least; it shrinks by about |ω| dt per round).
bool ledas::retarget_joints(Island& island, std::span<const resolution::ImpulseRow> rows, std::span<const RowInfo> info,
                            const Vector& v, std::span<const RigidBody> bodies) {
  double gap = 0.0;
  for (std::size_t i = 0; i < island.rows.size(); ++i) {
    const ledas::RowInfo& ri = info[island.rows[i]];
    if (!ri.position_level) continue;
    const double s = ledas::predicted_separation(rows[island.rows[i]], bodies, island.dt);
    island.target(static_cast<Eigen::Index>(i)) = v(static_cast<Eigen::Index>(i)) - s / island.dt;
    gap = std::max(gap, std::abs(s));
  }
  const bool refine = gap > kJointTolerance && gap < 0.5 * island.joint_gap;
  island.joint_gap = gap;
  return refine;
}

}  // namespace impetus
