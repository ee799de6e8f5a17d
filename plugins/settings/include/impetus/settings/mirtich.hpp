#pragma once
/// \file
/// Typed settings of the `mirtich` resolver plugin (the sequential single-contact baseline): its scene
/// options as a struct, read by the plugin through from_options and written by to_options.
/// resolution/mirtich/README.md explains each option.

#include "impetus/settings/options_writer.hpp"
#include "impetus/settings/resting.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace impetus {

/// Which approaching contact the velocity sweep resolves next.
enum class MirtichOrder : std::uint8_t {
  /// The contact with the most negative v_n in its island; ties go to the lower contact index.
  most_approaching,
  /// Cyclic passes over the island's contacts in increasing contact index, resolving each approaching
  /// one as it is met (Gauss–Seidel order).
  index
};

/// Configuration of the sequential resolver (every option of the plugin).
struct MirtichSettings {
  /// The plugin these settings configure.
  static constexpr const char* plugin_name = "mirtich";

  MirtichOrder order = MirtichOrder::most_approaching;  ///< option `order: most_approaching | index`
  /// A contact approaches when v_n < −tolerance (m/s); the sweep stops when none does. Option `tolerance`.
  double tolerance = 1e-6;
  /// Cap on single impulses per island; 0 means automatic: max(10000, 100 × contacts in the island).
  /// Reaching it stops the sweep and counts the island in ResolverCounters::non_converged.
  /// Option `max_impulses`.
  std::uint64_t max_impulses = 0;
  /// Cap on Gauss–Seidel passes of the position correction per island. Option `position_iterations`.
  int position_iterations = 50;
  /// Resting-contact settings: options `slop`, `correction`, `bounce_threshold`.
  resolution::RestingSettings resting;

  /// Reads every option above; throws OptionError for a bad value.
  static MirtichSettings from_options(const ModuleOptions& options) {
    MirtichSettings s;
    s.order = options.choice("order", "most_approaching", {"most_approaching", "index"}) == "index"
                  ? MirtichOrder::index
                  : MirtichOrder::most_approaching;
    s.tolerance = options.number("tolerance", s.tolerance, 0.0, 1e3);
    s.max_impulses = static_cast<std::uint64_t>(options.integer("max_impulses", 0, 0, 1'000'000'000'000LL));
    s.position_iterations =
        static_cast<int>(options.integer("position_iterations", s.position_iterations, 0, 100000));
    s.resting = resolution::RestingSettings::from_options(options);
    return s;
  }

  /// The options a scene would give for these settings: every value that differs from the default.
  ModuleOptions to_options() const {
    using settings_detail::put;
    const MirtichSettings d;
    ModuleOptions o("plugin 'mirtich' (resolver)");
    put(o, "order", order == MirtichOrder::index ? "index" : "most_approaching", "most_approaching");
    put(o, "tolerance", tolerance, d.tolerance);
    put(o, "max_impulses", static_cast<long long>(max_impulses), static_cast<long long>(d.max_impulses));
    put(o, "position_iterations", static_cast<long long>(position_iterations),
        static_cast<long long>(d.position_iterations));
    resting.add_options(o);
    return o;
  }

  /// The impulse cap for an island of `contacts` contacts (max_impulses, or the automatic value).
  std::uint64_t impulse_cap(std::size_t contacts) const {
    if (max_impulses > 0) return max_impulses;
    return std::max<std::uint64_t>(10000, 100 * static_cast<std::uint64_t>(contacts));
  }
};

}  // namespace impetus
