#include "common/impulse_rows.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace impetus::resolution {

ImpulseRow make_row(std::span<const RigidBody> bodies, BodyIndex ia, BodyIndex ib, const Vec3& point,
                    const Vec3& normal, double restitution) {
  const RigidBody& a = bodies[ia];
  const RigidBody& b = bodies[ib];
  ImpulseRow row;
  row.a = ia;
  row.b = ib;
  row.normal = normal;
  row.point = point;
  row.restitution = restitution;
  if (!a.fixed) {
    row.inv_mass_a = a.inv_mass;
    row.arm_a = (point - a.position).cross(normal);
    row.turn_a = a.inv_inertia_world() * row.arm_a;
  }
  if (!b.fixed) {
    row.inv_mass_b = b.inv_mass;
    row.arm_b = (point - b.position).cross(normal);
    row.turn_b = b.inv_inertia_world() * row.arm_b;
  }
  return row;
}

ImpulseRow make_contact_row(std::span<const RigidBody> bodies, const Contact& contact) {
  return make_row(bodies, contact.a, contact.b, contact.point, contact.normal,
                  combined_restitution(bodies[contact.a], bodies[contact.b]));
}

namespace {
// The term of eq. 7 for one shared body s: σ_i σ_k [n_i·n_k / M_s + (r_{s,i}×n_i)·J_s⁻¹(r_{s,k}×n_k)].
double body_term(double sigma, double inv_mass, const Vec3& normal_i, const Vec3& arm_i,
                 const Vec3& normal_k, const Vec3& turn_k) {
  return sigma * (inv_mass * normal_i.dot(normal_k) + arm_i.dot(turn_k));
}
}  // namespace

double coupling(const ImpulseRow& i, const ImpulseRow& k) {
  double a_ik = 0.0;
  // Body a of row i: σ_{s,i} = −1. It is shared with row k as k's a (σ = −1) or k's b (σ = +1).
  if (i.inv_mass_a != 0.0) {  // a movable body (fixed bodies have no terms)
    if (i.a == k.a) a_ik += body_term(+1.0, i.inv_mass_a, i.normal, i.arm_a, k.normal, k.turn_a);
    if (i.a == k.b) a_ik += body_term(-1.0, i.inv_mass_a, i.normal, i.arm_a, k.normal, k.turn_b);
  }
  if (i.inv_mass_b != 0.0) {
    if (i.b == k.a) a_ik += body_term(-1.0, i.inv_mass_b, i.normal, i.arm_b, k.normal, k.turn_a);
    if (i.b == k.b) a_ik += body_term(+1.0, i.inv_mass_b, i.normal, i.arm_b, k.normal, k.turn_b);
  }
  return a_ik;
}

double row_velocity(const ImpulseRow& row, std::span<const RigidBody> bodies) {
  const RigidBody& a = bodies[row.a];
  const RigidBody& b = bodies[row.b];
  return (b.velocity_at(row.point) - a.velocity_at(row.point)).dot(row.normal);
}

void apply_row_impulse(const ImpulseRow& row, double p, std::span<RigidBody> bodies) {
  RigidBody& a = bodies[row.a];
  RigidBody& b = bodies[row.b];
  if (!a.fixed) {
    a.velocity -= (p * row.inv_mass_a) * row.normal;
    a.angular_velocity -= p * row.turn_a;
  }
  if (!b.fixed) {
    b.velocity += (p * row.inv_mass_b) * row.normal;
    b.angular_velocity += p * row.turn_b;
  }
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
                                 std::span<const RigidBody> bodies) {
  ContactResidual out;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const double vn = row_velocity(rows[k], bodies);
    out.max_approach = std::max(out.max_approach, -vn);
    if (k < impulses.size()) out.complementarity = std::max(out.complementarity, std::abs(impulses[k] * vn));
  }
  return out;
}

}  // namespace impetus::resolution
