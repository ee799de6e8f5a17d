#pragma once
/// \file
/// Typed settings of the shipped integrator plugins `euler`, `momentum` and `splitting`: one option,
/// `orthonormalize`, read by each plugin through RotationSettings::from_options. One struct per plugin so
/// that the type names the plugin (PluginHost::create_integrator(settings)).

#include "impetus/settings/options_writer.hpp"

namespace impetus {
namespace integrators {

/// Options of the rotation step, shared by every eq. 2 integrator.
struct RotationSettings {
  /// Re-orthonormalize R after every rotation step (the paper, after eq. 2), counted in
  /// IntegratorCounters::orthonormalized. Scene option `orthonormalize` (bool, default true).
  bool orthonormalize = true;

  /// Reads the options above; throws OptionError on a bad value.
  static RotationSettings from_options(const ModuleOptions& options) {
    RotationSettings settings;
    settings.orthonormalize = options.boolean("orthonormalize", settings.orthonormalize);
    return settings;
  }
  /// The options a scene would give for these settings (those that differ from the default).
  ModuleOptions to_options(const char* label) const {
    ModuleOptions o(label);
    settings_detail::put(o, "orthonormalize", orthonormalize, RotationSettings{}.orthonormalize);
    return o;
  }
};

}  // namespace integrators

/// The `euler` integrator (the paper's eq. 2).
struct EulerSettings : integrators::RotationSettings {
  static constexpr const char* plugin_name = "euler";
  ModuleOptions to_options() const { return RotationSettings::to_options("plugin 'euler' (integrator)"); }
};
/// The `momentum` integrator (eq. 2 with the angular momentum carried; the default).
struct MomentumSettings : integrators::RotationSettings {
  static constexpr const char* plugin_name = "momentum";
  ModuleOptions to_options() const { return RotationSettings::to_options("plugin 'momentum' (integrator)"); }
};
/// The `splitting` integrator (free-rigid-body splitting by principal axes).
struct SplittingSettings : integrators::RotationSettings {
  static constexpr const char* plugin_name = "splitting";
  ModuleOptions to_options() const { return RotationSettings::to_options("plugin 'splitting' (integrator)"); }
};

}  // namespace impetus
