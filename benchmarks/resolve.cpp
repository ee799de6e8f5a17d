// The paper's measurement (sec. 5): the resolver alone on a prepared contact list. Detection runs once,
// outside the timed loop; the bodies' velocities are restored before every iteration (untimed). The
// velocity phase only: position correction is switched off (correction = 0), as the paper has none.
//
// Rows: resolve/<resolver>/<scene>. Counters (per row, from the last iteration):
//   bodies, contacts        movable bodies; contacts handed to the resolver
//   rounds                  ledas: linear systems solved (paper: rounds); mirtich: single impulses
//   pulling                 impulses that came out negative (paper mode applies them)
//   non_converged           islands that hit the cap
//   residual                largest approach velocity after the solve, measured from the velocities (m/s)
//   complementarity         max |p_k v_n,k⁺| measured (e = 0 rows; NaN for e = 1)
//   energy_change           (E⁺ − E⁻)/E⁻ of the kinetic energy
//   exact                   e = 0: residual ≤ 1e-9 m/s and complementarity ≤ 1e-9 N·m/s;
//                           e = 1: residual ≤ 1e-9 m/s and |energy_change| ≤ 1e-9
//   cold_ms                 wall time of the untimed first call (ms): with what is set up once per
//                           contact graph (ledas: symbolic analyses), which the timed iterations reuse
// With friction (scenes "…_muX": every contact's μ = X), also:
//   natural_map             fclib's natural-map residual of the impulses applied (Contact::impulse,
//                           tangent_impulse) on the scene's contact problem (core/fclib), unscaled; the
//                           same measure for every resolver
//   sticking, sliding       contacts the resolver reports sticking and sliding
//   exact                   natural_map ≤ 1e-9 and no approach left (≤ 1e-9 m/s)
// Every row runs on one thread, as the paper's table does: in a task arena of one slot, so that ledas
// does not factorize a large island's subtrees on the other cores (the step family's …_t2 rows measure
// that).
#include "support/bench_main.hpp"
#include "support/bench_resolvers.hpp"
#include "support/bench_scenes.hpp"

#include "impetus/fclib/fclib.hpp"

#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace impetus;

void resolve(benchmark::State& state, const std::string& resolver_name, const std::string& scene_key) {
  const bench::PreparedScene& prepared = bench::prepared_scene(scene_key);
  std::vector<RigidBody> bodies = prepared.bodies;
  std::vector<Contact> contacts = prepared.contacts;
  const auto resolver = bench::make_resolver(resolver_name, /*velocity_only=*/true);
  ResolverCounters counters;
  const StepContext ctx{};
  // One untimed call first: it does what a simulation does once and reuses while the contact graph is
  // unchanged (ledas: the symbolic analysis of each island's pattern; buffers), so every timed
  // iteration is a steady-state step whatever the repetition count. Its wall time is the cold_ms counter.
  const auto cold_start = std::chrono::steady_clock::now();
  resolver->resolve(bodies, contacts, {}, ctx, counters);
  const double cold_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cold_start).count();
  for (auto _ : state) {
    state.PauseTiming();
    bench::restore_velocities(bodies, prepared.bodies);
    contacts = prepared.contacts;
    counters = ResolverCounters{};
    state.ResumeTiming();
    resolver->resolve(bodies, contacts, {}, ctx, counters);
    benchmark::DoNotOptimize(bodies.data());
  }
  std::vector<double> impulses(contacts.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) impulses[k] = contacts[k].impulse;
  const bool inelastic = !scene_key.ends_with("_e1");
  const bench::Quality q = bench::measure_quality(bodies, prepared.bodies, contacts,
                                                  inelastic ? std::span<const double>(impulses) : std::span<const double>());
  // e = 0: the exact answer has no approach and no complementarity error. e = 1: the methods answer
  // different models (simultaneous (1 + e) p against a sequence of single collisions), and both keep
  // the kinetic energy: exact = no approach and no energy change.
  const double complementarity = inelastic ? q.complementarity : std::nan("");
  const bool exact = q.approach <= 1e-9 && (inelastic ? q.complementarity <= 1e-9 : std::abs(q.energy_change) <= 1e-9);
  state.counters["bodies"] = static_cast<double>(prepared.movable);
  state.counters["contacts"] = static_cast<double>(contacts.size());
  state.counters["rounds"] = static_cast<double>(counters.rounds);
  state.counters["pulling"] = static_cast<double>(counters.pulling_impulses);
  state.counters["non_converged"] = static_cast<double>(counters.non_converged);
  state.counters["residual"] = q.approach;
  state.counters["complementarity"] = complementarity;
  state.counters["energy_change"] = q.energy_change;
  state.counters["exact"] = exact ? 1.0 : 0.0;
  state.counters["cold_ms"] = cold_ms;
  if (bench::key_friction(scene_key) > 0.0) {
    const fclib::SceneProblem problem = fclib::scene_problem(prepared.bodies, prepared.contacts, ctx.dt);
    fclib::Vector r(static_cast<Eigen::Index>(problem.local.rows()));
    for (std::size_t k = 0; k < problem.contacts.size(); ++k) {
      const Contact& c = contacts[problem.contacts[k]];
      Vec3 t1, t2;
      tangent_basis(c.normal, t1, t2);
      r.segment<3>(static_cast<Eigen::Index>(3 * k)) = Vec3(c.impulse, c.tangent_impulse.dot(t1), c.tangent_impulse.dot(t2));
    }
    const double natural_map = fclib::natural_map_residual(problem.local, r);
    state.counters["natural_map"] = natural_map;
    state.counters["sticking"] = static_cast<double>(counters.sticking);
    state.counters["sliding"] = static_cast<double>(counters.sliding);
    state.counters["exact"] = natural_map <= 1e-9 && q.approach <= 1e-9 ? 1.0 : 0.0;
  }
}

/// A first solve of a contact pattern (issue: "cold as fast as warm"), as in a scene whose contacts change
/// every step. One resolver, kept over the iterations as a world keeps it; every iteration hands it the
/// prepared contacts rotated (the list started at a different contact for each of kPatterns patterns,
/// more than the resolver's cache of symbolic analyses holds): the same problem, but each island's rows
/// in an order, so its matrix in a pattern, the resolver has not seen, and the analysis (ledas: AMD
/// ordering, elimination tree) is in the timed call, while its buffers are already sized, as they would
/// be from the previous step. (Leaving one contact out instead changes the problem: without one contact
/// a dropped pyramid is no longer symmetric, and takes ledas 5–25× longer warm or cold.) Untimed, the resolver then solves
/// the same contacts again: the warm solve of the rows above. Counters: warm_ms, the mean of those
/// repeated solves, and cold_over_warm, the ratio of the means in one run. Warm starts (ContactKey)
/// carry over between patterns, as they do between steps for the contacts that persist.
constexpr int kPatterns = 40;

void resolve_cold(benchmark::State& state, const std::string& resolver_name, const std::string& scene_key) {
  const bench::PreparedScene& prepared = bench::prepared_scene(scene_key);
  std::vector<std::vector<Contact>> orders(kPatterns, prepared.contacts);
  for (std::size_t i = 0; i < orders.size(); ++i)  // start points spread over the list
    std::rotate(orders[i].begin(), orders[i].begin() + static_cast<std::ptrdiff_t>((i + 1) * orders[i].size() / (kPatterns + 1)),
                orders[i].end());
  std::vector<RigidBody> bodies = prepared.bodies;
  std::vector<Contact> contacts;
  ResolverCounters counters;
  const StepContext ctx{};
  const auto resolver = bench::make_resolver(resolver_name, /*velocity_only=*/true);
  // Every pattern once, untimed: buffers sized and the cache of analyses full, as after the first steps
  // of a running scene (its next patterns replace the least recently used).
  for (const std::vector<Contact>& order : orders) {
    bench::restore_velocities(bodies, prepared.bodies);
    contacts = order;
    resolver->resolve(bodies, contacts, {}, ctx, counters);
  }
  double cold_s = 0.0, warm_s = 0.0, cold_analyses = 0.0, warm_analyses = 0.0, cold_sparse = 0.0, warm_sparse = 0.0;
  std::int64_t runs = 0;
  for (auto _ : state) {
    state.PauseTiming();
    bench::restore_velocities(bodies, prepared.bodies);
    contacts = orders[static_cast<std::size_t>(runs % kPatterns)];
    counters = ResolverCounters{};
    state.ResumeTiming();
    const auto cold_start = std::chrono::steady_clock::now();
    resolver->resolve(bodies, contacts, {}, ctx, counters);
    cold_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - cold_start).count();
    state.PauseTiming();
    if (const auto* ledas = dynamic_cast<const LedasResolver*>(resolver.get())) {
      cold_analyses += static_cast<double>(ledas->last_stats().velocity.symbolic_analyses);
      cold_sparse += static_cast<double>(ledas->last_stats().velocity.sparse);
    }
    bench::restore_velocities(bodies, prepared.bodies);
    contacts = orders[static_cast<std::size_t>(runs % kPatterns)];
    const auto warm_start = std::chrono::steady_clock::now();
    resolver->resolve(bodies, contacts, {}, ctx, counters);
    warm_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - warm_start).count();
    if (const auto* ledas = dynamic_cast<const LedasResolver*>(resolver.get())) {
      warm_analyses += static_cast<double>(ledas->last_stats().velocity.symbolic_analyses);
      warm_sparse += static_cast<double>(ledas->last_stats().velocity.sparse);
    }
    ++runs;
    state.ResumeTiming();
  }
  state.counters["bodies"] = static_cast<double>(prepared.movable);
  state.counters["contacts"] = static_cast<double>(contacts.size());
  state.counters["warm_ms"] = runs > 0 ? 1e3 * warm_s / static_cast<double>(runs) : 0.0;
  state.counters["cold_over_warm"] = warm_s > 0.0 ? cold_s / warm_s : 0.0;
  // ledas's symbolic analyses and sparse factorizations per solve, cold and warm.
  const auto per_run = [runs](double total) { return runs > 0 ? total / static_cast<double>(runs) : 0.0; };
  state.counters["analyses"] = per_run(cold_analyses);
  state.counters["warm_analyses"] = per_run(warm_analyses);
  state.counters["factorizations"] = per_run(cold_sparse);
  state.counters["warm_factorizations"] = per_run(warm_sparse);
}

/// A row's function run in a task arena of one thread.
template <class Row>
auto one_thread(Row row) {
  return [row](benchmark::State& state) {
    tbb::task_arena one(1);
    one.execute([&] { row(state); });
  };
}

/// Rows left out: the paper mode on pyramid K = 100 (tens of thousands of rounds on 15 000 contacts) and
/// on the line N = 10 000 with e = 0 (its round cap times 10⁴ rows: minutes per iteration).
bool too_slow(const std::string& resolver, const std::string& scene) {
  return resolver == "ledas_paper" && (scene == "pyramid_100" || scene == "line_10000_e0");
}

/// Registers every resolver on every scene. IMPETUS_BENCH_MAX_BODIES (default: all) skips larger scenes,
/// for a quick run; the sequential resolver's slowest rows are still bounded by its impulse cap.
int register_all() {
  const char* cap = std::getenv("IMPETUS_BENCH_MAX_BODIES");
  const long max_bodies = cap ? std::atol(cap) : 1L << 40;
  std::vector<std::pair<std::string, long>> scenes;
  for (int k : {3, 4, 10, 20, 50, 100}) scenes.emplace_back("pyramid_" + std::to_string(k), k * (k + 1) / 2);
  for (int n : {10, 100, 1000, 10000}) {
    scenes.emplace_back("line_" + std::to_string(n) + "_e0", n);
    scenes.emplace_back("line_" + std::to_string(n) + "_e1", n);
  }
  // With friction (the paper mode refuses friction): the dropped pyramid where every contact can stick
  // (μ = 0.7) and where supports slide (0.5, 0.2; K ≤ 20: beyond, ledas's Coulomb stage takes minutes),
  // and the line, where nothing slips.
  for (int k : {3, 10, 20, 50, 100}) scenes.emplace_back("pyramid_" + std::to_string(k) + "_mu0.7", k * (k + 1) / 2);
  for (const char* mu : {"0.5", "0.2"})
    for (int k : {3, 10, 20}) scenes.emplace_back("pyramid_" + std::to_string(k) + "_mu" + mu, k * (k + 1) / 2);
  for (int n : {10, 100, 1000, 10000}) scenes.emplace_back("line_" + std::to_string(n) + "_e0_mu0.5", n);
  const std::set<std::string> cold = {"pyramid_10", "pyramid_20", "pyramid_50", "pyramid_100", "pyramid_10_mu0.7",
                                      "pyramid_20_mu0.7", "line_1000_e1"};
  for (const auto& [key, bodies] : scenes) {
    if (bodies > max_bodies || !cold.contains(key)) continue;
    benchmark::RegisterBenchmark(("resolve_cold/ledas/" + key).c_str(),
                                 one_thread([key](benchmark::State& st) { resolve_cold(st, "ledas", key); }))
        ->Unit(benchmark::kMillisecond);
  }
  for (const std::string resolver : {"ledas", "ledas_paper", "mirtich"}) {
    for (const auto& [key, bodies] : scenes) {
      if (bodies > max_bodies || too_slow(resolver, key)) continue;
      if (resolver == "ledas_paper" && bench::key_friction(key) > 0.0) continue;
      benchmark::RegisterBenchmark(("resolve/" + resolver + "/" + key).c_str(),
                                   one_thread([resolver, key](benchmark::State& st) { resolve(st, resolver, key); }))
          ->Unit(benchmark::kMillisecond);
    }
  }
  return 0;
}
const int registered = register_all();

}  // namespace

IMPETUS_BENCHMARK_MAIN();
