#pragma once
// `impetus fclib solve FILE` and `impetus fclib export SCENE --out FILE` (README.md, "The `impetus`
// tool"): frictional contact problems in the Frictional Contact Library's HDF5 form, solved by a
// resolver plugin, and a scene's contact problem written in that form.

#include "impetus/engine/scene.hpp"
#include "impetus/engine/world.hpp"

#include <string>

namespace impetus::cli {

/// The options of `impetus fclib solve`.
struct FclibSolveArgs {
  std::string file;
  double tolerance = 1e-10;       ///< on fclib's merit (relative error)
  std::string resolver = "ledas"; ///< the resolver plugin that solves it
  bool json = false;
};

/// Reads the problem, solves it with the resolver plugin, prints the result. Throws Error naming the
/// file and the defect for a file that is not a valid fclib problem, or naming the plugin if it refuses.
int run_fclib_solve(const FclibSolveArgs& args);

/// The options of `impetus fclib export` besides the scene's.
struct FclibExportArgs {
  std::string out;
  bool global = false;
  bool overwrite = false;
};

/// Detects the contacts of `world` (built from `scene`) once and writes their problem to args.out.
int run_fclib_export(const Scene& scene, World& world, const FclibExportArgs& args);

}  // namespace impetus::cli
