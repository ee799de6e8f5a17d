#include "impetus/resolution/common/resting.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

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
  // Each movable body's translation and turn (the sums apply_row_displacement makes).
  struct Motion {
    Vec3 shift = Vec3::Zero(), turn = Vec3::Zero();
  };
  std::unordered_map<BodyIndex, Motion> motion;
  for (std::size_t j = 0; j < rows.size(); ++j) {
    if (q[j] == 0.0) continue;
    const ImpulseRow& row = *rows[j];
    if (!bodies[row.a].fixed) {
      Motion& m = motion[row.a];
      m.shift -= (q[j] * row.inv_mass_a) * row.normal;
      m.turn -= q[j] * row.turn_a;
    }
    if (!bodies[row.b].fixed) {
      Motion& m = motion[row.b];
      m.shift += (q[j] * row.inv_mass_b) * row.normal;
      m.turn += q[j] * row.turn_b;
    }
  }
  CorrectionBound out;
  if (motion.empty()) return out;
  double worst = 0.0;  // largest ratio of a displacement (or turn) to its bound
  const auto point_moves = [&](BodyIndex s, const Vec3& point) {
    const auto it = motion.find(s);
    if (it == motion.end()) return;
    const Vec3 d = it->second.shift + it->second.turn.cross(point - bodies[s].position);
    const double length = d.norm();
    out.largest = std::max(out.largest, length);
    worst = std::max(worst, length / limit);
  };
  for (std::size_t j = 0; j < rows.size(); ++j) {
    point_moves(rows[j]->a, rows[j]->point);
    point_moves(rows[j]->b, rows[j]->point_b);
  }
  for (const auto& [s, m] : motion) {
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
