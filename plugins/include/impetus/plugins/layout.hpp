#pragma once
/// \file
/// Layout words: what the host and a plugin must agree on for the data they hand each other by memory
/// layout (bodies, contacts, constraints, the step context, counters, statuses and options).
///
/// A layout word is a 64-bit FNV-1a hash of a type's sizeof and alignof and, for each of its public
/// fields, the field's offset and size (for a std::variant, its alternatives count too). It changes when
/// a field is added, removed, reordered or resized, or when a build setting changes the type's layout.
/// The config word (abi.hpp) names the build settings; the layout words name the type that differs.
/// Header-only on purpose: host and plugin each compute them from their own build of these headers.

#include "impetus/core/body.hpp"
#include "impetus/core/shape.hpp"
#include "impetus/modules/constraint.hpp"
#include "impetus/modules/contact.hpp"
#include "impetus/modules/contact_problem.hpp"
#include "impetus/modules/detector.hpp"
#include "impetus/modules/options.hpp"
#include "impetus/modules/status.hpp"
#include "impetus/modules/step.hpp"
#include "impetus/plugins/abi.hpp"

#include <cstddef>
#include <cstdint>
#include <variant>

namespace impetus {

namespace layout_detail {
inline constexpr std::uint64_t kFnvOffsetBasis = 0xcbf29ce484222325ull;
inline constexpr std::uint64_t kFnvPrime = 0x100000001b3ull;

/// FNV-1a step over the 8 bytes of `value` (little end first, whatever the machine).
inline std::uint64_t mix(std::uint64_t hash, std::uint64_t value) {
  for (int byte = 0; byte < 8; ++byte) {
    hash ^= (value >> (8 * byte)) & 0xFFu;
    hash *= kFnvPrime;
  }
  return hash;
}
}  // namespace layout_detail

/// Layout word of `T` from its size, alignment and the given fields (offset and size of each). The
/// offsets are measured on a value-initialized object, so no offsetof on non-standard-layout types.
template <typename T, typename... Fields>
std::uint64_t layout_word(Fields T::*... fields) {
  const T object{};
  const auto* base = reinterpret_cast<const unsigned char*>(&object);
  std::uint64_t hash = layout_detail::mix(layout_detail::kFnvOffsetBasis, sizeof(T));
  hash = layout_detail::mix(hash, alignof(T));
  ((hash = layout_detail::mix(
        layout_detail::mix(hash, static_cast<std::uint64_t>(reinterpret_cast<const unsigned char*>(&(object.*fields)) - base)),
        sizeof(object.*fields))),
   ...);
  return hash;
}

/// Layout word of a std::variant: its size, alignment and number of alternatives (each alternative
/// has its own word).
template <typename Variant>
std::uint64_t variant_layout_word() {
  return layout_detail::mix(layout_word<Variant>(), std::variant_size_v<Variant>);
}

/// The layout words of the translation unit that calls it (host or plugin), indexed by LayoutType.
inline LayoutWords plugin_layout_words() {
  LayoutWords w{};
  auto at = [&w](LayoutType type) -> std::uint64_t& { return w[static_cast<std::size_t>(type)]; };
  using RB = RigidBody;
  at(LayoutType::rigid_body) = layout_word<RB>(
      &RB::name, &RB::shape, &RB::fixed, &RB::mass, &RB::inv_mass, &RB::inertia_body, &RB::inv_inertia_body,
      &RB::material, &RB::collision_group, &RB::collision_mask, &RB::position, &RB::rotation, &RB::velocity,
      &RB::angular_velocity, &RB::force, &RB::torque);
  at(LayoutType::material) = layout_word<Material>(&Material::restitution, &Material::friction);
  at(LayoutType::shape) = variant_layout_word<Shape>();
  at(LayoutType::sphere) = layout_word<Sphere>(&Sphere::radius);
  at(LayoutType::box) = layout_word<Box>(&Box::size);
  at(LayoutType::capsule) = layout_word<Capsule>(&Capsule::radius, &Capsule::length);
  at(LayoutType::cylinder) = layout_word<Cylinder>(&Cylinder::radius, &Cylinder::length);
  at(LayoutType::plane) = layout_word<Plane>(&Plane::normal, &Plane::offset);
  at(LayoutType::mesh_shape) = layout_word<MeshShape>(&MeshShape::file, &MeshShape::scale, &MeshShape::collision,
                                                      &MeshShape::mesh, &MeshShape::hull);
  at(LayoutType::triangle_mesh) = layout_word<TriangleMesh>(&TriangleMesh::vertices, &TriangleMesh::triangles);
  at(LayoutType::contact) = layout_word<Contact>(&Contact::a, &Contact::b, &Contact::point, &Contact::normal,
                                                 &Contact::depth, &Contact::feature, &Contact::impulse,
                                                 &Contact::tangent_impulse, &Contact::mode);
  using PP = PointPointConstraint;
  at(LayoutType::point_point_constraint) =
      layout_word<PP>(&PP::a, &PP::b, &PP::anchor_a, &PP::anchor_b, &PP::level, &PP::collide);
  using CC = CoaxialConstraint;
  at(LayoutType::coaxial_constraint) = layout_word<CC>(&CC::a, &CC::b, &CC::anchor_a, &CC::anchor_b, &CC::axis_a,
                                                       &CC::axis_b, &CC::length, &CC::level, &CC::collide);
  at(LayoutType::constraint) = variant_layout_word<Constraint>();
  at(LayoutType::step_context) =
      layout_word<StepContext>(&StepContext::dt, &StepContext::gravity, &StepContext::step, &StepContext::time);
  at(LayoutType::integrator_counters) =
      layout_word<IntegratorCounters>(&IntegratorCounters::bodies, &IntegratorCounters::orthonormalized);
  using DC = DetectorCounters;
  at(LayoutType::detector_counters) =
      layout_word<DC>(&DC::pairs_tested, &DC::narrowphase_calls, &DC::contacts, &DC::contacts_dropped,
                              &DC::pair_limit, &DC::crowded_body, &DC::crowded_pairs, &DC::speculative_pairs);
  using RC = ResolverCounters;
  at(LayoutType::resolver_counters) =
      layout_word<RC>(&RC::islands, &RC::contacts, &RC::rounds, &RC::pulling_impulses, &RC::non_converged,
                      &RC::singular_systems, &RC::redundant_systems, &RC::nan_caught, &RC::residual, &RC::complementarity_error,
                      &RC::energy_gain_events, &RC::sticking, &RC::sliding, &RC::natural_map_residual,
                      &RC::friction_work, &RC::work_limited, &RC::corrections_clamped, &RC::largest_correction);
  at(LayoutType::module_status) = layout_word<ModuleStatus>(&ModuleStatus::ok, &ModuleStatus::message);
  at(LayoutType::module_options) = layout_word<ModuleOptions>();  // private fields: size and alignment
  at(LayoutType::option_value) = layout_word<OptionValue>(&OptionValue::text, &OptionValue::items,
                                                          &OptionValue::is_list, &OptionValue::where);
  at(LayoutType::body_pair) = layout_word<BodyPair>(&BodyPair::first, &BodyPair::second);
  using LP = LocalContactProblem;
  at(LayoutType::local_contact_problem) = layout_word<LP>(&LP::contacts, &LP::equalities, &LP::w_columns, &LP::w_rows,
                                                          &LP::w_values, &LP::q, &LP::mu, &LP::tolerance);
  using LS = LocalContactSolution;
  at(LayoutType::local_contact_solution) =
      layout_word<LS>(&LS::r, &LS::u, &LS::residual, &LS::iterations, &LS::converged);
  return w;
}

}  // namespace impetus
