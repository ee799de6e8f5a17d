#pragma once
/// \file
/// The plugin ABI: what one Impetus plugin shared library exports and what the host checks.
///
/// A plugin library exports exactly one symbol, `extern "C" impetus_plugin_descriptor`, a function
/// returning a pointer to a static PluginDescriptor. The host checks, in this order: the ABI version,
/// the descriptor's size, the config word (build settings that change the layout of shared types),
/// the layout words (the layout of every type that crosses the boundary, impetus/plugins/layout.hpp),
/// the kind, and the name; then calls `create`. Objects a plugin creates are destroyed by its own
/// `destroy`, and the library stays loaded while any of them lives.
///
/// Across the boundary: no exceptions (create reports failure through its error buffer), no
/// dynamic_cast (the kind says which base class the returned pointer is), no host singletons.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace impetus {

class ModuleOptions;

/// Version of this ABI. Bump on any change to PluginDescriptor or to the module interfaces.
/// 2: the descriptor carries the layout words. 3: friction (CollisionResolver::accept_friction, the
/// contact's tangential impulse and mode, the resolver's friction counters). 4: local contact problems
/// (CollisionResolver::solve_contact_problem, LocalContactProblem, LocalContactSolution).
/// 5: ResolverCounters::redundant_systems (redundant contact sets solved by minimum norm, told apart from
/// singular_systems, which now counts only real failures).
/// 6: applied loads in the body frame and prescribed motion of fixed bodies (RigidBody::force_body,
/// torque_body, motion); CollisionResolver::bodies_removed. 7: RigidBody::asleep (sleeping islands).
/// 8: pathological scenes (DetectorCounters::pair_limit, crowded_body, crowded_pairs;
/// ResolverCounters::work_limited, corrections_clamped, largest_correction).
/// 9: speculative contacts (DetectorCounters::speculative_pairs).
inline constexpr std::uint32_t kPluginAbiVersion = 9;

/// Name of the entry symbol every plugin exports.
inline constexpr const char* kPluginEntrySymbol = "impetus_plugin_descriptor";

/// The kinds of module a plugin can provide.
enum class ModuleKind : std::uint32_t { integrator = 1, detector = 2, resolver = 3 };

/// "integrator", "detector", "resolver", or "unknown".
inline const char* module_kind_name(ModuleKind kind) {
  switch (kind) {
    case ModuleKind::integrator: return "integrator";
    case ModuleKind::detector: return "detector";
    case ModuleKind::resolver: return "resolver";
  }
  return "unknown";
}

/// The types whose objects cross the plugin boundary by memory layout (passed by pointer, reference or
/// span between host and plugin). Each has one layout word in the descriptor, at this index.
enum class LayoutType : std::uint32_t {
  rigid_body, material, shape, sphere, box, capsule, cylinder, plane, mesh_shape, triangle_mesh,
  contact, point_point_constraint, coaxial_constraint, constraint, step_context, integrator_counters,
  detector_counters, resolver_counters, module_status, module_options, option_value, body_pair,
  local_contact_problem, local_contact_solution,
  count  ///< not a type: the number of layout words
};
/// Number of layout words in a descriptor.
inline constexpr std::size_t kLayoutTypeCount = static_cast<std::size_t>(LayoutType::count);
/// The qualified C++ name of each LayoutType, for messages.
inline constexpr std::array<const char*, kLayoutTypeCount> kLayoutTypeNames{
    "impetus::RigidBody", "impetus::Material", "impetus::Shape", "impetus::Sphere", "impetus::Box",
    "impetus::Capsule", "impetus::Cylinder", "impetus::Plane", "impetus::MeshShape", "impetus::TriangleMesh",
    "impetus::Contact", "impetus::PointPointConstraint", "impetus::CoaxialConstraint", "impetus::Constraint",
    "impetus::StepContext", "impetus::IntegratorCounters", "impetus::DetectorCounters",
    "impetus::ResolverCounters", "impetus::ModuleStatus", "impetus::ModuleOptions", "impetus::OptionValue",
    "impetus::BodyPair", "impetus::LocalContactProblem", "impetus::LocalContactSolution"};
/// One layout word per LayoutType (plugin_layout_words() of a build).
using LayoutWords = std::array<std::uint64_t, kLayoutTypeCount>;

/// Factory signature: builds a module from its options. On failure returns null and writes a message
/// (NUL-terminated, at most `error_capacity` bytes) into `error`. Never throws.
using PluginCreateFn = void* (*)(ModuleOptions* options, char* error, std::size_t error_capacity);
/// Destroys an object returned by the same plugin's create.
using PluginDestroyFn = void (*)(void* module);

/// The static description of a plugin, returned by its entry symbol.
struct PluginDescriptor {
  std::uint32_t abi_version;      ///< kPluginAbiVersion the plugin was built with
  std::uint32_t descriptor_size;  ///< sizeof(PluginDescriptor) the plugin was built with
  std::uint64_t config_word;      ///< plugin_config_word() of the plugin's build
  std::uint32_t kind;             ///< a ModuleKind
  const char* name;               ///< the name scenes use, e.g. "euler"
  const char* version;            ///< the plugin's own version, e.g. "1.0.0"
  const char* summary;            ///< one line for `impetus plugins`
  PluginCreateFn create;
  PluginDestroyFn destroy;
  LayoutWords layout_words;       ///< plugin_layout_words() of the plugin's build, by LayoutType
};

/// Signature of the entry symbol.
using PluginEntryFn = const PluginDescriptor* (*)();

// Config word layout (bits): what must agree between host and plugin for shared types to match.
namespace config_bits {
inline constexpr std::uint64_t scalar_double = 1ull << 0;   ///< Scalar is double
inline constexpr std::uint64_t cxx11_abi = 1ull << 1;       ///< libstdc++ new std::string ABI
inline constexpr std::uint64_t glibcxx_debug = 1ull << 2;   ///< checked std containers (other layout)
inline constexpr std::uint64_t eigen_no_align = 1ull << 3;  ///< Eigen static alignment disabled
inline constexpr int pointer_size_shift = 8;                ///< bits 8–15: sizeof(void*)
inline constexpr int eigen_align_shift = 16;                ///< bits 16–23: EIGEN_MAX_STATIC_ALIGN_BYTES
inline constexpr int cxx_abi_shift = 32;                    ///< bits 32–63: __GXX_ABI_VERSION
}  // namespace config_bits

/// The config word of the translation unit that calls it (host or plugin). Header-only on purpose: each
/// side computes it from its own build settings.
std::uint64_t plugin_config_word();

/// Human-readable list of the settings in a config word, e.g. "double, cxx11-abi, 64-bit, eigen-align=16".
std::string describe_config_word(std::uint64_t word);

}  // namespace impetus

// The definitions must see the including build's macros, so they are in this header (inline).
#include <Eigen/Core>

namespace impetus {

inline std::uint64_t plugin_config_word() {
  std::uint64_t word = config_bits::scalar_double;
#if defined(_GLIBCXX_USE_CXX11_ABI) && _GLIBCXX_USE_CXX11_ABI
  word |= config_bits::cxx11_abi;
#endif
#if defined(_GLIBCXX_DEBUG)
  word |= config_bits::glibcxx_debug;
#endif
#if defined(EIGEN_DONT_ALIGN) || defined(EIGEN_DONT_ALIGN_STATICALLY)
  word |= config_bits::eigen_no_align;
#endif
  word |= static_cast<std::uint64_t>(sizeof(void*)) << config_bits::pointer_size_shift;
#if defined(EIGEN_MAX_STATIC_ALIGN_BYTES)
  word |= static_cast<std::uint64_t>(EIGEN_MAX_STATIC_ALIGN_BYTES & 0xFF) << config_bits::eigen_align_shift;
#endif
#if defined(__GXX_ABI_VERSION)
  word |= static_cast<std::uint64_t>(__GXX_ABI_VERSION) << config_bits::cxx_abi_shift;
#endif
  return word;
}

inline std::string describe_config_word(std::uint64_t word) {
  std::string out = (word & config_bits::scalar_double) ? "double" : "non-double scalar";
  out += (word & config_bits::cxx11_abi) ? ", cxx11-abi" : ", old-string-abi";
  if (word & config_bits::glibcxx_debug) out += ", _GLIBCXX_DEBUG";
  if (word & config_bits::eigen_no_align) out += ", EIGEN_DONT_ALIGN";
  out += ", " + std::to_string(8 * ((word >> config_bits::pointer_size_shift) & 0xFF)) + "-bit";
  out += ", eigen-align=" + std::to_string((word >> config_bits::eigen_align_shift) & 0xFF);
  out += ", c++-abi=" + std::to_string(word >> config_bits::cxx_abi_shift);
  return out;
}

}  // namespace impetus
