#pragma once
/// \file
/// Typed settings of the `ledas` resolver plugin: the options a scene gives it, as a struct C++ code
/// fills in (misspellings fail at compile time) and hands to PluginHost::create_resolver. The plugin
/// reads its scene options into the same struct (from_options), so the two cannot drift apart.
/// resolution/ledas/README.md explains each option.

#include "impetus/settings/options_writer.hpp"
#include "impetus/settings/resting.hpp"

#include <cstddef>
#include <cstdint>

namespace impetus {

/// Which contacts enter the system and how it is solved.
enum class LedasMode : std::uint8_t {
  /// The paper's method (sec. 3.2) literally: only approaching contacts (v_n < −tolerance) enter;
  /// A p = b is solved as equalities, (1 + e) p applied (eq. 3), every contact re-checked, and the
  /// approaching ones solved again, round after round, until none approaches. Impulses may pull.
  paper,
  /// The frictionless inelastic impact solved exactly: approaching and touching contacts enter one
  /// system; an active set releases pulling impulses and adds approaching contacts until p ≥ 0,
  /// v_n⁺ ≥ 0, p·v_n⁺ = 0 at every contact (a linear complementarity problem); then (1 + e) p.
  complementary
};

/// Which touching contacts the complementary mode's active-set search starts with
/// (resolution/ledas/README.md, "The start set"). Only the first guess of the active set: the answer is
/// the same either way.
enum class LedasStartSet : std::uint8_t {
  /// Approaching contacts, and the touching ones that can pass the impact on: to a fixed body, or
  /// between two bodies at different distances (contact hops) from the impact. A touching contact across
  /// the impact's front (between bodies at the same distance) mostly separates, so it starts out.
  impact,
  /// Every approaching or touching contact.
  touching
};

namespace ledas {

/// How systems are solved (configuration; read once from the resolver's options).
struct SolverSettings {
  std::size_t dense_limit = 64;   ///< systems of at most this many rows use the dense path
  /// Complementary mode: a final system of at most this many rows gets the minimum-norm impulse split
  /// (an eigen-decomposition when it is singular, which costs more than the solve itself above ~16 rows).
  std::size_t polish_limit = 16;
  double rank_tolerance = 1e-10;  ///< a pivot or eigenvalue ≤ this × max A_ii counts as zero
  /// Sparse path: largest active-set change solved by an update of the last factorization; 0: automatic,
  /// max(8, √rows) (an update costs about its rows² × the elimination tree's height, ~√rows on a
  /// contact network, against ~rows^1.5 for a factorization).
  std::size_t update_limit = 0;
  std::uint64_t max_iterations = 10000;  ///< active-set iterations per complementarity problem
  /// Complementarity problems: proximal regularization ε = this × max A_kk (solve_complementarity): the
  /// first solve's and the final one.
  double regularization = 1e-10;
  /// Complementarity problems: the larger ε = this × max A_kk of the active-set search once the start set
  /// turned out not to be the answer (solve_complementarity); at most `regularization` disables it.
  double search_regularization = 1e-3;
  /// Complementarity problems: the exact solve on a candidate free set (conjugate gradients preconditioned
  /// by the search's factorization) may refactor at a smaller shift when it predicts that cheaper than
  /// the steps it would take (refine_on_free_set).
  bool sharpen_refinement = true;
  /// Complementarity problems of at least this many rows, with more rows than their bodies have
  /// coordinates (redundant contacts: bricks with four points per face) and no joint row, are solved
  /// first by a primal–dual interior point in body space, whose system stays positive definite; the
  /// active-set search takes over if it does not meet the search's own stopping rule. 0: never.
  std::size_t interior_point_rows = 500;
  /// Where that interior point stalls at the regularization's floor (resolution/ledas/README.md,
  /// "Creeping at the floor"), its best iterate is taken if no row approaches and its complementarity
  /// products are within this factor of the stopping rule's bound; else the active-set search takes
  /// over (exact, but up to thousands of iterations on a large wall). Below 1: never taken at a stall.
  double interior_point_stall_excess = 100.0;
};

}  // namespace ledas

/// Configuration of the `ledas` resolver (every option of the plugin).
struct LedasSettings {
  /// The plugin these settings configure (PluginHost::create_resolver(settings) loads it by this name).
  static constexpr const char* plugin_name = "ledas";

  LedasMode mode = LedasMode::complementary;  ///< option `mode: paper | complementary`
  /// Touch tolerance (m/s): a contact approaches when v_n < target − tolerance and touches when
  /// v_n ≤ target + tolerance. Option `tolerance`.
  double tolerance = 1e-9;
  /// Cap on rounds per island (paper mode; restitution rounds in complementary mode) and on active-set
  /// iterations per complementarity problem; reaching it counts in non_converged. Option `max_rounds`.
  std::uint64_t max_rounds = 1000000;
  /// Complementary mode: the active-set search's first guess. Option `start_set: impact | touching`.
  LedasStartSet start_set = LedasStartSet::impact;
  /// Options `dense_limit`, `polish_limit`, `rank_tolerance`, `update_limit`, `regularization`,
  /// `search_regularization`, `sharpen_refinement`, `interior_point_rows`, `interior_point_stall_excess`
  /// (max_iterations is set to max_rounds).
  ledas::SolverSettings solver;
  /// Solve each island (rows connected through movable bodies) on its own (default), or every row in
  /// one system (`islands: false`: the same velocities up to rounding, with the bounce threshold judged
  /// over all rows; only slower or faster, as benchmarks/model.cpp measures).
  bool islands = true;
  /// Frictional islands start from the last step's impulses of the contacts they still have (matched by
  /// bodies and the detector's feature key): a resting body's impulses usually solve the next step's
  /// problem as they are (`warm_start: false` starts every step from its convex relaxation).
  bool warm_start = true;
  /// Options `slop`, `correction`, `bounce_threshold` (impetus/settings/resting.hpp).
  resolution::RestingSettings resting;

  /// Reads every option above; throws OptionError for a bad value.
  static LedasSettings from_options(const ModuleOptions& options) {
    LedasSettings s;
    s.mode = options.choice("mode", "complementary", {"paper", "complementary"}) == "paper" ? LedasMode::paper
                                                                                           : LedasMode::complementary;
    s.tolerance = options.number("tolerance", s.tolerance, 0.0, 1.0);
    s.start_set = options.choice("start_set", "impact", {"impact", "touching"}) == "touching"
                      ? LedasStartSet::touching
                      : LedasStartSet::impact;
    s.max_rounds = static_cast<std::uint64_t>(
        options.integer("max_rounds", static_cast<long long>(s.max_rounds), 1, 1'000'000'000));
    s.solver.dense_limit = static_cast<std::size_t>(
        options.integer("dense_limit", static_cast<long long>(s.solver.dense_limit), 1, 100'000));
    s.solver.polish_limit = static_cast<std::size_t>(
        options.integer("polish_limit", static_cast<long long>(s.solver.polish_limit), 0, 100'000));
    s.solver.rank_tolerance = options.number("rank_tolerance", s.solver.rank_tolerance, 1e-16, 1e-2);
    s.solver.update_limit = static_cast<std::size_t>(
        options.integer("update_limit", static_cast<long long>(s.solver.update_limit), 0, 10'000));
    s.solver.regularization = options.number("regularization", s.solver.regularization, 1e-16, 1e-2);
    s.solver.search_regularization =
        options.number("search_regularization", s.solver.search_regularization, 0.0, 1e-1);
    s.solver.sharpen_refinement = options.boolean("sharpen_refinement", s.solver.sharpen_refinement);
    s.solver.interior_point_rows = static_cast<std::size_t>(options.integer(
        "interior_point_rows", static_cast<long long>(s.solver.interior_point_rows), 0, 1'000'000'000));
    s.solver.interior_point_stall_excess =
        options.number("interior_point_stall_excess", s.solver.interior_point_stall_excess, 0.0, 1e6);
    s.solver.max_iterations = s.max_rounds;
    s.islands = options.boolean("islands", s.islands);
    s.warm_start = options.boolean("warm_start", s.warm_start);
    s.resting = resolution::RestingSettings::from_options(options);
    return s;
  }

  /// The options a scene would give for these settings: every value that differs from the default.
  ModuleOptions to_options() const {
    using settings_detail::put;
    const LedasSettings d;
    ModuleOptions o("plugin 'ledas' (resolver)");
    put(o, "mode", mode == LedasMode::paper ? "paper" : "complementary", "complementary");
    put(o, "tolerance", tolerance, d.tolerance);
    put(o, "start_set", start_set == LedasStartSet::touching ? "touching" : "impact", "impact");
    put(o, "max_rounds", static_cast<long long>(max_rounds), static_cast<long long>(d.max_rounds));
    put(o, "dense_limit", static_cast<long long>(solver.dense_limit), static_cast<long long>(d.solver.dense_limit));
    put(o, "polish_limit", static_cast<long long>(solver.polish_limit), static_cast<long long>(d.solver.polish_limit));
    put(o, "rank_tolerance", solver.rank_tolerance, d.solver.rank_tolerance);
    put(o, "update_limit", static_cast<long long>(solver.update_limit), static_cast<long long>(d.solver.update_limit));
    put(o, "regularization", solver.regularization, d.solver.regularization);
    put(o, "search_regularization", solver.search_regularization, d.solver.search_regularization);
    put(o, "sharpen_refinement", solver.sharpen_refinement, d.solver.sharpen_refinement);
    put(o, "interior_point_rows", static_cast<long long>(solver.interior_point_rows),
        static_cast<long long>(d.solver.interior_point_rows));
    put(o, "interior_point_stall_excess", solver.interior_point_stall_excess, d.solver.interior_point_stall_excess);
    put(o, "islands", islands, d.islands);
    put(o, "warm_start", warm_start, d.warm_start);
    resting.add_options(o);
    return o;
  }
};

}  // namespace impetus
