// Plugin entry for the sequential baseline resolver; the algorithm is in mirtich.cpp.
#include "impetus/plugins/export.hpp"
#include "impetus/resolution/mirtich/mirtich.hpp"

IMPETUS_PLUGIN(impetus::CollisionResolver, impetus::MirtichResolver, "mirtich", "1.0.0",
               "sequential single-contact impulses (Mirtich), the paper's baseline [4]")
