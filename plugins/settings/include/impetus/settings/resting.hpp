#pragma once
/// \file
/// Resting-contact settings shared by the impulse resolvers (`ledas`, `mirtich`): options `slop`,
/// `correction`, `bounce_threshold` (resolution/common/resting.hpp explains them).

#include "impetus/settings/options_writer.hpp"

namespace impetus::resolution {

/// Resting-contact settings, read from a resolver's options.
struct RestingSettings {
  double slop = 1e-4;              ///< penetration left alone (m); option `slop`
  double correction = 0.2;         ///< fraction of the remaining penetration removed per step, [0, 1]; option `correction`
  double bounce_threshold = 0.05;  ///< approach speed below which restitution is not applied (m/s); option `bounce_threshold`

  /// Reads `slop`, `correction`, `bounce_threshold`; throws OptionError for a bad value.
  static RestingSettings from_options(const ModuleOptions& options) {
    RestingSettings s;
    s.slop = options.number("slop", s.slop, 0.0, 1.0);
    s.correction = options.number("correction", s.correction, 0.0, 1.0);
    s.bounce_threshold = options.number("bounce_threshold", s.bounce_threshold, 0.0, 1e3);
    return s;
  }
  /// Adds the values that differ from the defaults to `options`.
  void add_options(ModuleOptions& options) const {
    const RestingSettings d;
    settings_detail::put(options, "slop", slop, d.slop);
    settings_detail::put(options, "correction", correction, d.correction);
    settings_detail::put(options, "bounce_threshold", bounce_threshold, d.bounce_threshold);
  }
};

}  // namespace impetus::resolution
