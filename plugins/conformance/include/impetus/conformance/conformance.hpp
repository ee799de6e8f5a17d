#pragma once
/// \file
/// The conformance suites: one GoogleTest suite per module kind that checks the promises of its contract
/// (impetus/modules/*.hpp) on a plugin loaded from its .so through the plugin host, exactly as a scene
/// would load it. The suites' tests are value-parameterized by PluginUnderTest; the CMake function
/// impetus_add_conformance_tests() (cmake/ImpetusConformance.cmake) generates the instantiation for a
/// plugin, so a plugin written outside Impetus runs the same suite as the shipped ones.
///
/// Test-only code: it uses GoogleTest and throws impetus::Error through the host on a load failure.

#include "impetus/conformance/fixtures.hpp"
#include "impetus/core/body.hpp"
#include "impetus/core/math.hpp"
#include "impetus/core/shape.hpp"
#include "impetus/modules/contact.hpp"
#include "impetus/modules/detector.hpp"
#include "impetus/modules/integrator.hpp"
#include "impetus/modules/options.hpp"
#include "impetus/modules/resolver.hpp"
#include "impetus/plugins/abi.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <ostream>
#include <set>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace impetus::conformance {

/// One plugin file to test, with the options it is created with and what it claims beyond its contract.
struct PluginUnderTest {
  std::string label;                   ///< test-name suffix: letters, digits and _ (e.g. "ledas_paper")
  std::filesystem::path file;          ///< the plugin's shared library
  /// Options given to every module the suite creates, as (key, value) written in a scene.
  std::vector<std::pair<std::string, std::string>> options;
  /// Documented capabilities that enable extra tests:
  ///   integrator `angular_momentum` — conserves L without torque (a tumbling asymmetric body);
  ///   resolver `elastic` — conserves kinetic energy when every contact has e = 1;
  ///   detector `margin` — reads the option `margin` (m): gaps up to it are contacts of depth −gap.
  std::set<std::string> claims;
  /// Largest approach velocity (m/s) a resolver may leave at a contact (resolvers: its touch tolerance).
  double approach_tolerance = 1e-6;

  bool claims_capability(const std::string& name) const { return claims.count(name) != 0; }
};

/// For GoogleTest's messages.
inline void PrintTo(const PluginUnderTest& plugin, std::ostream* out) { *out << plugin.label << " (" << plugin.file << ")"; }
/// Test-name suffix of an instantiation.
inline std::string plugin_label(const ::testing::TestParamInfo<PluginUnderTest>& info) { return info.param.label; }

/// The plugin's options as a scene would give them (where: "conformance"), plus `extra`.
ModuleOptions options_for(const PluginUnderTest& plugin,
                          const std::vector<std::pair<std::string, std::string>>& extra = {});

/// Loads the plugin file through a PluginHost and creates one module with options_for(plugin, extra).
/// Throws impetus::Error with the host's message when the plugin does not load.
std::shared_ptr<Integrator> load_integrator(const PluginUnderTest& plugin,
                                            const std::vector<std::pair<std::string, std::string>>& extra = {});
std::shared_ptr<CollisionDetector> load_detector(const PluginUnderTest& plugin,
                                                 const std::vector<std::pair<std::string, std::string>>& extra = {});
std::shared_ptr<CollisionResolver> load_resolver(const PluginUnderTest& plugin,
                                                 const std::vector<std::pair<std::string, std::string>>& extra = {});

/// The message of the impetus::Error the loader throws for an option the plugin does not read, or a
/// failure of the test if it loads.
std::string unknown_option_message(const PluginUnderTest& plugin, ModuleKind kind, const std::string& key);

// --- bodies, built without the engine (mass properties in closed form) ---

// Bodies and contacts built by hand: impetus/conformance/fixtures.hpp.

// --- measures of the movable bodies (fixed bodies carry none) ---

/// Σ m v (N·s).
Vec3 linear_momentum(std::span<const RigidBody> bodies);
/// Σ (x × m v + J_world ω) about the world origin (N·m·s).
Vec3 angular_momentum(std::span<const RigidBody> bodies);
/// Σ ½ m v² + ½ ωᵀ J_world ω (J).
double kinetic_energy(std::span<const RigidBody> bodies);

/// The resolver suite. Tests: see resolver_suite.cpp.
class ResolverConformance : public ::testing::TestWithParam<PluginUnderTest> {};
/// The integrator suite. Tests: see integrator_suite.cpp.
class IntegratorConformance : public ::testing::TestWithParam<PluginUnderTest> {};
/// The detector suite. Tests: see detector_suite.cpp.
class DetectorConformance : public ::testing::TestWithParam<PluginUnderTest> {};

}  // namespace impetus::conformance
