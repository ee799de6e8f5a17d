#pragma once
/// \file
/// The algebra every impulse resolver shares: one "row" per contact (or constraint direction), the
/// matrix A = G M⁻¹ Gᵀ of the paper's eq. 6–7, the right-hand side of eq. 8, and applying impulses
/// with eq. 3.
///
/// Sign convention (docs/conventions.md): a row has bodies a, b, a world point P and a unit direction n
/// (out of a into b). Its velocity is v_n = (u_b − u_a)·n with u = v + ω × r. An impulse magnitude p
/// acts −p n on a and +p n on b, so for body s with sign σ (−1 for a, +1 for b):
///   Δv_s = σ p n / M_s,   Δω_s = σ p J_s⁻¹ (r_s × n)                          (eq. 3, sign fixed)
/// and the rows' velocities change by A p with
///   A_ik = Σ_{s shared by rows i, k} σ_{s,i} σ_{s,k} [ n_i·n_k / M_s + (r_{s,i} × n_i)·J_s⁻¹ (r_{s,k} × n_k) ]
/// (eq. 7 with its indices read as docs/conventions.md says: symmetric positive semi-definite). The inelastic
/// condition v_n⁺ = 0 (eq. 4) is A p = b with b = −v_n⁻ (eq. 8 with the sign fixed).
/// Fixed bodies (inverse mass and inertia zero) drop out of every term.

#include "impetus/core/body.hpp"
#include "impetus/modules/contact.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace impetus::resolution {

/// The velocity-space description of one impulse direction between two bodies.
struct ImpulseRow {
  BodyIndex a = 0, b = 0;
  Vec3 normal = Vec3::UnitZ();  ///< unit, out of a into b
  Vec3 point = Vec3::Zero();    ///< world point where the impulse acts on a (m)
  /// World point where the impulse acts on b (m): `point` for a contact; a joint row's own point on b,
  /// which drifts from a's as the joint opens (arm_b is taken from it).
  Vec3 point_b = Vec3::Zero();
  double inv_mass_a = 0.0, inv_mass_b = 0.0;
  Vec3 arm_a = Vec3::Zero(), arm_b = Vec3::Zero();  ///< r_s × n (m)
  Vec3 turn_a = Vec3::Zero(), turn_b = Vec3::Zero(); ///< J_s⁻¹ (r_s × n) (1/(kg·m))
  double restitution = 0.0;
};

/// The world-frame inverse inertia J⁻¹ = R J_body⁻¹ Rᵀ (RigidBody::inv_inertia_world) of the bodies a
/// step's rows touch, each computed once instead of once per row (a sphere in a pyramid carries up to
/// twelve contacts). The same matrices, so rows built through it are bit-identical to rows built
/// without it.
class InverseInertiaCache {
 public:
  /// Forgets every matrix (O(1): a new generation) and sizes the cache for `body_count` bodies.
  void reset(std::size_t body_count);
  /// Body `index`'s J⁻¹ (1/(kg·m²)), computed on its first use since reset(). Valid until the body turns.
  const Mat3& get(std::span<const RigidBody> bodies, BodyIndex index) {
    if (generation_of_[index] != generation_) {
      generation_of_[index] = generation_;
      // Evaluated in place: copying a returned matrix in costs a failed store forwarding per body.
      bodies[index].inv_inertia_world(matrix_[index]);
    }
    return matrix_[index];
  }

 private:
  std::vector<Mat3> matrix_;
  std::vector<std::uint64_t> generation_of_;  // per body: the generation its matrix was computed in
  std::uint64_t generation_ = 0;
};

/// Builds the row for a direction `normal` at `point` between bodies `ia` and `ib` of `bodies`.
ImpulseRow make_row(std::span<const RigidBody> bodies, BodyIndex ia, BodyIndex ib, const Vec3& point,
                    const Vec3& normal, double restitution = 0.0);
/// The same row, taking the bodies' J⁻¹ from `inertia` (reset() for `bodies` at their current poses).
ImpulseRow make_row(std::span<const RigidBody> bodies, InverseInertiaCache& inertia, BodyIndex ia, BodyIndex ib,
                    const Vec3& point, const Vec3& normal, double restitution = 0.0);
/// A row acting at `point_a` on a and `point_b` on b (a joint row), e = 0, J⁻¹ from `inertia`.
ImpulseRow make_row(std::span<const RigidBody> bodies, InverseInertiaCache& inertia, BodyIndex ia, BodyIndex ib,
                    const Vec3& point_a, const Vec3& point_b, const Vec3& normal);

/// The row of a contact, with the combined restitution of its bodies.
ImpulseRow make_contact_row(std::span<const RigidBody> bodies, const Contact& contact);
/// The same row, taking the bodies' J⁻¹ from `inertia`.
ImpulseRow make_contact_row(std::span<const RigidBody> bodies, InverseInertiaCache& inertia, const Contact& contact);

/// A_ik: how a unit impulse on row k changes the velocity of row i (eq. 7). Zero unless they share a
/// movable body. Inline: assembling A calls it once per non-zero.
inline double coupling(const ImpulseRow& i, const ImpulseRow& k) {
  // The term of eq. 7 for one shared body s: σ_i σ_k [n_i·n_k / M_s + (r_{s,i}×n_i)·J_s⁻¹(r_{s,k}×n_k)].
  const auto body_term = [](double sigma, double inv_mass, const Vec3& normal_i, const Vec3& arm_i,
                            const Vec3& normal_k, const Vec3& turn_k) {
    return sigma * (inv_mass * normal_i.dot(normal_k) + arm_i.dot(turn_k));
  };
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

/// A_kk = 1/m_eff of a single row: n·n/M_a + (r_a×n)·J_a⁻¹(r_a×n) + the same for b.
inline double self_coupling(const ImpulseRow& row) { return coupling(row, row); }

/// v_n = (u_b(point_b) − u_a(point))·n of the row at the bodies' current velocities, u = v + ω × r
/// (eq. 5; m/s, < 0 approaches). Inline: evaluated for every row after every round.
inline double row_velocity(const ImpulseRow& row, std::span<const RigidBody> bodies) {
  return relative_normal_velocity(bodies[row.a], row.point, bodies[row.b], row.point_b, row.normal);
}

/// Body a's share of the row's v_n in Jacobian form, n·v_a + (r_a×n)·ω_a (m/s; eq. 5 with
/// (ω×r)·n = ω·(r×n)); v_n = movable_share_b − movable_share_a for two movable bodies. Zero arm for a
/// fixed body: its share is then only n·v_a.
inline double movable_share_a(const ImpulseRow& row, const RigidBody& a) {
  return row.normal.dot(a.velocity) + row.arm_a.dot(a.angular_velocity);
}
/// Body b's share of the row's v_n in Jacobian form, n·v_b + (r_b×n)·ω_b (m/s).
inline double movable_share_b(const ImpulseRow& row, const RigidBody& b) {
  return row.normal.dot(b.velocity) + row.arm_b.dot(b.angular_velocity);
}

/// Applies impulse magnitude `p` along the row (eq. 3): −p n on a, +p n on b. Fixed bodies unchanged.
void apply_row_impulse(const ImpulseRow& row, double p, std::span<RigidBody> bodies);

/// Rows grouped into islands (find_islands), laid out in one array, with the grouping's scratch: kept
/// from step to step, it allocates only when the rows or bodies outgrow every earlier step's.
class IslandSet {
 public:
  /// How many islands.
  std::size_t size() const { return start_.empty() ? 0 : start_.size() - 1; }
  /// Island i's rows, increasing.
  std::span<const std::uint32_t> island(std::size_t i) const {
    return {rows_.data() + start_[i], rows_.data() + start_[i + 1]};
  }
  /// Makes the islands one: every row of every island, increasing (a single system for everything).
  void merge();

 private:
  friend void find_islands(std::span<const ImpulseRow>, std::size_t, std::span<const RigidBody>, IslandSet&);
  std::vector<std::uint32_t> start_;  // per island, its first entry in rows_; one more at the end
  std::vector<std::uint32_t> rows_;
  std::vector<std::uint32_t> parent_;          // union-find over bodies
  std::vector<std::int64_t> island_of_root_;   // per root body, its island, or −1
  std::vector<std::int64_t> island_of_row_;    // per row, its island, or −1 (fixed–fixed)
};

/// Groups rows into islands: rows connected through shared movable bodies (fixed bodies do not
/// connect). Each island lists row indices in increasing order; islands are ordered by their first
/// row. Deterministic.
void find_islands(std::span<const ImpulseRow> rows, std::size_t body_count, std::span<const RigidBody> bodies,
                  IslandSet& out);
/// The same as a list of lists (allocates).
std::vector<std::vector<std::uint32_t>> find_islands(std::span<const ImpulseRow> rows,
                                                     std::size_t body_count,
                                                     std::span<const RigidBody> bodies);

/// Quality of a resolved contact set, measured from the bodies' velocities after resolution.
struct ContactResidual {
  double max_approach = 0.0;         ///< max over rows of max(0, t − v_n⁺) (m/s)
  double complementarity = 0.0;      ///< max over rows of |p · (v_n⁺ − t)| (N·m/s)
};

/// Measures the residual of `rows` with their applied impulse magnitudes `impulses`, against each row's
/// target velocity t (`targets`; empty: t = 0 for every row). A contact with a gap g has t = −g/dt
/// (gap_target): it may approach until the gap closes at the end of the step.
ContactResidual measure_residual(std::span<const ImpulseRow> rows, std::span<const double> impulses,
                                 std::span<const RigidBody> bodies, std::span<const double> targets = {});

/// The lowest normal velocity a contact of depth `depth` needs after the step (m/s): 0 when touching or
/// overlapping; −gap/dt for a gap (depth = −gap < 0), which closes exactly at the end of the step. A
/// speculative contact (a fast body met a step ahead, detection/fcl/README.md) stops the body at the
/// surface, never short of it.
inline double gap_target(double depth, double dt) { return depth < 0.0 ? depth / dt : 0.0; }

}  // namespace impetus::resolution
