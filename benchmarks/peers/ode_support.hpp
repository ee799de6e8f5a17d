#pragma once
/// \file
/// ODE set-up shared by bench_peers (ode.cpp) and bench_accuracy_peers (accuracy/ode_world.cpp): one-time
/// initialization in double precision and a message handler that counts ODE's messages (not errors),
/// among them the Dantzig LCP's "LCP internal error, s <= 0": ODE's only report that dWorldStep gave up.

#include <ode/ode.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>

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

}  // namespace impetus::peers
