// Plugin entry for the paper's integrator; the algorithm is in euler.cpp.
#include "impetus/integrators/euler/euler.hpp"
#include "impetus/plugins/export.hpp"

IMPETUS_PLUGIN(impetus::Integrator, impetus::EulerIntegrator, "euler", "1.0.0",
               "the paper's explicit scheme (eq. 2): omega updated directly, first order")
