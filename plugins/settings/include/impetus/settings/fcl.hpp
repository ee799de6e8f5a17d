#pragma once
/// \file
/// Typed settings of the `fcl` detector plugin: its scene options as a struct, read by the plugin
/// through from_options and written by to_options. detection/fcl/README.md explains each option.

#include "impetus/settings/options_writer.hpp"

#include <cstddef>

namespace impetus {

/// Settings of the `fcl` detector (scene options of the same names).
struct FclDetectorSettings {
  /// The plugin these settings configure.
  static constexpr const char* plugin_name = "fcl";

  /// Bodies within this distance of touching produce contacts, with depth = −gap (m, ≥ 0). It makes
  /// resting and exactly touching bodies robust to rounding; keep it far below the bodies' size.
  double margin = 1e-4;
  /// Most contacts kept per body pair (1…4), chosen to span the largest area; 0 keeps every point (no
  /// reduction: benchmarks/model.cpp measures what the reduction saves).
  int max_contacts_per_pair = 4;
  /// Points of one pair closer than this × the smaller body's bounding radius are merged into the
  /// deeper one (relative, 0 … 0.5).
  double merge_tolerance = 1e-3;
  /// Most broadphase candidate pairs per movable body (the limit is this × movable bodies, at least
  /// kMinPairLimit); beyond it the detection is refused (DetectorCounters::pair_limit) instead of
  /// allocating every pair: many bodies at one point. Touching equal spheres have at most 12 neighbours
  /// each (6 pairs per body); 0: no limit.
  int max_pairs_per_body = 16;
  /// The smallest pair limit, whatever the number of bodies.
  static constexpr std::size_t kMinPairLimit = 1024;
  /// Speculative contacts: a pair that can close by more than the margin within one step, and by more
  /// than half the thinner body's inner radius (so it could pass through it), is searched with its margin
  /// grown by that closing distance; the resolvers let such a gap close exactly at the end of the step
  /// and remove only the approach beyond it. false: the margin alone (fast bodies may tunnel).
  bool speculative = true;

  /// Reads `margin`, `max_contacts_per_pair`, `merge_tolerance`, `max_pairs_per_body` and `speculative`;
  /// throws OptionError on a bad value.
  static FclDetectorSettings from_options(const ModuleOptions& options) {
    FclDetectorSettings s;
    s.margin = options.number("margin", s.margin, 0.0, 1e3);
    s.max_contacts_per_pair =
        static_cast<int>(options.integer("max_contacts_per_pair", s.max_contacts_per_pair, 0, 4));
    s.merge_tolerance = options.number("merge_tolerance", s.merge_tolerance, 0.0, 0.5);
    s.max_pairs_per_body =
        static_cast<int>(options.integer("max_pairs_per_body", s.max_pairs_per_body, 0, 1'000'000));
    s.speculative = options.boolean("speculative", s.speculative);
    return s;
  }

  /// The options a scene would give for these settings: every value that differs from the default.
  ModuleOptions to_options() const {
    using settings_detail::put;
    const FclDetectorSettings d;
    ModuleOptions o("plugin 'fcl' (detector)");
    put(o, "margin", margin, d.margin);
    put(o, "max_contacts_per_pair", static_cast<long long>(max_contacts_per_pair),
        static_cast<long long>(d.max_contacts_per_pair));
    put(o, "merge_tolerance", merge_tolerance, d.merge_tolerance);
    put(o, "max_pairs_per_body", static_cast<long long>(max_pairs_per_body),
        static_cast<long long>(d.max_pairs_per_body));
    put(o, "speculative", speculative, d.speculative);
    return o;
  }
};

}  // namespace impetus
