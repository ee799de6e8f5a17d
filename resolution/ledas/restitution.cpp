// Restitution (sec. 3.2, end): the inelastic impulses p, then the restitution phase e p, for a total of
// (1 + e) p; each row's e, with the bounce threshold judged per island.
#include "impetus/resolution/common/resting.hpp"
#include "island.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <algorithm>

namespace impetus {

// Restitution per island: the bounce threshold is judged on the island's fastest approach, because
// touching contacts carry the restitution phase too (impetus/resolution/common/resting.hpp).
void LedasResolver::assign_restitution(ledas::Island& island, std::span<const RigidBody> bodies) {
  const std::size_t m = island.rows.size();
  const ledas::Vector& v = current_velocities(island, bodies);
  double impact_speed = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (island.normal_row(i) && v(ei) <= island.target(ei) + settings_.tolerance)
      impact_speed = std::max(impact_speed, -v(ei));
  }
  for (std::size_t i = 0; i < m; ++i)
    if (island.normal_row(i))
      island.restitution(static_cast<Eigen::Index>(i)) =
          resolution::effective_restitution(rows_[island.rows[i]], impact_speed, settings_.resting);
}

// Applies one round: the inelastic impulses p (eq. 3), measures complementarity on that state, then the
// restitution phase e p (sec. 3.2: the total is (1 + e) p). Joint rows have e = 0.
void LedasResolver::finish_round(ledas::Island& island, const ledas::Vector& p, const ledas::Vector& target,
                                 std::span<RigidBody> bodies) {
  const std::size_t m = island.rows.size();
  for (std::size_t i = 0; i < m; ++i) resolution::apply_row_impulse(rows_[island.rows[i]], p(static_cast<Eigen::Index>(i)), bodies);
  island.impulse_inelastic += p;
  island.velocity_current = false;
  const ledas::Vector& v = current_velocities(island, bodies);
  island.measure_complementarity(v, target);
  for (std::size_t i = 0; i < m; ++i) {
    const auto ei = static_cast<Eigen::Index>(i);
    if (island.restitution(ei) != 0.0) {
      resolution::apply_row_impulse(rows_[island.rows[i]], island.restitution(ei) * p(ei), bodies);
      island.velocity_current = false;
    }
    island.impulse_total(ei) += (1.0 + island.restitution(ei)) * p(ei);
  }
}

}  // namespace impetus
