#include "impetus/resolution/common/impulse_rows.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace impetus::resolution {

void InverseInertiaCache::reset(std::size_t body_count) {
  ++generation_;
  matrix_.resize(body_count);
  generation_of_.resize(body_count, 0);
}

namespace {
// make_row with J⁻¹ of a body from `inv_inertia(body index)`; the impulse acts at `point` on a and
// `point_b` on b.
template <class InverseInertia>
ImpulseRow row_from(std::span<const RigidBody> bodies, InverseInertia&& inv_inertia, BodyIndex ia, BodyIndex ib,
                    const Vec3& point, const Vec3& point_b, const Vec3& normal, double restitution) {
  const RigidBody& a = bodies[ia];
  const RigidBody& b = bodies[ib];
  ImpulseRow row;
  row.a = ia;
  row.b = ib;
  row.normal = normal;
  row.point = point;
  row.point_b = point_b;
  row.restitution = restitution;
  if (!a.fixed) {
    row.inv_mass_a = a.inv_mass;
    row.arm_a = (point - a.position).cross(normal);
    row.turn_a = inv_inertia(ia) * row.arm_a;
  }
  if (!b.fixed) {
    row.inv_mass_b = b.inv_mass;
    row.arm_b = (point_b - b.position).cross(normal);
    row.turn_b = inv_inertia(ib) * row.arm_b;
  }
  return row;
}
}  // namespace

ImpulseRow make_row(std::span<const RigidBody> bodies, BodyIndex ia, BodyIndex ib, const Vec3& point,
                    const Vec3& normal, double restitution) {
  return row_from(
      bodies, [&](BodyIndex i) { return bodies[i].inv_inertia_world(); }, ia, ib, point, point, normal, restitution);
}

ImpulseRow make_row(std::span<const RigidBody> bodies, InverseInertiaCache& inertia, BodyIndex ia, BodyIndex ib,
                    const Vec3& point, const Vec3& normal, double restitution) {
  return row_from(
      bodies, [&](BodyIndex i) -> const Mat3& { return inertia.get(bodies, i); }, ia, ib, point, point, normal, restitution);
}

ImpulseRow make_row(std::span<const RigidBody> bodies, InverseInertiaCache& inertia, BodyIndex ia, BodyIndex ib,
                    const Vec3& point_a, const Vec3& point_b, const Vec3& normal) {
  return row_from(
      bodies, [&](BodyIndex i) -> const Mat3& { return inertia.get(bodies, i); }, ia, ib, point_a, point_b, normal, 0.0);
}

ImpulseRow make_contact_row(std::span<const RigidBody> bodies, const Contact& contact) {
  return make_row(bodies, contact.a, contact.b, contact.point, contact.normal,
                  combined_restitution(bodies[contact.a], bodies[contact.b]));
}

ImpulseRow make_contact_row(std::span<const RigidBody> bodies, InverseInertiaCache& inertia, const Contact& contact) {
  return make_row(bodies, inertia, contact.a, contact.b, contact.point, contact.normal,
                  combined_restitution(bodies[contact.a], bodies[contact.b]));
}

void apply_row_impulse(const ImpulseRow& row, double p, std::span<RigidBody> bodies) {
  // Eq. 3 with the row's J⁻¹ (r × n) (turn_a, turn_b) computed once when the row was built.
  apply_normal_impulse(bodies[row.a], -p, row.normal, row.turn_a);
  apply_normal_impulse(bodies[row.b], p, row.normal, row.turn_b);
}

std::vector<std::vector<std::uint32_t>> find_islands(std::span<const ImpulseRow> rows,
                                                     std::size_t body_count,
                                                     std::span<const RigidBody> bodies) {
  // Union-find over bodies; a row joins its two bodies unless one is fixed (fixed bodies never carry
  // an impulse from one row to another).
  std::vector<std::uint32_t> parent(body_count);
  std::iota(parent.begin(), parent.end(), 0u);
  const auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const ImpulseRow& r : rows) {
    if (bodies[r.a].fixed || bodies[r.b].fixed) continue;
    const std::uint32_t ra = find(r.a), rb = find(r.b);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
  }
  // A row belongs to the island of its movable body.
  std::vector<std::int64_t> island_of_root(body_count, -1);
  std::vector<std::vector<std::uint32_t>> islands;
  for (std::uint32_t k = 0; k < rows.size(); ++k) {
    const ImpulseRow& r = rows[k];
    const BodyIndex body = bodies[r.a].fixed ? r.b : r.a;
    if (bodies[body].fixed) continue;  // fixed–fixed: nothing to resolve
    const std::uint32_t root = find(body);
    if (island_of_root[root] < 0) {
      island_of_root[root] = static_cast<std::int64_t>(islands.size());
      islands.emplace_back();
    }
    islands[static_cast<std::size_t>(island_of_root[root])].push_back(k);
  }
  return islands;
}

ContactResidual measure_residual(std::span<const ImpulseRow> rows, std::span<const double> impulses,
                                 std::span<const RigidBody> bodies, std::span<const double> targets) {
  ContactResidual out;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const double vn = row_velocity(rows[k], bodies) - (k < targets.size() ? targets[k] : 0.0);
    out.max_approach = std::max(out.max_approach, -vn);
    if (k < impulses.size()) out.complementarity = std::max(out.complementarity, std::abs(impulses[k] * vn));
  }
  return out;
}

}  // namespace impetus::resolution
