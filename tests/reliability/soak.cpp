// The long-run soak (scripts/soak.sh): resting scenes stepped for a million steps, checking what a
// program that runs for hours needs — no NaN, no energy growth, flat memory, bounded penetration.
//
//   impetus_soak [--steps N] [--every K] [--case pyramid|stack|all] [--resolver NAME]
//
// Cases: `pyramid`, the paper's pyramid K = 10 (55 spheres of radius 0.5, mass 1) at rest on the ground
// between two walls (dt 1 ms); `stack`, assets/scenes/box_stack_10.yaml (ten unit boxes, dt 1/60 s).
// Every K steps it measures the total energy, the kinetic energy, the largest penetration and the
// resident memory. It fails (exit 1) when a step is not ok (a NaN or Inf caught), when the total energy
// rises above its value after the first K steps (the settling of the initial overlaps) by more than
// `energy_tolerance`, when the largest penetration exceeds `penetration_bound`, or when resident memory
// at the end exceeds the first checkpoint after 10 % of the run by more than 1 MiB.

#include "impetus/core/error.hpp"
#include "impetus/engine/metrics.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/plugins/host.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#ifndef IMPETUS_SOURCE_DIR
#error "IMPETUS_SOURCE_DIR must be defined by the build"
#endif

namespace {

using namespace impetus;

struct Case {
  std::string name;
  std::string yaml;              // scene text (empty: `file`)
  std::string file;              // a bundled scene
  double energy_tolerance;       // J: allowed rise of the total energy above its settled value
  double penetration_bound;      // m
};

// The pyramid of the paper's table (K = 10), at rest, with a wall at each end of the bottom row.
std::string resting_pyramid() {
  // Bottom row: centers at x = 0 … 9 (spacing 2r(1 − overlap) ≈ 1); walls touch the end spheres.
  const double r = 0.5, spacing = 2 * r * (1 - 1e-4);
  const double left = -r * (1 - 1e-4), right = 9 * spacing + r * (1 - 1e-4);
  char walls[512];
  std::snprintf(walls, sizeof walls,
                "  - {name: left_wall, fixed: true, shape: {plane: {normal: [1, 0, 0], offset: %.17g}}}\n"
                "  - {name: right_wall, fixed: true, shape: {plane: {normal: [-1, 0, 0], offset: %.17g}}}\n",
                left, -right);
  return std::string("dt: 0.001\n"
                     "modules: {integrator: momentum, detector: {plugin: fcl, margin: 1.0e-4}, resolver: RESOLVER}\n"
                     "generators:\n"
                     "  - pyramid: {rows: 10, radius: 0.5, mass: 1, velocity: [0, 0, 0], overlap: 1.0e-4}\n"
                     "bodies:\n") +
         walls;
}

long resident_kib() {
  std::ifstream statm("/proc/self/statm");
  long pages_total = 0, pages_resident = 0;
  statm >> pages_total >> pages_resident;
  return pages_resident * (sysconf(_SC_PAGESIZE) / 1024);
}

long peak_kib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;  // KiB on Linux
}

bool run(const Case& c, long long steps, long long every, const std::string& resolver) {
  PluginHost host;
  const std::vector<SceneOverride> overrides = {{"modules.resolver", resolver}};
  Scene scene;
  if (c.file.empty()) {
    std::string yaml = c.yaml;
    yaml.replace(yaml.find("RESOLVER"), 8, resolver);
    scene = load_scene_text(yaml, c.name, ".");
  } else {
    scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/" + c.file, overrides);
  }
  const auto world = build_world(scene, host);
  const auto start = std::chrono::steady_clock::now();
  double settled_energy = NAN, max_rise = -INFINITY, max_penetration = 0.0, max_kinetic = 0.0;
  long rss_early = 0, rss_end = 0;
  bool ok = true;
  std::printf("soak %s (%s): %zu bodies, dt %g s, %lld steps\n", c.name.c_str(), resolver.c_str(),
              world->bodies().size(), world->settings().dt, steps);
  for (long long i = 1; i <= steps; ++i) {
    const StepStatus& status = world->step();
    if (!status.ok) {
      std::printf("  FAIL at step %lld: %s\n", i, status.message.c_str());
      return false;
    }
    if (i % every != 0 && i != steps) continue;
    const WorldMetrics m = measure(*world);
    const double energy = total_energy(m);
    if (std::isnan(settled_energy)) settled_energy = energy;
    max_rise = std::max(max_rise, energy - settled_energy);
    max_penetration = std::max(max_penetration, m.max_penetration);
    max_kinetic = std::max(max_kinetic, m.kinetic_energy);
    rss_end = resident_kib();
    if (rss_early == 0 && i >= steps / 10) rss_early = rss_end;
    if (i % (steps / 10 > 0 ? steps / 10 : 1) == 0) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf("  step %9lld  t %9.1f s  E %+.9e J  KE %.3e J  pen %.3e m  rss %ld KiB  wall %.0f s\n", i,
                  world->time(), energy, m.kinetic_energy, m.max_penetration, rss_end, wall);
      std::fflush(stdout);
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("  result: %lld steps in %.0f s (%.1f us/step); energy rise above settled %.3e J (limit %.1e); "
              "max kinetic %.3e J; max penetration %.3e m (limit %.1e); rss at 10%% %ld KiB, at end %ld KiB, "
              "peak %ld KiB\n",
              steps, wall, 1e6 * wall / static_cast<double>(steps), max_rise, c.energy_tolerance, max_kinetic,
              max_penetration, c.penetration_bound, rss_early, rss_end, peak_kib());
  if (max_rise > c.energy_tolerance) std::printf("  FAIL: the energy grew\n"), ok = false;
  if (max_penetration > c.penetration_bound) std::printf("  FAIL: penetration beyond its bound\n"), ok = false;
  if (rss_end - rss_early > 1024) std::printf("  FAIL: resident memory grew by %ld KiB\n", rss_end - rss_early), ok = false;
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  long long steps = 1000000, every = 1000;
  std::string which = "all", resolver = "ledas";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--steps") steps = std::atoll(value.c_str());
    else if (key == "--every") every = std::atoll(value.c_str());
    else if (key == "--case") which = value;
    else if (key == "--resolver") resolver = value;
    else {
      std::fprintf(stderr, "usage: impetus_soak [--steps N] [--every K] [--case pyramid|stack|all] [--resolver NAME]\n");
      return 2;
    }
  }
  if (steps < 1 || every < 1) {
    std::fprintf(stderr, "impetus_soak: --steps and --every must be positive\n");
    return 2;
  }
  const std::vector<Case> cases = {
      {"pyramid", resting_pyramid(), "", 1e-6, 1e-3},
      {"stack", "", "assets/scenes/box_stack_10.yaml", 1e-6, 1e-2},
  };
  bool ok = true;
  try {
    for (const Case& c : cases)
      if (which == "all" || which == c.name) ok = run(c, steps, every, resolver) && ok;
  } catch (const Error& e) {
    std::fprintf(stderr, "impetus_soak: %s\n", e.what());
    return 1;
  }
  std::printf("soak: %s\n", ok ? "PASS" : "FAIL");
  return ok ? 0 : 1;
}
