// Plugin entry for the LEDAS resolver; the algorithm is in ledas.cpp and island_solver.cpp.
#include "impetus/plugins/export.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

IMPETUS_PLUGIN(impetus::CollisionResolver, impetus::LedasResolver, "ledas", "1.0.0",
               "simultaneous impulses (Ermolin & Kazakov): contacts and joints in one exact system per island")
