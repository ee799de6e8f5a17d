// A whole step (integrate velocities → detect → resolve → integrate positions) of the benchmark scenes
// under gravity, with each stage's share from the step profile. Every iteration steps the same state:
// the initial state (the pyramid drop, the line push) is restored before each step, untimed, so the
// rows measure one well-defined step rather than a scene that falls apart as the benchmark runs.
//
// Rows: step/<resolver>/<scene>, on one thread (World::set_threads(1)); …_speculative_off with the
// detector's look-ahead off. Counters: bodies, threads,
// contacts, rounds, speculative_pairs, and the mean time per step of each stage (velocities_ms,
// detect_ms, resolve_ms, positions_ms) plus resolve_share = resolve / total.
// The resolvers run with their defaults (position correction on, warm starts on), as in a simulation.
// With friction ("…_mu0.7"): the pyramid at rest (spheres at zero velocity, μ = 0.7 everywhere, where an
// equilibrium exists), stacks of N unit boxes on the ground (μ = 0.5) and brick walls in running bond
// (μ = 0.5; 40 and 80 bricks, 10 per course), each step the frictional problem of a resting scene;
// counters add natural_map (ledas's natural-map residual), sticking and sliding. The walls of 200 and
// 1,000 bricks (25 per course) run only with IMPETUS_BENCH_SLOW=1: one step of the 200-brick wall takes
// ledas 10-140 s today (benchmarks/README.md), so the default suite would not finish.
#include "support/allocation_counter.hpp"
#include "support/bench_dynamic.hpp"
#include "support/bench_main.hpp"
#include "support/bench_resolvers.hpp"
#include "support/bench_scenes.hpp"
#include "support/bench_steps.hpp"
#include "support/machine_probe.hpp"

#include "impetus/core/mass.hpp"
#include "impetus/engine/world.hpp"
#include "impetus/integrators/momentum/momentum.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace impetus;

// A fixed ground plane z = 0 with friction μ, last in `bodies`.
void add_ground(std::vector<RigidBody>& bodies, double mu) {
  RigidBody ground;
  ground.name = "ground";
  ground.shape = Plane{Vec3(0, 0, 1), 0.0};
  make_fixed(ground);
  ground.material.friction = mu;
  bodies.push_back(ground);
}

// N unit boxes (1 kg) stacked on a fixed ground plane, each 1e-5 m into the one below, friction μ.
std::vector<RigidBody> make_stack(int n, double mu) {
  std::vector<RigidBody> bodies;
  for (int i = 0; i < n; ++i) {
    RigidBody box;
    box.name = "box_" + std::to_string(i);
    box.shape = Box{Vec3(1, 1, 1)};
    set_primitive_mass(box, 1.0);
    box.position = Vec3(0, 0, 0.5 + i * (1.0 - 1e-5) - 1e-5);
    box.material.friction = mu;
    bodies.push_back(box);
  }
  add_ground(bodies, mu);
  return bodies;
}

// A wall of `courses` × `per_course` bricks (0.4 × 0.2 × 0.2 m, 16 kg: 1000 kg/m³) in running bond on a
// fixed ground plane: every other course shifted by half a brick, so each brick rests on two below it and
// the wall is one island. Each brick is 1e-5 m into the course below it, friction μ everywhere.
std::vector<RigidBody> make_wall(int courses, int per_course, double mu) {
  const Vec3 size(0.4, 0.2, 0.2);
  std::vector<RigidBody> bodies;
  for (int c = 0; c < courses; ++c)
    for (int i = 0; i < per_course; ++i) {
      RigidBody brick;
      brick.name = "brick_" + std::to_string(c) + "_" + std::to_string(i);
      brick.shape = Box{size};
      set_primitive_mass(brick, 1000.0 * size.prod());
      brick.position = Vec3((i + 0.5 * (c % 2)) * size.x(), 0.0, 0.5 * size.z() + c * (size.z() - 1e-5) - 1e-5);
      brick.material.friction = mu;
      bodies.push_back(brick);
    }
  add_ground(bodies, mu);
  return bodies;
}

enum class Scene { pyramid, line, resting_pyramid, stack, wall };

void step(benchmark::State& state, const std::string& resolver_name, Scene scene, int n, double restitution,
          bool speculative = true) {
  const std::vector<RigidBody> initial =
      scene == Scene::pyramid ? make_pyramid(PyramidParams{.rows = n, .restitution = restitution})
      : scene == Scene::line  ? make_line(LineParams{.count = n, .restitution = restitution})
      : scene == Scene::stack ? make_stack(n, 0.5)
      : scene == Scene::wall  ? make_wall(n / (n < 200 ? 10 : 25), n < 200 ? 10 : 25, 0.5)
                              : make_pyramid(PyramidParams{.rows = n, .velocity = Vec3::Zero(), .friction = 0.7});
  WorldSettings settings;  // dt 1 ms, gravity −9.81 m/s² along z
  World world(settings);
  for (const RigidBody& b : initial) world.add_body(b);
  world.set_integrator(std::make_shared<MomentumIntegrator>(ModuleOptions{}));
  FclDetectorSettings detector;
  detector.speculative = speculative;
  world.set_detector(std::make_shared<FclDetector>(detector));
  world.set_resolver(bench::make_resolver(resolver_name, /*velocity_only=*/false));
  world.set_threads(1);

  const auto [sum, last, cold_ms, allocations] = bench::time_steps(state, world, initial, &bench::allocations);
  const auto per_step = benchmark::Counter::kAvgIterations;
  state.counters["bodies"] = static_cast<double>(initial.size() - 1);
  state.counters["threads"] = static_cast<double>(world.threads());
  state.counters["contacts"] = static_cast<double>(last.detector.contacts);
  state.counters["rounds"] = static_cast<double>(last.resolver.rounds);
  state.counters["speculative_pairs"] = static_cast<double>(last.detector.speculative_pairs);
  state.counters["residual"] = last.resolver.residual;
  state.counters["velocities_ms"] = benchmark::Counter(1e3 * sum.velocities, per_step);
  state.counters["detect_ms"] = benchmark::Counter(1e3 * sum.detect, per_step);
  state.counters["resolve_ms"] = benchmark::Counter(1e3 * sum.resolve, per_step);
  state.counters["positions_ms"] = benchmark::Counter(1e3 * sum.positions, per_step);
  state.counters["cold_ms"] = cold_ms;
  state.counters["allocations"] = allocations;  // operator new calls per steady-state step
  state.counters["resolve_share"] = sum.total > 0 ? sum.resolve / sum.total : 0.0;
  if (scene == Scene::resting_pyramid || scene == Scene::stack || scene == Scene::wall) {
    // Only ledas reports it (mirtich's sequential impulses have no problem-wide residual: 0 would mislead).
    if (resolver_name.starts_with("ledas")) state.counters["natural_map"] = last.resolver.natural_map_residual;
    state.counters["sticking"] = static_cast<double>(last.resolver.sticking);
    state.counters["sliding"] = static_cast<double>(last.resolver.sliding);
  }
}

// The dynamic scenes (support/bench_dynamic.hpp). Every iteration starts as a running simulation would
// be found at the snapshot: a new resolver (no warm start, no cached analysis), one untimed step from the
// state a step before the snapshot, then the bodies put at the snapshot; it times kDynamicSteps whole
// steps from there, so the contact pattern changes from step to step and every warm start comes from the
// previous step, never from a timed step's own answer in an earlier iteration (bench_peers times its
// dynamic rows the same way, one step). Counters are per step: step_ms and the stages,
// contacts, islands, rounds, allocations (heap allocations), ledas's symbolic analyses (analyses: new
// patterns; analyses_reused: cached ones); residual, natural_map and penetration (deepest contact a
// detection found) are the largest over the steps, and energy_change the kinetic energy the resolve stage changed per
// step (J). With friction, ledas's rows also count its frictional stages per step (friction_problems,
// warm_solved, slips_taken, releases, relaxed, newton_steps, newton_reused (those of them that reused
// the step before's factorization), interior_point_steps, proximal_steps, nonsmooth_sweeps,
// nonsmooth_solved, projection_iterations, projection_solved, coulomb_interior_point_steps,
// friction_non_converged:
// ledas::FrictionalStats), and the lead-in to the snapshot as a whole (a longer, steadier measure of the
// solver than five steps of a chaotic pile): lead_in_steps, lead_in_resolve_s, lead_in_friction_problems,
// lead_in_non_converged, and the steps of the lead-in that left a problem unconverged with their
// resolver seconds (lead_in_unconverged_steps, lead_in_unconverged_resolve_s).
constexpr int kDynamicSteps = 5;

const bench::DynamicStates& snapshot(const std::string& family, int n, double mu) {
  static std::map<std::string, bench::DynamicStates> cache;
  const std::string key = family + "_" + std::to_string(n) + "_" + std::to_string(mu);
  auto it = cache.find(key);
  if (it == cache.end()) it = cache.emplace(key, bench::dynamic_states(bench::dynamic_scene(family, n, mu))).first;
  return it->second;
}

void dynamic_step(benchmark::State& state, const std::string& resolver_name, const std::string& family, int n,
                  double mu, std::uint32_t threads, int cpu = -1) {
  const bench::DynamicStates& states = snapshot(family, n, mu);
  std::optional<bench::PinnedThread> pinned;  // machine/…_cpu<k>: this thread on vCPU k only
  if (cpu >= 0 && !pinned.emplace(cpu).ok()) {
    state.SkipWithError(("cannot pin the thread to vCPU " + std::to_string(cpu)).c_str());
    return;
  }
  const std::vector<RigidBody>& start = states.at;
  World world;
  bench::set_up_world(world, start);
  ledas::FrictionalStats friction;
  world.set_threads(threads);
  StepProfile sum;
  double contacts = 0, islands = 0, rounds = 0, energy = 0, residual = 0, natural_map = 0, penetration = 0;
  double analyses = 0, reused = 0;  // ledas's symbolic analyses (impacts and corrections)
  std::uint64_t allocations = 0;     // heap allocations in the timed steps (allocation_counter.hpp)
  for (auto _ : state) {
    state.PauseTiming();
    std::shared_ptr<CollisionResolver> resolver = bench::make_resolver(resolver_name, /*velocity_only=*/false);
    const auto* ledas = dynamic_cast<const LedasResolver*>(resolver.get());  // its frictional stages, counted
    world.set_resolver(std::move(resolver));
    bench::restore_state(world.bodies(), states.before);
    if (const StepStatus& s = world.step(); !s.ok) {
      state.SkipWithError(s.message.c_str());
      return;
    }
    bench::restore_state(world.bodies(), start);
    state.ResumeTiming();
    for (int i = 0; i < kDynamicSteps; ++i) {
      const std::uint64_t allocated_before = bench::allocations();
      const StepStatus& s = world.step();
      allocations += bench::allocations() - allocated_before;
      state.PauseTiming();
      if (!s.ok) {
        state.SkipWithError(s.message.c_str());
        return;
      }
      sum.velocities += s.profile.velocities;
      sum.detect += s.profile.detect;
      sum.resolve += s.profile.resolve;
      sum.positions += s.profile.positions;
      sum.total += s.profile.total;
      contacts += static_cast<double>(s.detector.contacts);
      islands += static_cast<double>(s.resolver.islands);
      rounds += static_cast<double>(s.resolver.rounds);
      energy += s.resolve_kinetic_energy_change;
      residual = std::max(residual, s.resolver.residual);
      natural_map = std::max(natural_map, s.resolver.natural_map_residual);
      for (const Contact& c : world.contacts()) penetration = std::max(penetration, c.depth);
      if (ledas != nullptr) {
        const LedasStats& stats = ledas->last_stats();
        ledas::add(friction, stats.friction);
        analyses += static_cast<double>(stats.velocity.symbolic_analyses + stats.position.symbolic_analyses);
        reused += static_cast<double>(stats.velocity.symbolic_reused + stats.position.symbolic_reused);
      }
      state.ResumeTiming();
    }
  }
  const auto per_step = [](double total) { return benchmark::Counter(total / kDynamicSteps, benchmark::Counter::kAvgIterations); };
  state.counters["bodies"] = static_cast<double>(std::count_if(start.begin(), start.end(), [](const RigidBody& b) { return !b.fixed; }));
  state.counters["threads"] = static_cast<double>(world.threads());
  state.counters["step_ms"] = per_step(1e3 * sum.total);
  state.counters["detect_ms"] = per_step(1e3 * sum.detect);
  state.counters["resolve_ms"] = per_step(1e3 * sum.resolve);
  state.counters["contacts"] = per_step(contacts);
  state.counters["islands"] = per_step(islands);
  state.counters["rounds"] = per_step(rounds);
  state.counters["energy_change"] = per_step(energy);
  state.counters["residual"] = residual;
  state.counters["penetration"] = penetration;
  state.counters["allocations"] = per_step(static_cast<double>(allocations));
  if (resolver_name.starts_with("ledas")) {
    // The sparse factorizations' symbolic analyses per step (the impacts' and the corrections'): new
    // patterns analysed, and patterns met before whose cached analysis was reused.
    state.counters["analyses"] = per_step(analyses);
    state.counters["analyses_reused"] = per_step(reused);
  }
  if (resolver_name.starts_with("ledas") && mu > 0) {
    state.counters["natural_map"] = natural_map;
    // Where the frictional solver's time goes, per step: its island problems, those their warm start
    // solved (with at most warm_newton + warm_checked Newton steps), the slipping warm answers taken
    // after the loose check, those solved cold (from the convex relaxation), and its factorizations.
    state.counters["friction_problems"] = per_step(static_cast<double>(friction.problems));
    state.counters["warm_solved"] = per_step(static_cast<double>(friction.warm_started));
    state.counters["slips_taken"] = per_step(static_cast<double>(friction.slips_taken));
    state.counters["releases"] = per_step(static_cast<double>(friction.releases));
    state.counters["relaxed"] = per_step(static_cast<double>(friction.relaxed));
    state.counters["warm_relaxed"] = per_step(static_cast<double>(friction.warm_relaxed));
    state.counters["newton_steps"] = per_step(static_cast<double>(friction.newton_steps));
    state.counters["newton_reused"] = per_step(static_cast<double>(friction.newton_reused));
    state.counters["interior_point_steps"] = per_step(static_cast<double>(friction.interior_point_steps));
    state.counters["proximal_steps"] = per_step(static_cast<double>(friction.proximal_steps));
    state.counters["nonsmooth_sweeps"] = per_step(static_cast<double>(friction.nonsmooth_sweeps));
    state.counters["nonsmooth_solved"] = per_step(static_cast<double>(friction.nonsmooth_solved));
    state.counters["projection_iterations"] = per_step(static_cast<double>(friction.projection_iterations));
    state.counters["projection_solved"] = per_step(static_cast<double>(friction.projection_solved));
    state.counters["coulomb_interior_point_steps"] = per_step(static_cast<double>(friction.coulomb_interior_point_steps));
    state.counters["friction_non_converged"] = per_step(static_cast<double>(friction.non_converged));
    // The lead-in to the snapshot, whole (one thread, its first step to its last): its resolver's
    // seconds and its frictional problems left unconverged, out of how many.
    state.counters["lead_in_steps"] = states.lead_steps;
    state.counters["lead_in_resolve_s"] = states.lead_resolve_s;
    state.counters["lead_in_friction_problems"] = static_cast<double>(states.lead_friction_problems);
    state.counters["lead_in_non_converged"] = static_cast<double>(states.lead_friction_non_converged);
    state.counters["lead_in_unconverged_steps"] = static_cast<double>(states.lead_unconverged_steps);
    state.counters["lead_in_unconverged_resolve_s"] = states.lead_unconverged_resolve_s;
  }
}

void register_dynamic(long max_bodies) {
  struct Row {
    const char* family;
    int n;
    double mu;
  };
  const Row rows[] = {{"pile", 100, 0.0},   {"pile", 1000, 0.0},  {"pile", 1000, 0.5},
                      {"pile_late", 1000, 0.5},
                      {"heap", 300, 0.0},   {"heap", 1000, 0.0},  {"heap", 3000, 0.0},
                      {"heap", 10000, 0.0}, {"heap", 1000, 0.5},
                      {"knocked_wall", 200, 0.0}, {"knocked_wall", 1000, 0.0}, {"pyramid", 100, 0.0},
                      {"pyramid", 100, 0.7}};
  const bool slow = std::getenv("IMPETUS_BENCH_SLOW") != nullptr;
  for (const Row& row : rows) {
    // The knocked wall of 1,000 bricks is one island of ~11,600 contacts whose active set ledas builds
    // over thousands of pivots: minutes per step today (benchmarks/README.md), so only with IMPETUS_BENCH_SLOW.
    const bool pyramid = row.family == std::string("pyramid");  // n is its rows K
    if ((pyramid ? row.n * (row.n + 1) / 2 : row.n) > max_bodies ||
        (row.family == std::string("knocked_wall") && row.n >= 1000 && !slow))
      continue;
    std::ostringstream scene_name;  // "pyramid_100_mu0.7": μ as written in the row
    scene_name << row.family << '_' << row.n;
    if (row.mu > 0) scene_name << "_mu" << row.mu;
    const std::string scene = scene_name.str();
    for (const std::string resolver : {"ledas", "mirtich"})
      for (std::uint32_t threads : {1u, 2u}) {
        // mirtich is serial (only the detector would split), and with friction it takes seconds per step
        // here, as on the pyramid K = 100 (12.8 s per step in the pyramid_100 row above).
        if (resolver == "mirtich" && (threads > 1 || row.mu > 0 || pyramid)) continue;
        const std::string name = "step/" + resolver + "/" + scene + "_t" + std::to_string(threads);
        benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& st) {
          dynamic_step(st, resolver, row.family, row.n, row.mu, threads);
        })->Unit(benchmark::kMillisecond);
      }
  }
  // The pile's one-thread steps on each vCPU in turn (support/machine_probe.hpp).
  if (const std::vector<int> cpus = bench::allowed_cpus(); cpus.size() > 1 && max_bodies >= 1000)
    for (const int cpu : cpus)
      benchmark::RegisterBenchmark(("machine/pile_1000_cpu" + std::to_string(cpu)).c_str(), [cpu](benchmark::State& st) {
        dynamic_step(st, "ledas", "pile", 1000, 0.0, 1, cpu);
      })->Unit(benchmark::kMillisecond);
}

int register_all() {
  const char* cap = std::getenv("IMPETUS_BENCH_MAX_BODIES");
  const long max_bodies = cap ? std::atol(cap) : 1L << 40;
  for (const std::string resolver : {"ledas", "ledas_paper", "mirtich"}) {
    for (int k : {3, 4, 10, 20, 50, 100}) {
      if (k * (k + 1) / 2 > max_bodies || (resolver == "ledas_paper" && k == 100)) continue;  // see resolve.cpp
      benchmark::RegisterBenchmark(("step/" + resolver + "/pyramid_" + std::to_string(k)).c_str(),
                                   [resolver, k](benchmark::State& st) { step(st, resolver, Scene::pyramid, k, 0.0); })
          ->Unit(benchmark::kMillisecond);
    }
    if (resolver != "ledas_paper") {  // the paper mode refuses friction
      for (int k : {10, 20}) {
        if (k * (k + 1) / 2 > max_bodies) continue;
        benchmark::RegisterBenchmark(("step/" + resolver + "/pyramid_" + std::to_string(k) + "_rest_mu0.7").c_str(),
                                     [resolver, k](benchmark::State& st) { step(st, resolver, Scene::resting_pyramid, k, 0.0); })
            ->Unit(benchmark::kMillisecond);
      }
      for (int n : {10, 40})
        benchmark::RegisterBenchmark(("step/" + resolver + "/stack_" + std::to_string(n) + "_mu0.5").c_str(),
                                     [resolver, n](benchmark::State& st) { step(st, resolver, Scene::stack, n, 0.0); })
            ->Unit(benchmark::kMillisecond);
      const bool slow = std::getenv("IMPETUS_BENCH_SLOW") != nullptr;
      for (int n : {40, 80, 200, 1000}) {
        if (n > max_bodies || (n >= 200 && !slow)) continue;
        benchmark::RegisterBenchmark(("step/" + resolver + "/wall_" + std::to_string(n) + "_mu0.5").c_str(),
                                     [resolver, n](benchmark::State& st) { step(st, resolver, Scene::wall, n, 0.0); })
            ->Unit(benchmark::kMillisecond);
      }
    }
    // Speculative contacts off: what the look-ahead costs where nothing is fast (compare with the rows
    // above; detection/fcl/README.md, "Fast bodies").
    if (resolver == "ledas") {
      for (int k : {20, 100}) {
        if (k * (k + 1) / 2 > max_bodies) continue;
        benchmark::RegisterBenchmark(("step/ledas/pyramid_" + std::to_string(k) + "_speculative_off").c_str(),
                                     [k](benchmark::State& st) { step(st, "ledas", Scene::pyramid, k, 0.0, false); })
            ->Unit(benchmark::kMillisecond);
      }
      if (1000 <= max_bodies)
        benchmark::RegisterBenchmark("step/ledas/line_1000_e0_speculative_off",
                                     [](benchmark::State& st) { step(st, "ledas", Scene::line, 1000, 0.0, false); })
            ->Unit(benchmark::kMillisecond);
    }
    for (int n : {10, 100, 1000, 10000}) {
      if (n > max_bodies) continue;
      for (double e : {0.0, 1.0}) {
        if (resolver == "ledas_paper" && n == 10000 && e == 0.0) continue;  // see resolve.cpp
        const std::string name = "step/" + resolver + "/line_" + std::to_string(n) + (e > 0 ? "_e1" : "_e0");
        benchmark::RegisterBenchmark(name.c_str(), [resolver, n, e](benchmark::State& st) { step(st, resolver, Scene::line, n, e); })
          ->Unit(benchmark::kMillisecond);
      }
    }
  }
  register_dynamic(max_bodies);
  return 0;
}
const int registered = register_all();

}  // namespace

IMPETUS_BENCHMARK_MAIN();
