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

void find_islands(std::span<const ImpulseRow> rows, std::size_t body_count, std::span<const RigidBody> bodies,
                  IslandSet& out) {
  // Union-find over bodies; a row joins its two bodies unless one is fixed (fixed bodies never carry
  // an impulse from one row to another).
  std::vector<std::uint32_t>& parent = out.parent_;
  parent.resize(body_count);
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
  // A row belongs to the island of its movable body; islands are numbered by their first row. Count
  // each island's rows, then lay them out in row order.
  out.island_of_root_.assign(body_count, -1);
  out.island_of_row_.assign(rows.size(), -1);
  out.start_.assign(1, 0);
  for (std::uint32_t k = 0; k < rows.size(); ++k) {
    const ImpulseRow& r = rows[k];
    const BodyIndex body = bodies[r.a].fixed ? r.b : r.a;
    if (bodies[body].fixed) continue;  // fixed–fixed: nothing to resolve
    std::int64_t& island = out.island_of_root_[find(body)];
    if (island < 0) {
      island = static_cast<std::int64_t>(out.start_.size() - 1);
      out.start_.push_back(0);
    }
    out.island_of_row_[k] = island;
    ++out.start_[static_cast<std::size_t>(island) + 1];
  }
  for (std::size_t i = 1; i < out.start_.size(); ++i) out.start_[i] += out.start_[i - 1];
  out.rows_.resize(out.start_.back());
  // island_of_root_ is free again: reuse it as each island's fill cursor.
  for (std::size_t i = 0; i + 1 < out.start_.size(); ++i) out.island_of_root_[i] = out.start_[i];
  for (std::uint32_t k = 0; k < rows.size(); ++k)
    if (const std::int64_t island = out.island_of_row_[k]; island >= 0)
      out.rows_[static_cast<std::size_t>(out.island_of_root_[static_cast<std::size_t>(island)]++)] = k;
}

void IslandSet::merge() {
  if (size() <= 1) return;
  std::sort(rows_.begin(), rows_.end());
  start_.assign({0u, static_cast<std::uint32_t>(rows_.size())});
}

std::vector<std::vector<std::uint32_t>> find_islands(std::span<const ImpulseRow> rows,
                                                     std::size_t body_count,
                                                     std::span<const RigidBody> bodies) {
  IslandSet set;
  find_islands(rows, body_count, bodies, set);
  std::vector<std::vector<std::uint32_t>> islands;
  for (std::size_t i = 0; i < set.size(); ++i) islands.emplace_back(set.island(i).begin(), set.island(i).end());
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
