// Loading through the plugin host, hand-built bodies and whole-system measures for the conformance
// suites. Measures are computed here, independently of any plugin's algebra.
#include "impetus/conformance/conformance.hpp"

#include "impetus/core/error.hpp"
#include "impetus/plugins/host.hpp"

namespace impetus::conformance {

namespace {

using Extra = std::vector<std::pair<std::string, std::string>>;

PluginRequest request_for(const PluginUnderTest& plugin, ModuleOptions& options) {
  PluginRequest request;
  request.file = plugin.file;
  request.options = &options;
  request.where = "conformance";
  return request;
}

}  // namespace

ModuleOptions options_for(const PluginUnderTest& plugin, const Extra& extra) {
  ModuleOptions options("plugin '" + plugin.label + "'");
  for (const auto& list : {plugin.options, extra})
    for (const auto& [key, value] : list) options.set(key, OptionValue{value, {}, false, "conformance"});
  return options;
}

// The host is only needed while loading: each module keeps its library loaded.
std::shared_ptr<Integrator> load_integrator(const PluginUnderTest& plugin, const Extra& extra) {
  ModuleOptions options = options_for(plugin, extra);
  return PluginHost().create_integrator(request_for(plugin, options));
}

std::shared_ptr<CollisionDetector> load_detector(const PluginUnderTest& plugin, const Extra& extra) {
  ModuleOptions options = options_for(plugin, extra);
  return PluginHost().create_detector(request_for(plugin, options));
}

std::shared_ptr<CollisionResolver> load_resolver(const PluginUnderTest& plugin, const Extra& extra) {
  ModuleOptions options = options_for(plugin, extra);
  return PluginHost().create_resolver(request_for(plugin, options));
}

std::string unknown_option_message(const PluginUnderTest& plugin, ModuleKind kind, const std::string& key) {
  const Extra extra{{key, "1"}};
  try {
    switch (kind) {
      case ModuleKind::integrator: load_integrator(plugin, extra); break;
      case ModuleKind::detector: load_detector(plugin, extra); break;
      case ModuleKind::resolver: load_resolver(plugin, extra); break;
    }
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "the plugin was created with the unknown option '" << key << "'";
  return {};
}

Vec3 linear_momentum(std::span<const RigidBody> bodies) {
  Vec3 p = Vec3::Zero();
  for (const RigidBody& b : bodies)
    if (!b.fixed) p += b.mass * b.velocity;
  return p;
}

Vec3 angular_momentum(std::span<const RigidBody> bodies) {
  Vec3 l = Vec3::Zero();
  for (const RigidBody& b : bodies)
    if (!b.fixed) l += b.position.cross(b.mass * b.velocity) + b.inertia_world() * b.angular_velocity;
  return l;
}

double kinetic_energy(std::span<const RigidBody> bodies) {
  double e = 0.0;
  for (const RigidBody& b : bodies)
    if (!b.fixed)
      e += 0.5 * b.mass * b.velocity.squaredNorm() + 0.5 * b.angular_velocity.dot(b.inertia_world() * b.angular_velocity);
  return e;
}

}  // namespace impetus::conformance
