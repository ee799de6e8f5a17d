#pragma once
/// \file
/// The LEDAS simultaneous impulse resolver (Ermolin & Kazakov, "Impulse-based Approach for Rigid Body
/// Collisions Simultaneous Resolution"; conventions and typos in docs/conventions.md).
/// resolution/ledas/README.md derives A and b with their signs and says what the method assumes,
/// guarantees and where it fails.
///
/// Notation (impetus/resolution/common/impulse_rows.hpp): row k (a contact or a joint direction) has
/// v_k = (u_b − u_a)·n_k (< 0 approaches); impulses p act −p n on a and +p n on b (eq. 3, sign fixed);
/// the rows' velocities change by A p with A = G M⁻¹ Gᵀ (eq. 7), and eq. 4's inelastic condition is
/// A p = b with b = target − v⁻ (eq. 8 with its sign fixed; target = 0 for a touching contact).

#include "impetus/modules/options.hpp"
#include "impetus/modules/resolver.hpp"
#include "impetus/resolution/common/impulse_rows.hpp"
#include "impetus/resolution/common/resting.hpp"
#include "impetus/resolution/ledas/constraint_rows.hpp"
#include "impetus/resolution/ledas/frictional_solver.hpp"
#include "impetus/resolution/ledas/island_solver.hpp"
#include "impetus/settings/ledas.hpp"  // LedasSettings, LedasMode, LedasStartSet

#include <compare>
#include <cstdint>
#include <memory>
#include <vector>

namespace impetus {

namespace ledas {
struct Island;  // one island's working data (island.hpp)
}  // namespace ledas

/// What the last resolve() did, in more detail than ResolverCounters (for tests and benchmarks).
struct LedasStats {
  std::uint64_t islands = 0;         ///< islands solved
  std::size_t largest_island = 0;    ///< rows of the largest island
  std::uint64_t rounds = 0;          ///< most rounds in one island (paper: solve rounds; complementary: restitution rounds)
  std::uint64_t systems = 0;         ///< linear systems solved in the velocity phase (= ResolverCounters::rounds)
  std::uint64_t pulling_applied = 0; ///< paper mode: negative impulses applied
  ledas::SolverStats velocity;       ///< the solver's counts in the velocity phase
  ledas::SolverStats position;       ///< ... and in the position correction
  double kinetic_energy_change = 0.0;  ///< Σ over islands of the velocity phase's ΔE_kin (J)
  ledas::FrictionalStats friction;   ///< the frictional solver's counts (islands with friction)
  /// Frictional islands whose restitution phase was scaled back so as not to raise the kinetic energy
  /// above its pre-impact value (resolution/ledas/README.md, "Restitution with friction").
  std::uint64_t restitution_capped = 0;
  /// Position corrections scaled down to the displacement bound (resolution/common/resting.hpp).
  std::uint64_t corrections_clamped = 0;
  /// Constraints identical to an earlier one, left out of the system (their rows would repeat it).
  std::uint64_t duplicate_constraints = 0;
  double largest_correction = 0.0;  ///< largest displacement a position correction gave a row point (m)
};

/// Adds the statistics of `part` (some islands of a resolve) to `into`: counts and the energy change add
/// up, the largest values stay the largest.
void add(LedasStats& into, const LedasStats& part);

/// The LEDAS resolver: contacts and assembly constraints (point-point, coaxial) in one system per island.
///
/// Per island: (1) velocity phase by `mode`; (2) position correction: the complementarity problem
/// A q ≥ correction_target(depth), q ≥ 0 (same solver, joints as equality rows with target 0), applied
/// with resolution::apply_row_displacement (no velocity change). Contact::impulse gets each contact's
/// total impulse Σ (1 + e) p (N·s).
///
/// Friction (complementary mode; resolution/ledas/README.md, "Friction"): a contact with μ > 0 adds two
/// tangent rows after its normal row, and its island's velocity phase is the frictional contact problem
/// (frictional_solver.hpp) in two phases, inelastic then restitution capped at the pre-impact energy;
/// Contact::tangent_impulse and Contact::mode are written for every contact. The position correction
/// acts along normals only.
///
/// Gap contacts (depth < 0, within the detector's margin) are speculative: a gap contact takes part only
/// if it would close within the step (v_n·dt < depth) and then asks v_n⁺ ≥ depth/dt, so the gap closes
/// exactly at the end of the step; with restitution (e > 0 after the bounce threshold) it asks v_n⁺ ≥ 0
/// instead, so a bounce keeps its energy and turns back at most the margin early.
///
/// Counters: islands; contacts (that entered a system); rounds (linear systems solved in the velocity
/// phase: rounds in paper mode, active-set iterations in complementary mode); pulling_impulses (paper:
/// negative impulses applied; complementary: negative impulses released by the active set);
/// non_converged; redundant_systems (rank-deficient systems the minimum-norm solution satisfies);
/// singular_systems (rank-deficient systems it does not: conflicting targets); nan_caught (bad contacts, non-finite
/// solutions); residual (largest v_n approach left below the target, m/s); complementarity_error
/// (max |P·(v_n − target)| after the inelastic phase, P the total inelastic impulse); energy_gain_events
/// (islands with restitution whose kinetic energy rose, possible only with mixed restitution).
class LedasResolver final : public CollisionResolver {
 public:
  /// Reads the options; throws OptionError on a bad value.
  explicit LedasResolver(const ModuleOptions& options);
  /// Builds the resolver from settings directly (tests, embedding).
  explicit LedasResolver(const LedasSettings& settings = {});
  ~LedasResolver() override;

  /// Accepts point-point and coaxial constraints at either level; refuses one with a bad axis or length.
  ModuleStatus accept_constraints(std::span<const Constraint> constraints) noexcept override;
  /// Complementary mode models Coulomb friction; paper mode refuses it (the paper gives no friction
  /// formulas for its rounds).
  ModuleStatus accept_friction() noexcept override;

  /// Solves a frictional contact problem in local form with the frictional solver (complementary mode;
  /// ledas::solve_local_problem); last_stats().friction gets its counts.
  ModuleStatus solve_contact_problem(const LocalContactProblem& problem,
                                     LocalContactSolution& solution) noexcept override;

  /// Renumbers the warm starts kept from the last step and drops those of removed bodies.
  void bodies_removed(std::span<const std::int64_t> new_index) noexcept override;

  /// Resolves `contacts` and `constraints` (see the class comment), writing Contact::impulse.
  void resolve(std::span<RigidBody> bodies, std::span<Contact> contacts, std::span<const Constraint> constraints,
               const StepContext& ctx, ResolverCounters& counters) noexcept override;

  const LedasSettings& settings() const { return settings_; }
  /// Details of the last resolve().
  const LedasStats& last_stats() const { return stats_; }

 private:
  // One worker's solvers, statistics and scratch (lane.hpp). The islands of a step are dealt to the
  // lanes by a body of theirs (lane_of: the lower movable body of an island's first row) and the lanes
  // run in parallel, each on its islands in order; a lane's caches (symbolic analyses) thus see the same
  // islands in the same order whatever the number of threads, and the lanes' statistics are added up in
  // lane order, so the results are bit-identical for every thread count. Dealt by a body rather than by
  // the island's index, an island that persists stays in its lane from step to step, where its last
  // pattern's analysis is cached and its buffers have its sizes, when islands appear or vanish before it.
  struct Lane;
  static constexpr std::size_t kLanes = 256;

  // The stages of one resolve(), each in its own file: ledas.cpp (rows, islands, report), island.cpp
  // (an island's system), paper_rounds.cpp, complementary_impact.cpp, restitution.cpp,
  // position_correction.cpp.
  void resolve_all(std::span<RigidBody> bodies, std::span<Contact> contacts, std::span<const Constraint> constraints,
                   const StepContext& ctx, ResolverCounters& counters);
  void build_rows(std::span<const RigidBody> bodies, std::span<Contact> contacts,
                  std::span<const Constraint> constraints, double dt, ResolverCounters& counters);
  void solve_island(std::span<const std::uint32_t> rows, std::span<RigidBody> bodies, std::span<Contact> contacts,
                    double dt, Lane& lane);
  void make_island(std::span<const std::uint32_t> rows, std::span<const RigidBody> bodies, double dt,
                   ledas::Island& island);
  void assign_restitution(ledas::Island& island, std::span<const RigidBody> bodies);
  const ledas::Vector& current_velocities(ledas::Island& island, std::span<const RigidBody> bodies) const;
  void velocity_paper(ledas::Island& island, std::span<RigidBody> bodies, Lane& lane);
  void velocity_complementary(ledas::Island& island, std::span<RigidBody> bodies, Lane& lane);
  void velocity_frictional(ledas::Island& island, std::span<RigidBody> bodies, Lane& lane);
  ledas::Vector& solve_frictional(Lane& lane, ledas::Island& island, const ledas::Vector& v,
                                  const ledas::Vector& target, bool warm);
  bool warm_start(ledas::Island& island) const;
  void remember_impulses(Lane& lane, const ledas::Island& island, std::span<const Contact> contacts) const;
  void apply_island_impulse(ledas::Island& island, const ledas::Vector& p, std::span<RigidBody> bodies,
                            Lane& lane);
  void add_closable_gaps(const ledas::Island& island, const ledas::Vector& v, std::vector<char>& start) const;
  void narrow_start_set(Lane& lane, const ledas::Island& island, const ledas::Vector& v, std::vector<char>& start);
  void finish_round(ledas::Island& island, const ledas::Vector& p, const ledas::Vector& target,
                    std::span<RigidBody> bodies);
  void report_island(ledas::Island& island, std::span<const RigidBody> bodies, std::span<Contact> contacts,
                     ResolverCounters& counters);
  bool solve_correction(ledas::Island& island, std::span<const RigidBody> bodies, Lane& lane);
  void apply_correction(ledas::Island& island, std::span<RigidBody> bodies, Lane& lane);
  void velocity_phase(ledas::Island& island, std::span<RigidBody> bodies, std::span<Contact> contacts, Lane& lane);
  Lane& lane(std::size_t index);
  static std::size_t lane_of(BodyIndex body);

  LedasSettings settings_;
  ledas::SolverSettings solver_settings_;     // the lanes' island solvers'
  std::vector<std::unique_ptr<Lane>> lanes_;  // created when first used
  std::vector<std::size_t> lane_order_;        // this step's lanes, heaviest first (resolve_all)
  std::vector<double> lane_load_;
  // This step's dealing: each island's lane, and the islands by lane (lane k's in lane_islands_
  // [lane_start_[k], lane_start_[k + 1]), increasing); lane_next_ is the fill's cursor.
  std::vector<std::size_t> island_lane_, lane_start_, lane_islands_, lane_next_;
  ledas::FrictionalSolver friction_solver_;   // solve_contact_problem's
  LedasStats stats_;
  std::vector<resolution::ImpulseRow> rows_;  // this step's rows: contacts first, then joint rows
  std::vector<ledas::RowInfo> info_;
  resolution::IslandSet islands_;            // this step's islands (rows_ indices)
  resolution::InverseInertiaCache inertia_;  // the bodies' J⁻¹ while this step's rows are built
  std::vector<std::int32_t> body_slot_;  // per body: its slot in its island's movable bodies, or −1
  // Warm starts: a frictional contact's inelastic impulse (normal; tangential as a world vector) by its
  // bodies and feature key, from the last step (`warm_`) and for the next (`next_warm_`); per row of
  // this step, the warm start found for it (0 if none).
  struct ContactKey {
    BodyIndex a = 0, b = 0;
    std::uint64_t feature = 0;
    auto operator<=>(const ContactKey&) const = default;
  };
  struct ContactImpulse {
    double normal = 0.0;
    Vec3 tangent = Vec3::Zero();
  };
  // Sorted by key, unique (a flat map: swapped and refilled step after step without allocating); `order`
  // is the entry's place in the lanes' lists, so that of two contacts with one key the last is kept.
  struct WarmStart {
    ContactKey key;
    ContactImpulse impulse;
    std::size_t order = 0;
  };
  std::vector<WarmStart> warm_, next_warm_;
  const ContactImpulse* find_warm(const ContactKey& key) const;
  std::vector<double> row_warm_;
};

}  // namespace impetus
