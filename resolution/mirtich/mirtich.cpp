#include "impetus/resolution/mirtich/mirtich.hpp"

#include "impetus/resolution/common/incidence.hpp"
#include "impetus/resolution/mirtich/friction.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace impetus {
// What the two passes share for one resolve() call. Arrays are indexed by contact (= row) index.
struct MirtichWorkspace {
  std::vector<resolution::ImpulseRow> rows;
  std::vector<double> a_kk;      // A_kk = 1/m_eff (eq. 7, i = k)
  // Current v_n − t of each row (m/s), refreshed after every impulse: the approach beyond the row's
  // target t = gap_target (0 unless the contact has a gap, then −gap/dt: it may close by the step's end).
  std::vector<double> vn;
  std::vector<double> target;    // t of each row (m/s, ≤ 0)
  std::vector<double> impulse;   // accumulated p ≥ 0 (N·s)
  std::vector<char> usable;      // false for rows whose A_kk is not a finite positive number
  std::vector<double> mu;        // Coulomb coefficient of each contact (combined_friction)
  std::vector<Vec3> tangent;     // accumulated tangential impulse p_t (N·s, world)
  std::span<const Contact> contacts;
  resolution::Incidence incidence;  // rows ↔ movable bodies (slot = body index; fixed bodies: none)
  std::vector<std::size_t> local;  // row → its position in the island being corrected
  std::vector<std::uint32_t> all;             // 0 … m − 1
  std::vector<std::int32_t> slot_of_body;     // body → incidence slot (−1: fixed)
  resolution::IslandSet islands;
  // correct_island's, per row of the island: target, pseudo-impulse q, separation A q, the row, and the
  // sparse coupling to the rows sharing a body with it (column j: coupling[coupling_start[j] …]).
  std::vector<double> correction_target, q, separation;
  std::vector<const resolution::ImpulseRow*> correction_rows;
  std::vector<std::size_t> coupling_start;
  std::vector<std::pair<std::size_t, double>> coupling;
  std::vector<std::uint32_t> neighbour_rows;  // neighbours()'s answer

  // Every row sharing a movable body with row k (k included, each once), sorted, into `out`.
  void neighbours(std::uint32_t k, std::vector<std::uint32_t>& out) const {
    out.clear();
    for (const std::int32_t s : incidence.slots[k]) {
      const std::span<const std::uint32_t> of_body = incidence.rows_of(s);
      out.insert(out.end(), of_body.begin(), of_body.end());
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }
};

namespace {

using resolution::ImpulseRow;

// A pseudo-impulse pass whose largest change of separation is below this (m) has converged.
constexpr double kPositionTolerance = 1e-11;

using Workspace = MirtichWorkspace;

// Refreshes v_n of every row that shares a movable body with row k (recomputed from the velocities).
void refresh_neighbours(std::uint32_t k, Workspace& ws, std::span<const RigidBody> bodies) {
  for (const std::int32_t s : ws.incidence.slots[k])
    for (std::uint32_t i : ws.incidence.rows_of(s))
      ws.vn[i] = resolution::row_velocity(ws.rows[i], bodies) - ws.target[i];
}

// The frictional single-contact impulse at contact k (μ > 0): Mirtich's integration of the collision
// in p_n (friction.hpp) from the current relative velocity, with Stronge's coefficient `e`; the whole
// impulse P = p_n n + p_t is applied with apply_contact_impulse. Returns false (and applies nothing)
// if the integration produced a non-finite number.
bool apply_frictional_impulse(std::uint32_t k, double e, Workspace& ws, std::span<RigidBody> bodies,
                              ResolverCounters& counters) {
  const Contact& c = ws.contacts[k];
  RigidBody& a = bodies[c.a];
  RigidBody& b = bodies[c.b];
  // An inelastic gap contact's target shifts the normal velocity the collision ends at: integrate from
  // u − t n. A bouncing one bounces where it is (resting.hpp, "Gaps").
  Vec3 u = relative_velocity(c, a, b);
  if (ws.target[k] != 0.0 && e == 0.0) u -= ws.target[k] * c.normal;
  const mirtich::FrictionalImpact impact =
      mirtich::integrate_frictional_impact(mirtich::collision_matrix(a, b, c.point), u, c.normal, ws.mu[k], e);
  if (!impact.finite || !impact.impulse(c.normal).allFinite()) {
    ++counters.nan_caught;
    ws.usable[k] = 0;
    return false;
  }
  if (!impact.converged) ++counters.non_converged;  // the partial impulse integrated so far is applied
  apply_contact_impulse(c, impact.impulse(c.normal), a, b);
  ws.impulse[k] += impact.normal_impulse;
  ws.tangent[k] += impact.tangent_impulse;
  counters.friction_work += impact.friction_work;
  refresh_neighbours(k, ws, bodies);
  return true;
}

// Applies the single-contact impulse at row k, which approaches beyond its target (ws.vn[k] < 0), and refreshes
// v_n of every row that shares a body with it (recomputed from the velocities, so no drift builds up).
// Returns false (and applies nothing) if the impulse is not finite.
bool apply_single_impulse(std::uint32_t k, Workspace& ws, std::span<RigidBody> bodies,
                          const MirtichSettings& settings, ResolverCounters& counters) {
  const ImpulseRow& row = ws.rows[k];
  // The impact speed is this contact's own approach speed: in a sequence of two-body collisions each
  // one is a separate event (Newton's cradle: the next contact approaches at full speed only after the
  // previous impulse). `ledas` judges the island as a whole instead; see README.md.
  const double e = resolution::effective_restitution(row, -(ws.vn[k] + ws.target[k]), settings.resting);
  if (ws.mu[k] > 0.0) return apply_frictional_impulse(k, e, ws, bodies, counters);
  // Frictionless: the closed form below. An inelastic contact stops at its target (a gap closes at the
  // end of the step); a bouncing one leaves at e times its whole approach speed, where it is.
  const double p = e == 0.0 ? -ws.vn[k] / ws.a_kk[k] : -(1.0 + e) * (ws.vn[k] + ws.target[k]) / ws.a_kk[k];
  if (!std::isfinite(p)) {
    ++counters.nan_caught;
    ws.usable[k] = 0;
    return false;
  }
  resolution::apply_row_impulse(row, p, bodies);
  ws.impulse[k] += p;
  refresh_neighbours(k, ws, bodies);
  return true;
}

// The usable row of `island` with the most negative v_n below −tol into `best` (the strict comparison
// keeps the lowest index among ties); false if none approaches. This scan is the sweep's hot loop (one
// pass over the island per impulse), so it is its own function aligned to a cache line: its speed
// depends on the loop not straddling an instruction-fetch window, which the surrounding code's layout
// would otherwise decide.
[[gnu::aligned(64), gnu::noinline]] bool most_approaching(std::span<const std::uint32_t> island,
                                                          std::span<const char> usable, std::span<const double> vn,
                                                          double tol, std::uint32_t& best) {
  std::uint32_t row = 0;
  double best_vn = -tol;
  bool found = false;
  for (std::uint32_t k : island) {
    if (usable[k] && vn[k] < best_vn) {
      row = k;
      best_vn = vn[k];
      found = true;
    }
  }
  best = row;
  return found;
}

// The velocity sweep over one island. Returns the number of single impulses applied; `capped` tells
// whether the sweep stopped at the cap with a contact still approaching.
std::uint64_t sweep_island(std::span<const std::uint32_t> island, Workspace& ws, std::span<RigidBody> bodies,
                           const MirtichSettings& settings, ResolverCounters& counters, bool& capped) {
  const std::uint64_t cap = settings.impulse_cap(island.size());
  const double tol = settings.tolerance;
  const auto approaches = [&](std::uint32_t k) { return ws.usable[k] && ws.vn[k] < -tol; };
  std::uint64_t applied = 0;
  capped = false;
  if (settings.order == MirtichOrder::most_approaching) {
    for (;;) {
      std::uint32_t best = 0;
      if (!most_approaching(island, ws.usable, ws.vn, tol, best)) break;
      if (applied >= cap) {
        capped = true;
        break;
      }
      if (apply_single_impulse(best, ws, bodies, settings, counters)) ++applied;
    }
    return applied;
  }
  // Index order: cyclic passes; stop after a whole pass in which nothing approached.
  std::size_t quiet = 0;  // consecutive rows met without an impulse
  for (std::size_t j = 0; quiet < island.size(); j = (j + 1) % island.size()) {
    const std::uint32_t k = island[j];
    if (!approaches(k)) {
      ++quiet;
      continue;
    }
    if (applied >= cap) {
      capped = true;
      break;
    }
    if (apply_single_impulse(k, ws, bodies, settings, counters)) {
      ++applied;
      quiet = 0;
    } else {
      ++quiet;
    }
  }
  return applied;
}

// Position correction of one island (resting.hpp): projected Gauss–Seidel on pseudo-impulses q ≥ 0
// with accumulated clamping for A q ≥ target, then one displacement per row. Velocities are untouched.
void correct_island(std::span<const std::uint32_t> island, Workspace& ws, std::span<const Contact> contacts,
                    std::span<RigidBody> bodies, const MirtichSettings& settings, ResolverCounters& counters) {
  std::vector<double>& target = ws.correction_target;
  target.resize(island.size());
  bool any = false;
  double total_target = 0.0;  // Σ targets: the displacement bound's scale (resting.hpp)
  for (std::size_t j = 0; j < island.size(); ++j) {
    target[j] = resolution::correction_target(contacts[island[j]].depth, settings.resting);
    any = any || target[j] > 0.0;
    total_target += target[j];
  }
  if (!any) return;  // nothing penetrates beyond the slop: q = 0 is the solution

  // Local indices and the sparse coupling of each row to the rows it shares a body with (eq. 7).
  // Rows sharing a body are always in the same island, so `local` is only read where just written.
  for (std::size_t j = 0; j < island.size(); ++j) ws.local[island[j]] = j;
  ws.coupling.clear();
  ws.coupling_start.resize(island.size() + 1);
  for (std::size_t j = 0; j < island.size(); ++j) {
    ws.coupling_start[j] = ws.coupling.size();
    ws.neighbours(island[j], ws.neighbour_rows);
    for (std::uint32_t i : ws.neighbour_rows)
      ws.coupling.emplace_back(ws.local[i], resolution::coupling(ws.rows[i], ws.rows[island[j]]));
  }
  ws.coupling_start[island.size()] = ws.coupling.size();

  std::vector<double>& q = ws.q;
  std::vector<double>& separation = ws.separation;  // = A q (m)
  q.assign(island.size(), 0.0);
  separation.assign(island.size(), 0.0);
  for (int pass = 0; pass < settings.position_iterations; ++pass) {
    double largest_change = 0.0;
    for (std::size_t j = 0; j < island.size(); ++j) {
      const std::uint32_t k = island[j];
      if (!ws.usable[k]) continue;
      const double q_new = std::max(0.0, q[j] + (target[j] - separation[j]) / ws.a_kk[k]);
      const double dq = q_new - q[j];
      if (dq == 0.0) continue;
      q[j] = q_new;
      for (std::size_t e = ws.coupling_start[j]; e < ws.coupling_start[j + 1]; ++e)
        separation[ws.coupling[e].first] += ws.coupling[e].second * dq;
      largest_change = std::max(largest_change, std::abs(dq) * ws.a_kk[k]);
    }
    if (largest_change < kPositionTolerance) break;
  }
  // No correction moves a body absurdly far (the displacement bound, resting.hpp).
  std::vector<const resolution::ImpulseRow*>& rows = ws.correction_rows;
  rows.resize(island.size());
  for (std::size_t j = 0; j < island.size(); ++j) rows[j] = &ws.rows[island[j]];
  const resolution::CorrectionBound bound =
      resolution::bound_correction(rows, q, resolution::kCorrectionBoundFactor * total_target, bodies);
  if (bound.scale < 1.0) ++counters.corrections_clamped;
  counters.largest_correction = std::max(counters.largest_correction, bound.largest);
  // All displacements use the rows built before the correction: first order in the (small) motion.
  for (std::size_t j = 0; j < island.size(); ++j)
    if (q[j] > 0.0) resolution::apply_row_displacement(*rows[j], q[j], bodies);
}

// Writes each contact's impulses and final mode (before the position correction moves the bodies):
// separate if it received no impulse, stick if its slip ‖u_t‖ after the sweep is at most `tolerance`,
// slide otherwise; counts sticking and sliding contacts once each.
void record_outcomes(const Workspace& ws, std::span<Contact> contacts, std::span<const RigidBody> bodies,
                     double tolerance, ResolverCounters& counters) {
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    Contact& c = contacts[k];
    c.impulse = ws.impulse[k];
    c.tangent_impulse = ws.tangent[k];
    if (ws.impulse[k] == 0.0 && ws.tangent[k].isZero(0.0)) {
      c.mode = ContactMode::separate;
      continue;
    }
    const Vec3 u = relative_velocity(c, bodies[c.a], bodies[c.b]);
    const Vec3 slip = u - u.dot(c.normal) * c.normal;
    c.mode = slip.norm() <= tolerance ? ContactMode::stick : ContactMode::slide;
    ++(c.mode == ContactMode::stick ? counters.sticking : counters.sliding);
  }
}

}  // namespace

MirtichResolver::MirtichResolver(const ModuleOptions& options)
    : settings_(MirtichSettings::from_options(options)), work_(std::make_unique<MirtichWorkspace>()) {}

MirtichResolver::MirtichResolver(const MirtichSettings& settings)
    : settings_(settings), work_(std::make_unique<MirtichWorkspace>()) {}

MirtichResolver::~MirtichResolver() = default;

void MirtichResolver::resolve(std::span<RigidBody> bodies, std::span<Contact> contacts,
                              std::span<const Constraint> /*constraints*/, const StepContext& ctx,
                              ResolverCounters& counters) noexcept {
  try {
    Workspace& ws = *work_;  // its vectors keep their storage from the last call
    const std::size_t m = contacts.size();
    ws.rows.clear();
    for (const Contact& c : contacts) ws.rows.push_back(resolution::make_contact_row(bodies, c));
    ws.a_kk.resize(m);
    ws.vn.resize(m);
    ws.target.resize(m);
    ws.impulse.assign(m, 0.0);
    ws.usable.assign(m, 1);
    ws.local.assign(m, 0);
    ws.mu.resize(m);
    ws.tangent.assign(m, Vec3::Zero());
    ws.contacts = contacts;
    for (std::size_t k = 0; k < m; ++k) ws.mu[k] = combined_friction(bodies[contacts[k].a], bodies[contacts[k].b]);
    for (std::uint32_t k = 0; k < m; ++k) {
      const ImpulseRow& row = ws.rows[k];
      ws.a_kk[k] = resolution::self_coupling(row);
      ws.target[k] = resolution::gap_target(contacts[k].depth, ctx.dt);
      ws.vn[k] = resolution::row_velocity(row, bodies) - ws.target[k];
      if (!(ws.a_kk[k] > 0.0) || !std::isfinite(ws.a_kk[k])) {
        ws.usable[k] = 0;  // e.g. a contact between two fixed bodies: no impulse can act on it
        if (!bodies[row.a].fixed || !bodies[row.b].fixed) ++counters.singular_systems;
      }
    }
    ws.all.resize(m);
    ws.slot_of_body.resize(bodies.size());
    for (std::uint32_t k = 0; k < m; ++k) ws.all[k] = k;
    for (std::size_t s = 0; s < bodies.size(); ++s)
      ws.slot_of_body[s] = bodies[s].fixed ? -1 : static_cast<std::int32_t>(s);
    ws.incidence.assign(ws.rows, ws.all, bodies.size(), ws.slot_of_body);

    resolution::find_islands(ws.rows, bodies.size(), bodies, ws.islands);
    for (std::size_t i = 0; i < ws.islands.size(); ++i) {
      const std::span<const std::uint32_t> island = ws.islands.island(i);
      bool capped = false;
      counters.rounds += sweep_island(island, ws, bodies, settings_, counters, capped);
      if (capped) ++counters.non_converged;
      ++counters.islands;
      counters.contacts += island.size();
    }
    // Quality is measured after the velocity sweep; the position correction does not change velocities.
    const resolution::ContactResidual residual = resolution::measure_residual(ws.rows, ws.impulse, bodies, ws.target);
    counters.residual = std::max(counters.residual, residual.max_approach);
    counters.complementarity_error = std::max(counters.complementarity_error, residual.complementarity);
    record_outcomes(ws, contacts, bodies, settings_.tolerance, counters);
    for (std::size_t i = 0; i < ws.islands.size(); ++i)
      correct_island(ws.islands.island(i), ws, contacts, bodies, settings_, counters);
  } catch (...) {
    // Only allocation can throw here; report it as a failed (non-converged) resolution.
    ++counters.non_converged;
  }
}

}  // namespace impetus
