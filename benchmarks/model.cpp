// "Model no more than a scene needs" (docs/architecture.md), measured: each lever of the engine switched on
// and off on the same scene, one whole step (detect + resolve + integrate) per iteration from the same
// state (restored untimed before each step). Rows: model/<lever>/<on|off>. Counters: bodies,
// contacts, rows_solved (contacts that entered a system), islands, and the per-stage times.
//
// Levers:
//   fixed_bodies  16 sphere pyramids (K = 6) dropped on a fixed ground plane (on) or on a movable ground
//                 box of 10⁹ kg (off): the fixed ground never enters a system and keeps the pyramids
//                 apart as 16 islands; a movable ground joins them into one island. Gravity off (the
//                 heavy box would fall), the paper's drop velocities.
//   primitives    the pyramid K = 10 of spheres (on) against the same pyramid of convex icosphere meshes
//                 (642 vertices, radius 0.5; off): the detector's analytic sphere test against FCL
//                 (GJK, MPR and closest points).
//                 A 5 mm margin in both rows, so the faceted spheres find the same 145 contacts.
//   contact_reduction  a tower of 10 boxes, each turned 45° from the one below so that every face
//                 contact is an octagon, under gravity: at most 4 points per pair (on) or all 8 (off).
//   islands       the 16 pyramids on the fixed ground solved island by island (on) or as one system
//                 (off, the ledas option `islands: false`).
//   start_set     one sphere pyramid K = 20 on the fixed ground, the paper's drop velocities: the ledas
//                 search starts with the impact's contacts (on, `start_set: impact`) or with every
//                 touching contact (off, `start_set: touching`): the same answer, another first guess.
//   sleep         1,000 unit boxes in 100 stacks of 10 resting on the fixed ground, settled for 0.2 s
//                 first, with sleeping islands (on: every stack asleep after 0.1 s still) or without
//                 (off): a sleeping scene costs no detection or resolution. Counter `sleeping`.
#include "support/bench_main.hpp"
#include "support/bench_steps.hpp"

#include "impetus/engine/scene.hpp"
#include "impetus/engine/world.hpp"
#include "impetus/plugins/host.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace impetus;

std::string header(const std::string& gravity, const std::string& detector, const std::string& resolver) {
  return "dt: 0.001\ngravity: " + gravity + "\nmodules:\n  integrator: momentum\n  detector: " + detector +
         "\n  resolver: " + resolver + "\nbodies:\n";
}

/// `count` pyramids of K rows in the x–z plane, 4 m apart in y, every sphere moving at (0, 0, −1) m/s;
/// `shape` is the YAML of each sphere's shape. Overlaps as the pyramid generator's (1e-4 r).
std::string pyramids(int count, int rows, const std::string& shape) {
  std::ostringstream out;
  out.precision(17);
  const double r = 0.5, s = 2 * r * (1 - 1e-4);
  for (int p = 0; p < count; ++p)
    for (int j = 0; j < rows; ++j)
      for (int i = 0; i < rows - j; ++i)
        out << "  - {name: p" << p << "_" << j << "_" << i << ", shape: " << shape << ", mass: 1, position: ["
            << (0.5 * j + i) * s << ", " << 4.0 * p << ", " << r * (1 - 1e-4) + j * std::sqrt(3.0) / 2 * s
            << "], velocity: [0, 0, -1]}\n";
  return out.str();
}

const std::string fixed_ground = "  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1], offset: 0}}}\n";

std::string scene_text(const std::string& lever, bool on) {
  if (lever == "fixed_bodies" || lever == "islands") {
    const std::string resolver = lever == "islands" && !on ? "{plugin: ledas, islands: false}" : "ledas";
    const std::string ground =
        lever == "fixed_bodies" && !on
            ? "  - {name: ground, shape: {box: {size: [200, 200, 1]}}, mass: 1.0e9, position: [0, 30, -0.49995]}\n"
            : fixed_ground;
    return header("[0, 0, 0]", "{plugin: fcl, margin: 1.0e-4}", resolver) + ground +
           pyramids(16, 6, "{sphere: {radius: 0.5}}");
  }
  if (lever == "start_set") {
    const std::string resolver = on ? "ledas" : "{plugin: ledas, start_set: touching}";
    return header("[0, 0, 0]", "{plugin: fcl, margin: 1.0e-4}", resolver) + fixed_ground +
           pyramids(1, 20, "{sphere: {radius: 0.5}}");
  }
  if (lever == "primitives") {
    const std::string shape = on ? "{sphere: {radius: 0.5}}" : "{mesh: {file: icosphere_3.obj, scale: 0.5}}";
    // The icosphere's facets lie up to 2.4 mm inside the sphere: a 5 mm margin finds all 145 contacts
    // with either shape.
    return header("[0, 0, -9.81]", "{plugin: fcl, margin: 5.0e-3}", "ledas") + fixed_ground + pyramids(1, 10, shape);
  }
  if (lever == "sleep") {
    std::ostringstream out;
    out.precision(17);
    out << "dt: 0.001\ngravity: [0, 0, -9.81]\nsleep: {enabled: " << (on ? "true" : "false")
        << ", time: 0.1}\nmodules:\n  integrator: momentum\n  detector: {plugin: fcl, margin: 1.0e-3}\n"
           "  resolver: ledas\nbodies:\n"
        << fixed_ground;
    for (int stack = 0; stack < 100; ++stack)
      for (int level = 0; level < 10; ++level)
        out << "  - {name: b" << stack << "_" << level << ", shape: {box: {size: [1, 1, 1]}}, mass: 1, position: ["
            << 2.0 * (stack % 10) << ", " << 2.0 * (stack / 10) << ", " << 0.49999 + 0.99999 * level << "]}\n";
    return out.str();
  }
  // contact_reduction
  std::ostringstream out;
  out.precision(17);
  out << header("[0, 0, -9.81]", std::string("{plugin: fcl, margin: 1.0e-3, max_contacts_per_pair: ") +
                                     (on ? "4" : "0") + "}", "ledas")
      << fixed_ground;
  for (int level = 0; level < 10; ++level) {
    const double half = 0.5 * std::atan(1.0) * (level % 2);  // 0 or 22.5°: boxes alternate by 45°
    out << "  - {name: box" << level << ", shape: {box: {size: [1, 1, 1]}}, mass: 1, position: [0, 0, "
        << 0.49999 + 0.99999 * level << "], orientation: [" << std::cos(half) << ", 0, 0, " << std::sin(half) << "]}\n";
  }
  return out.str();
}

void model(benchmark::State& state, const std::string& lever, bool on) {
  PluginHost host;
  std::unique_ptr<World> world;
  try {
    const Scene scene = load_scene_text(scene_text(lever, on), "model_" + lever + ".yaml", IMPETUS_MESH_DIR);
    world = build_world(scene, host);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  if (lever == "sleep")  // settle first (both rows alike), so that the timed steps are the settled scene's
    for (int i = 0; i < 200; ++i) world->step();
  const std::vector<RigidBody> initial(world->bodies().begin(), world->bodies().end());
  const auto [sum, last, cold_ms, allocations] = bench::time_steps(state, *world, initial);
  (void)allocations;  // not counted in this program
  const auto per_step = benchmark::Counter::kAvgIterations;
  state.counters["bodies"] = static_cast<double>(initial.size());
  state.counters["contacts"] = static_cast<double>(last.detector.contacts);
  state.counters["rows_solved"] = static_cast<double>(last.resolver.contacts);
  state.counters["islands"] = static_cast<double>(last.resolver.islands);
  state.counters["residual"] = last.resolver.residual;
  state.counters["sleeping"] = static_cast<double>(last.sleeping_bodies);
  state.counters["cold_ms"] = cold_ms;
  state.counters["detect_ms"] = benchmark::Counter(1e3 * sum.detect, per_step);
  state.counters["resolve_ms"] = benchmark::Counter(1e3 * sum.resolve, per_step);
}

int register_all() {
  for (const std::string lever : {"fixed_bodies", "islands", "primitives", "contact_reduction", "start_set", "sleep"})
    for (const bool on : {true, false})
      benchmark::RegisterBenchmark(("model/" + lever + (on ? "/on" : "/off")).c_str(),
                                   [lever, on](benchmark::State& st) { model(st, lever, on); })
          ->Unit(benchmark::kMillisecond);
  return 0;
}
const int registered = register_all();

}  // namespace

IMPETUS_BENCHMARK_MAIN();
