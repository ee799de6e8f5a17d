#pragma once
/// \file
/// IMPETUS_PLUGIN: the one line a plugin's entry file needs. It defines the factory, the destructor, the
/// static descriptor and the exported entry symbol. Example (integrators/euler/plugin.cpp):
///
///     IMPETUS_PLUGIN(impetus::Integrator, EulerIntegrator, "euler", "1.0.0", "the paper's scheme (eq. 2)")
///
/// `Class` derives from `Base` and has a constructor `Class(const impetus::ModuleOptions&)` that reads
/// its options and throws (e.g. impetus::OptionError) on a bad one. Exceptions stop at the factory.
/// Build the library with impetus_add_plugin() so everything but the entry symbol is hidden.

#include "impetus/modules/detector.hpp"
#include "impetus/modules/integrator.hpp"
#include "impetus/modules/options.hpp"
#include "impetus/modules/resolver.hpp"
#include "impetus/plugins/abi.hpp"
#include "impetus/plugins/layout.hpp"

#include <cstdio>
#include <exception>

namespace impetus {

/// Maps a module base class to its ModuleKind.
template <typename Base>
struct ModuleKindOf;
template <>
struct ModuleKindOf<Integrator> { static constexpr ModuleKind value = ModuleKind::integrator; };
template <>
struct ModuleKindOf<CollisionDetector> { static constexpr ModuleKind value = ModuleKind::detector; };
template <>
struct ModuleKindOf<CollisionResolver> { static constexpr ModuleKind value = ModuleKind::resolver; };

namespace plugin_detail {
/// The factory body shared by every plugin: construct, and turn any exception into an error message.
template <typename Base, typename Class>
void* create(ModuleOptions* options, char* error, std::size_t capacity) noexcept {
  try {
    Base* module = new Class(*options);
    return static_cast<void*>(module);
  } catch (const std::exception& e) {
    std::snprintf(error, capacity, "%s", e.what());
  } catch (...) {
    std::snprintf(error, capacity, "unknown exception in the plugin's factory");
  }
  return nullptr;
}
template <typename Base>
void destroy(void* module) noexcept {
  delete static_cast<Base*>(module);
}
}  // namespace plugin_detail
}  // namespace impetus

#define IMPETUS_PLUGIN(Base, Class, NAME, VERSION, SUMMARY)                                          \
  extern "C" __attribute__((visibility("default"))) const ::impetus::PluginDescriptor*               \
  impetus_plugin_descriptor() {                                                                       \
    static const ::impetus::PluginDescriptor descriptor{                                              \
        ::impetus::kPluginAbiVersion,                                                                 \
        static_cast<std::uint32_t>(sizeof(::impetus::PluginDescriptor)),                              \
        ::impetus::plugin_config_word(),                                                              \
        static_cast<std::uint32_t>(::impetus::ModuleKindOf<Base>::value),                             \
        NAME,                                                                                         \
        VERSION,                                                                                      \
        SUMMARY,                                                                                      \
        &::impetus::plugin_detail::create<Base, Class>,                                               \
        &::impetus::plugin_detail::destroy<Base>,                                                     \
        ::impetus::plugin_layout_words()};                                                            \
    return &descriptor;                                                                               \
  }
