#pragma once
/// \file
/// The collision resolver module contract.

#include "impetus/core/body.hpp"
#include "impetus/modules/constraint.hpp"
#include "impetus/modules/contact_problem.hpp"
#include "impetus/modules/contact.hpp"
#include "impetus/modules/status.hpp"
#include "impetus/modules/step.hpp"

#include <cstdint>
#include <span>

namespace impetus {

/// Changes body velocities by impulses so that no contact approaches (and constraints hold). A fixed
/// body never changes, but it may have velocities (a prescribed motion): relative velocities take every
/// body's velocity_at() the contact point, fixed or not. A resolver
/// may also correct penetration by moving positions directly, provided it leaves velocities (and so
/// kinetic energy) untouched by that correction.
class CollisionResolver {
 public:
  virtual ~CollisionResolver() = default;

  /// Checked once when a world is built: fails (naming the constraint) for constraints this resolver
  /// cannot enforce. The default accepts none.
  virtual ModuleStatus accept_constraints(std::span<const Constraint> constraints) noexcept {
    return constraints.empty() ? ModuleStatus::success()
                               : ModuleStatus::failure("this resolver does not support constraints");
  }

  /// Checked when a world is built and when a body is added, if any body has `friction` > 0: fails
  /// (saying why) if this resolver does not model Coulomb friction, so a scene's friction is never
  /// silently ignored. The default refuses.
  virtual ModuleStatus accept_friction() noexcept {
    return ModuleStatus::failure("this resolver does not model friction");
  }

  /// Solves a frictional contact problem given directly in local form (contact_problem.hpp), e.g. one read
  /// from an fclib file, writing `solution`. Fails (saying why) if this resolver has no such solver or
  /// the problem is outside what it solves; an unsolved problem is a success with converged = false and
  /// its best iterate. The default refuses.
  virtual ModuleStatus solve_contact_problem(const LocalContactProblem& problem,
                                             LocalContactSolution& solution) noexcept {
    (void)problem;
    (void)solution;
    return ModuleStatus::failure("this resolver does not solve contact problems in local form");
  }

  /// Told when bodies were removed from the world between steps: `new_index[i]` is the new index of
  /// the body that had index i, or −1 for a removed body. A resolver that carries anything keyed by body
  /// index from step to step (warm starts) renumbers or drops it here. The default keeps nothing.
  virtual void bodies_removed(std::span<const std::int64_t> new_index) noexcept { (void)new_index; }

  /// Applies impulses to `bodies` for `contacts` (writing each contact's total `impulse`,
  /// `tangent_impulse` and `mode`) and
  /// `constraints`, following the Contact sign convention.
  virtual void resolve(std::span<RigidBody> bodies, std::span<Contact> contacts,
                       std::span<const Constraint> constraints, const StepContext& ctx,
                       ResolverCounters& counters) noexcept = 0;
};

}  // namespace impetus
