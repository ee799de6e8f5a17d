#include "impetus/resolution/common/resting.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace impetus::resolution {

void apply_row_displacement(const ImpulseRow& row, double q, std::span<RigidBody> bodies) {
  RigidBody& a = bodies[row.a];
  RigidBody& b = bodies[row.b];
  // Rotations stay orthonormal to rounding: Rodrigues' matrix is exact, the angles are tiny.
  if (!a.fixed) {
    a.position -= (q * row.inv_mass_a) * row.normal;
    a.rotation = rotation_from_vector(-q * row.turn_a) * a.rotation;
  }
  if (!b.fixed) {
    b.position += (q * row.inv_mass_b) * row.normal;
    b.rotation = rotation_from_vector(q * row.turn_b) * b.rotation;
  }
}

CorrectionBound bound_correction(std::span<const ImpulseRow* const> rows, std::span<double> q, double limit,
                                 std::span<const RigidBody> bodies) {
  // Each movable body's translation and turn (the sums apply_row_displacement makes), accumulated in
  // the order of the rows and, within a row, a before b. The scratch is the thread's (kept from call to
  // call, so a correction allocates nothing once it has met its largest island); sorted (body, row
  // side) pairs instead of a hash map.
  struct Motion {
    BodyIndex body = 0;
    Vec3 shift = Vec3::Zero(), turn = Vec3::Zero();
  };
  thread_local std::vector<std::pair<BodyIndex, std::size_t>> order;  // (body, 2 j + side)
  thread_local std::vector<Motion> motion;                             // by body, increasing
  order.clear();
  motion.clear();
  for (std::size_t j = 0; j < rows.size(); ++j) {
    if (q[j] == 0.0) continue;
    if (!bodies[rows[j]->a].fixed) order.emplace_back(rows[j]->a, 2 * j);
    if (!bodies[rows[j]->b].fixed) order.emplace_back(rows[j]->b, 2 * j + 1);
  }
  std::sort(order.begin(), order.end());
  for (const auto& [body, code] : order) {
    if (motion.empty() || motion.back().body != body) motion.push_back(Motion{body, Vec3::Zero(), Vec3::Zero()});
    Motion& m = motion.back();
    const std::size_t j = code / 2;
    const ImpulseRow& row = *rows[j];
    if (code % 2 == 0) {
      m.shift -= (q[j] * row.inv_mass_a) * row.normal;
      m.turn -= q[j] * row.turn_a;
    } else {
      m.shift += (q[j] * row.inv_mass_b) * row.normal;
      m.turn += q[j] * row.turn_b;
    }
  }
  CorrectionBound out;
  if (motion.empty()) return out;
  double worst = 0.0;  // largest ratio of a displacement (or turn) to its bound
  const auto point_moves = [&](BodyIndex s, const Vec3& point) {
    const auto it = std::lower_bound(motion.begin(), motion.end(), s,
                                     [](const Motion& m, BodyIndex body) { return m.body < body; });
    if (it == motion.end() || it->body != s) return;
    const Vec3 d = it->shift + it->turn.cross(point - bodies[s].position);
    const double length = d.norm();
    out.largest = std::max(out.largest, length);
    worst = std::max(worst, length / limit);
  };
  for (std::size_t j = 0; j < rows.size(); ++j) {
    point_moves(rows[j]->a, rows[j]->point);
    point_moves(rows[j]->b, rows[j]->point_b);
  }
  for (const Motion& m : motion) {
    out.largest = std::max(out.largest, m.shift.norm());
    worst = std::max({worst, m.shift.norm() / limit, m.turn.norm() / kMaxCorrectionTurn});
  }
  if (!(worst > 1.0)) return out;  // within the bound (or limit = ∞): q untouched, bit for bit
  out.scale = std::isfinite(worst) ? 1.0 / worst : 0.0;
  for (double& qj : q) qj *= out.scale;
  out.largest *= out.scale;
  return out;
}

}  // namespace impetus::resolution
