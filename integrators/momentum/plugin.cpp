// Plugin entry for the angular-momentum integrator; the algorithm is in momentum.cpp.
#include "impetus/plugins/export.hpp"
#include "impetus/integrators/momentum/momentum.hpp"

IMPETUS_PLUGIN(impetus::Integrator, impetus::MomentumIntegrator, "momentum", "1.0.0",
               "eq. 2 with angular momentum kept through the rotation: conserves L, first order")
