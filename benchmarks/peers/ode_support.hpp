#pragma once
/// \file
/// ODE set-up shared by bench_peers (ode.cpp) and bench_accuracy_peers (accuracy/ode_world.cpp): one-time
/// initialization in double precision and a message handler that counts ODE's messages (not errors),
/// among them the Dantzig LCP's "LCP internal error, s <= 0": ODE's only report that dWorldStep gave up;
/// and the geom of a body.

#include "impetus/core/body.hpp"

#include <ode/ode.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <variant>

namespace impetus::peers {

/// ODE messages received since start. PEERS_ODE_VERBOSE=1 also prints them.
inline int& ode_messages() {
  static int count = 0;
  return count;
}

inline void count_ode_message(int number, const char* format, va_list args) {
  ++ode_messages();
  if (!std::getenv("PEERS_ODE_VERBOSE")) return;
  std::fprintf(stderr, "ODE message %d: ", number);
  std::vfprintf(stderr, format, args);
  std::fprintf(stderr, "\n");
}

/// Initializes ODE once (all data for this thread) and installs the counting message handler.
inline void init_ode() {
  static const bool done = [] {
    dInitODE2(0);
    dAllocateODEDataForThread(dAllocateMaskAll);
    dSetMessageHandler(&count_ode_message);
    return true;
  }();
  (void)done;
}

/// The geom of a body in `space`, in the body frame (a capsule and a cylinder along local z, as Impetus's;
/// a box by its full edge lengths). A mesh is refused before (the callers check the shapes).
inline dGeomID make_ode_geom(dSpaceID space, const RigidBody& b) {
  if (const auto* s = std::get_if<Sphere>(&b.shape)) return dCreateSphere(space, s->radius);
  if (const auto* s = std::get_if<Box>(&b.shape)) return dCreateBox(space, s->size.x(), s->size.y(), s->size.z());
  if (const auto* s = std::get_if<Capsule>(&b.shape)) return dCreateCapsule(space, s->radius, s->length);
  if (const auto* s = std::get_if<Cylinder>(&b.shape)) return dCreateCylinder(space, s->radius, s->length);
  const Plane& p = std::get<Plane>(b.shape);
  // ODE's plane a x + b y + c z = d bounds the solid below it, as Impetus's n·p ≤ offset.
  return dCreatePlane(space, p.normal.x(), p.normal.y(), p.normal.z(), p.offset);
}

}  // namespace impetus::peers
