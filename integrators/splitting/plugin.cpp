// Plugin entry for the splitting integrator; the algorithm is in splitting.cpp.
#include "impetus/plugins/export.hpp"
#include "impetus/integrators/splitting/splitting.hpp"

IMPETUS_PLUGIN(impetus::Integrator, impetus::SplittingIntegrator, "splitting", "1.0.0",
               "eq. 2 translation, symmetric splitting of the free rotation: conserves L, "
               "energy bounded, second order in the rotation")
