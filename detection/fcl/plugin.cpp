// Plugin entry for the default detector; the algorithm is in fcl_detector.cpp and its helpers.
#include "impetus/detection/fcl/fcl_detector.hpp"
#include "impetus/plugins/export.hpp"

IMPETUS_PLUGIN(impetus::CollisionDetector, impetus::FclDetector, "fcl", "1.0.0",
               "FCL broadphase and narrowphase with contact manifolds (up to 4 points per pair) and a margin")
