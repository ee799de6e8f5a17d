#pragma once
/// \file
/// The sequential baseline resolver: one approaching contact at a time, each with the exact
/// single-contact frictionless impulse (Mirtich 1996, the paper's reference [4]; the paper's sec. 1
/// argues against it with Figure 1 and the "almost freezing" stacks). See resolution/mirtich/README.md
/// for what it assumes, guarantees and where it fails.
///
/// Notation (shared with impetus/resolution/common/impulse_rows.hpp): a contact k is a row with relative normal
/// velocity v_k = (u_b − u_a)·n_k (< 0 approaches) and A_kk = 1/m_eff (eq. 7 for i = k). Its single
/// impulse is
///   p_k = −(1 + e_k) v_k / A_kk,
/// which leaves v_k⁺ = −e_k v_k exactly (the paper's eq. 6 for m = 1, with the restitution of sec. 3.2).
///
/// With Coulomb friction (μ = combined_friction > 0 at a contact) the single impulse is instead
/// Mirtich's frictional collision integrated in the normal impulse (his thesis, ch. 4; friction.hpp):
/// slide, stick or slip reversal, exact at the slip's zero, with Stronge's energetic restitution
/// (never Newton's or Poisson's, which can create energy with friction), so no single collision gains
/// energy for e ≤ 1. A contact with μ = 0 keeps the closed form above, bit for bit.

#include "impetus/modules/options.hpp"
#include "impetus/modules/resolver.hpp"
#include "impetus/resolution/common/impulse_rows.hpp"
#include "impetus/resolution/common/resting.hpp"
#include "impetus/settings/mirtich.hpp"  // MirtichSettings

#include <cstdint>
#include <memory>

namespace impetus {

struct MirtichWorkspace;  // resolve()'s buffers (mirtich.cpp)

/// Sequential single-contact impulses, island by island:
///  1. velocity sweep: while some contact approaches (v_n < −tolerance) and the island's cap is not
///     reached, pick one (MirtichOrder) and apply its single-contact impulse with
///     e = effective_restitution(row, −v_n of that contact, resting): each single collision gets its
///     own impact speed (see resolution/mirtich/README.md for why this differs from `ledas`). If μ = 0
///     the impulse is p = −(1 + e) v_n / A_kk along n; if μ > 0 it is P = p_n n + p_t from
///     integrate_frictional_impact (e read as Stronge's coefficient);
///  2. position correction: Gauss–Seidel on pseudo-impulses q ≥ 0 (projected, accumulated) so that
///     A q ≥ correction_target(depth) with complementarity, then apply_row_displacement; velocities are
///     not touched by it.
/// Every applied normal impulse is ≥ 0, so `pulling_impulses` stays 0. Counters: islands, contacts (in
/// islands), rounds (= single impulses), non_converged (islands that hit the cap, and frictional
/// collisions whose integration hit its step cap or could not end), residual and
/// complementarity_error (measure_residual after the sweep), nan_caught / singular_systems (contacts
/// whose A_kk or impulse was not a finite positive number; they are skipped), sticking / sliding
/// (contacts by final mode, once each), friction_work (Σ of the exact ∫ u_t·dp_t of every frictional
/// collision, ≤ 0). natural_map_residual stays 0: a sequential resolver solves no simultaneous
/// frictional problem to measure it on.
///
/// Its buffers are kept from call to call: once a scene's contact count and islands stop growing, a
/// call allocates nothing. Not thread-safe (one resolver per world, as every resolver).
///
/// Each contact receives Contact::impulse (Σ p_n), Contact::tangent_impulse (Σ p_t) and Contact::mode:
/// separate if it received no impulse, stick if its slip after the sweep is at most `tolerance`, slide
/// otherwise.
class MirtichResolver final : public CollisionResolver {
 public:
  /// Reads the options; throws OptionError on a bad value.
  explicit MirtichResolver(const ModuleOptions& options);
  /// Builds the resolver from settings directly (tests, embedding).
  explicit MirtichResolver(const MirtichSettings& settings);
  ~MirtichResolver() override;

  /// Accepts Coulomb friction (Mirtich's frictional collision integration).
  ModuleStatus accept_friction() noexcept override { return ModuleStatus::success(); }

  /// Resolves `contacts` (constraints are refused by accept_constraints and ignored here), writing
  /// each contact's total impulse (N·s, ≥ 0) into Contact::impulse, its tangential impulse and mode.
  void resolve(std::span<RigidBody> bodies, std::span<Contact> contacts,
               std::span<const Constraint> constraints, const StepContext& ctx,
               ResolverCounters& counters) noexcept override;

  /// The settings read from the options.
  const MirtichSettings& settings() const { return settings_; }

 private:
  MirtichSettings settings_;
  std::unique_ptr<MirtichWorkspace> work_;
};

}  // namespace impetus
