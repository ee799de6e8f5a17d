#include "impetus/resolution/ledas/constraint_rows.hpp"

#include <algorithm>
#include <cmath>
#include <array>
#include <bit>
#include <cstdint>
#include <unordered_set>
#include <type_traits>
#include <utility>
#include <variant>

namespace impetus::ledas {
namespace {

using resolution::ImpulseRow;

Vec3 world_point(const RigidBody& body, const Vec3& local) { return body.position + body.rotation * local; }

// Where the material point of `body` now at `p` will be after a step of dt at the current velocities,
// moved as the paper's eq. 2 moves bodies: x += dt v, R = Q(ω dt) R.
Vec3 predicted_point(const RigidBody& body, const Vec3& p, double dt) {
  if (body.fixed) return p;
  return body.position + dt * body.velocity + rotation_from_vector(dt * body.angular_velocity) * (p - body.position);
}

// One equality row along `normal` (unit) acting at point_a on a and point_b on b.
void append_row(std::span<const RigidBody> bodies, resolution::InverseInertiaCache& inertia, BodyIndex a, BodyIndex b,
                const Vec3& point_a, const Vec3& point_b, const Vec3& normal, ConstraintLevel level, double dt,
                std::vector<ImpulseRow>& rows, std::vector<RowInfo>& info) {
  const ImpulseRow row = resolution::make_row(bodies, inertia, a, b, point_a, point_b, normal);  // e = 0 (sec. 4)
  RowInfo ri;
  ri.equality = true;
  // eqs. 9–10: the joined points coincide after the step. Their separation along n after a step at the
  // current velocities is s⁺ (predicted exactly for eq. 2's rotation); an impulse changes it by dt times
  // the change of v_n, so the target is v_n⁺ = v_n⁻ − s⁺/dt (= −s/dt to first order in dt).
  if (level == ConstraintLevel::position) {
    ri.position_level = true;
    ri.target = resolution::row_velocity(row, bodies) - predicted_separation(row, bodies, dt) / dt;
  }
  rows.push_back(row);
  info.push_back(ri);
}

// A coaxial constraint's frame at the current poses: a point and unit direction of a's axis, and
// b's two axis points.
struct AxisFrame {
  Vec3 origin, direction;
  Vec3 points_b[2];
};

AxisFrame axis_frame(std::span<const RigidBody> bodies, const CoaxialConstraint& c) {
  const RigidBody& a = bodies[c.a];
  const RigidBody& b = bodies[c.b];
  AxisFrame f;
  f.origin = world_point(a, c.anchor_a);
  f.direction = (a.rotation * c.axis_a).normalized();
  f.points_b[0] = world_point(b, c.anchor_b);
  f.points_b[1] = f.points_b[0] + c.length * (b.rotation * c.axis_b).normalized();
  return f;
}

// The foot of `q` on the line through `origin` along unit `direction`.
Vec3 foot_on_axis(const Vec3& q, const Vec3& origin, const Vec3& direction) {
  return origin + (q - origin).dot(direction) * direction;
}

}  // namespace

double predicted_separation(const ImpulseRow& row, std::span<const RigidBody> bodies, double dt) {
  return (predicted_point(bodies[row.b], row.point_b, dt) - predicted_point(bodies[row.a], row.point, dt)).dot(row.normal);
}

void append_constraint_rows(std::span<const RigidBody> bodies, resolution::InverseInertiaCache& inertia,
                            const Constraint& constraint, double dt, std::vector<ImpulseRow>& rows,
                            std::vector<RowInfo>& info) {
  if (const auto* pp = std::get_if<PointPointConstraint>(&constraint)) {
    const Vec3 point_a = world_point(bodies[pp->a], pp->anchor_a);
    const Vec3 point_b = world_point(bodies[pp->b], pp->anchor_b);
    for (int axis = 0; axis < 3; ++axis)
      append_row(bodies, inertia, pp->a, pp->b, point_a, point_b, Vec3::Unit(axis), pp->level, dt, rows, info);
    return;
  }
  const auto& co = std::get<CoaxialConstraint>(constraint);
  const AxisFrame f = axis_frame(bodies, co);
  const Vec3 normal_1 = f.direction.unitOrthogonal();
  const Vec3 normal_2 = f.direction.cross(normal_1);
  for (const Vec3& q : f.points_b) {
    const Vec3 foot = foot_on_axis(q, f.origin, f.direction);
    append_row(bodies, inertia, co.a, co.b, foot, q, normal_1, co.level, dt, rows, info);
    append_row(bodies, inertia, co.a, co.b, foot, q, normal_2, co.level, dt, rows, info);
  }
}

double constraint_gap(std::span<const RigidBody> bodies, const Constraint& constraint) {
  if (const auto* pp = std::get_if<PointPointConstraint>(&constraint))
    return (world_point(bodies[pp->b], pp->anchor_b) - world_point(bodies[pp->a], pp->anchor_a)).norm();
  const AxisFrame f = axis_frame(bodies, std::get<CoaxialConstraint>(constraint));
  double gap = 0.0;
  for (const Vec3& q : f.points_b) gap = std::max(gap, (q - foot_on_axis(q, f.origin, f.direction)).norm());
  return gap;
}

std::string constraint_problem(const Constraint& constraint) {
  return std::visit(
      [](const auto& c) -> std::string {
        if (!all_finite(c.anchor_a) || !all_finite(c.anchor_b)) return "anchors must be finite";
        if constexpr (std::is_same_v<std::decay_t<decltype(c)>, CoaxialConstraint>) {
          if (!all_finite(c.axis_a) || !all_finite(c.axis_b) || !(c.axis_a.norm() > 1e-12) ||
              !(c.axis_b.norm() > 1e-12))
            return "the axis must be a finite, non-zero direction in both bodies";
          if (!(c.length > 0.0) || !std::isfinite(c.length)) return "length must be positive and finite";
        }
        return {};
      },
      constraint);
}

std::vector<char> duplicate_constraints(std::span<const Constraint> constraints) {
  using Key = std::array<double, 18>;  // kind, bodies, anchors, axes, length, level
  const auto key = [](const Constraint& c) {
    Key k{};
    k[0] = static_cast<double>(c.index());
    const auto put = [&k](std::size_t at, const Vec3& v) { k[at] = v.x(), k[at + 1] = v.y(), k[at + 2] = v.z(); };
    std::visit(
        [&](const auto& j) {
          k[1] = static_cast<double>(j.a);
          k[2] = static_cast<double>(j.b);
          put(3, j.anchor_a);
          put(6, j.anchor_b);
          k[9] = static_cast<double>(j.level);
          if constexpr (std::is_same_v<std::decay_t<decltype(j)>, CoaxialConstraint>) {
            put(10, j.axis_a);
            put(13, j.axis_b);
            k[16] = j.length;
          }
        },
        c);
    return k;
  };
  std::vector<char> duplicate(constraints.size(), 0);
  if (constraints.size() < 2) return duplicate;
  // Hashed: a thousand identical keys cost a thousand hashes and comparisons, not a sort's worth.
  struct Hash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a over the values' bits
      for (const double v : k) h = (h ^ std::bit_cast<std::uint64_t>(v == 0.0 ? 0.0 : v)) * 0x100000001b3ull;
      return static_cast<std::size_t>(h);
    }
  };
  std::unordered_set<Key, Hash> seen;
  seen.reserve(constraints.size());
  for (std::size_t i = 0; i < constraints.size(); ++i)
    if (!seen.insert(key(constraints[i])).second) duplicate[i] = 1;  // an earlier copy is in
  return duplicate;
}

}  // namespace impetus::ledas
