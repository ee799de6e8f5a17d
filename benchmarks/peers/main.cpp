// bench_peers: the paper's benchmark scenes (docs/conventions.md, "Benchmark scenes") stepped once by Bullet, ODE
// and MuJoCo, side by side with Impetus's resolvers, judged by the same velocity-based counters as
// benchmarks/resolve.cpp. What each row measures and the settings are in README.md.
//
// Rows: peers/<method>/<scene>; peers/<method>_gravity/pyramid_20 for the full step under gravity.
// Counters (per row, from the last step):
//   bodies, contacts        movable bodies; contacts the Impetus (fcl) detector finds
//   engine_contacts         contact points the engine generated
//   missing, extra          Impetus contacts with no engine point on their pair; engine points on other pairs
//   iterations              solver iterations (the setting; MuJoCo: used; Impetus: rounds; 0 = direct)
//   failures                exact solver gave up (Bullet MLCP: fallbacks; ODE: LCP error messages;
//                           Impetus: non-converged islands)
//   residual                largest approach velocity after the step, from the velocities (m/s)
//   complementarity         max |p_k v_n,k⁺| with the engine's own impulses (NaN: not mappable; e = 0 rows)
//   energy_change           (E⁺ − E⁻)/E⁻ of the kinetic energy
//   exact                   e = 0: residual ≤ 1e-9 m/s and complementarity ≤ 1e-9 N·m/s;
//                           e = 1: residual ≤ 1e-9 m/s and |energy_change| ≤ 1e-9 (as bench_resolve)
//   solver_ms               the engine's solver alone, mean per step (NaN where it cannot be separated)
// With friction (scenes "…_muX", every body's μ = X):
//   natural_map             fclib's natural-map error, unscaled: the 2-norm over contacts of
//                           r − P_K(r − (u_n + μ‖u_t‖, u_t)), r the engine's own impulse on the contact
//                           (normal and friction) and u the relative velocity its step left, in the
//                           contact's frame
//   impulse_mismatch        max over bodies of |m (v⁺ − v⁻ − g dt) − Σ impulses| (N·s): whether the
//                           impulses the engine reports are the ones it applied
//   exact                   natural_map ≤ 1e-9 and residual ≤ 1e-9 (as bench_resolve)
#include "peers.hpp"

#include "support/bench_dynamic.hpp"
#include "support/bench_main.hpp"

#include "impetus/fclib/fclib.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>

namespace {

using namespace impetus;
using namespace impetus::peers;


/// The natural-map error of the engine's impulses and the velocities its step left (see the counters
/// above), and how far its reported impulses are from the momentum its bodies gained.
struct FrictionQuality {
  double natural_map = kNaN, impulse_mismatch = kNaN;
};

FrictionQuality friction_quality(const bench::PreparedScene& prepared, std::span<const RigidBody> after,
                                 const StepResult& r, const StepSettings& settings) {
  FrictionQuality q;
  if (r.impulse_vectors.size() != prepared.contacts.size()) return q;
  const std::span<const RigidBody> before = prepared.bodies;
  std::vector<Vec3> received(before.size(), Vec3::Zero());
  double sum = 0.0;
  for (std::size_t k = 0; k < prepared.contacts.size(); ++k) {
    const Contact& c = prepared.contacts[k];
    const Vec3& impulse = r.impulse_vectors[k];  // on b
    received[c.b] += impulse;
    received[c.a] -= impulse;
    // Relative velocity of b with respect to a at the contact point, at the initial positions (the
    // impulse problem's); a gap that the step may close counts as fclib's w (fclib.hpp, scene_problem).
    const Vec3 u = after[c.b].velocity_at(c.point) - after[c.a].velocity_at(c.point);
    Vec3 t1, t2;
    tangent_basis(c.normal, t1, t2);
    const Vec3 r_local(impulse.dot(c.normal), impulse.dot(t1), impulse.dot(t2));
    const Vec3 u_local(u.dot(c.normal) - std::min(0.0, c.depth) / settings.dt, u.dot(t1), u.dot(t2));
    sum += fclib::natural_map(r_local, u_local, combined_friction(before[c.a], before[c.b])).squaredNorm();
  }
  q.natural_map = std::sqrt(sum);
  q.impulse_mismatch = 0.0;
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (before[i].fixed) continue;
    const Vec3 gained = before[i].mass * (after[i].velocity - before[i].velocity - settings.gravity * settings.dt);
    q.impulse_mismatch = std::max(q.impulse_mismatch, (gained - received[i]).norm());
  }
  return q;
}

/// Copies the peer's post-step velocities into a copy of the Impetus bodies and measures them.
void report(benchmark::State& state, const bench::PreparedScene& prepared, const StepResult& r, bool inelastic,
            const StepSettings& settings) {
  std::vector<RigidBody> after = prepared.bodies;
  for (std::size_t i = 0; i < after.size(); ++i) {
    if (after[i].fixed) continue;
    after[i].velocity = r.velocity[i];
    after[i].angular_velocity = r.angular_velocity[i];
  }
  const bool have_impulses = !r.impulses.empty();
  const bench::Quality q = bench::measure_quality(after, prepared.bodies, prepared.contacts,
                                                  have_impulses ? std::span<const double>(r.impulses)
                                                                : std::span<const double>());
  // For e = 1 the exact answer has p·v⁺ ≠ 0, so complementarity is not a failure measure there.
  const double complementarity = have_impulses && inelastic ? q.complementarity : kNaN;
  state.counters["bodies"] = static_cast<double>(prepared.movable);
  state.counters["contacts"] = static_cast<double>(prepared.contacts.size());
  state.counters["engine_contacts"] = static_cast<double>(r.engine_contacts);
  state.counters["missing"] = static_cast<double>(prepared.contacts.size() - r.matched);
  state.counters["extra"] = static_cast<double>(r.extra);
  state.counters["iterations"] = r.iterations;
  state.counters["failures"] = r.failures;
  state.counters["residual"] = q.approach;
  state.counters["complementarity"] = complementarity;
  state.counters["energy_change"] = q.energy_change;
  // As bench_resolve: e = 1 rows are exact with no approach and no energy change.
  const bool exact = q.approach <= 1e-9 && (inelastic ? complementarity <= 1e-9 : std::abs(q.energy_change) <= 1e-9);
  state.counters["exact"] = exact ? 1.0 : 0.0;
  state.counters["solver_ms"] = 1e3 * r.solver_seconds;
  if (bench::key_friction(prepared.name) > 0.0) {
    const FrictionQuality f = friction_quality(prepared, after, r, settings);
    state.counters["natural_map"] = f.natural_map;
    state.counters["impulse_mismatch"] = f.impulse_mismatch;
    state.counters["exact"] = f.natural_map <= 1e-9 && q.approach <= 1e-9 ? 1.0 : 0.0;
  }
}

/// The dynamic scene `family`_`n` (support/bench_dynamic.hpp): its snapshot, and the contacts Impetus's
/// detector finds there that touch or overlap, prepared once per process. The speculative ones (a gap
/// the step may close) are left out: the bodies are still falling there, and their approach velocity
/// after the step says nothing about a solver.
const bench::PreparedScene& dynamic_prepared(const std::string& family, int n) {
  static std::map<std::string, bench::PreparedScene> cache;
  const std::string key = family + "_" + std::to_string(n);
  auto it = cache.find(key);
  if (it == cache.end()) {
    bench::PreparedScene s = bench::prepare(key, bench::dynamic_snapshot(bench::dynamic_scene(family, n, 0.0)));
    std::erase_if(s.contacts, [](const Contact& c) { return c.depth < 0.0; });
    it = cache.emplace(key, std::move(s)).first;
  }
  return it->second;
}

void run(benchmark::State& state, const Method& method, const bench::PreparedScene& prepared,
         const StepSettings& settings) {
  std::unique_ptr<PeerStep> peer;
  try {
    peer = method.make(prepared, settings);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  for (auto _ : state) {
    state.PauseTiming();
    peer->reset();
    state.ResumeTiming();
    peer->step();
  }
  report(state, prepared, peer->result(), !prepared.name.ends_with("_e1"), settings);
}

std::vector<Method>& methods() {
  static std::vector<Method> all;
  return all;
}

/// Methods whose full step under gravity is also measured on pyramid 20 (the issue's "a full step of
/// pyramid K = 20 faster than ODE's exact dWorldStep on the same scene").
const std::set<std::string> kGravityMethods = {
    "bullet_si_10",       "bullet_mlcp",      "bullet_mlcp_shipped", "ode_worldstep_cfm0",
    "ode_worldstep",      "ode_worldstep_cfm", "ode_worldstep_shipped", "ode_quickstep_50",
    "mujoco_newton",      "mujoco_newton_stiff", "impetus_ledas_step",  "impetus_mirtich_step"};

/// Methods run on the dynamic heap (whole steps under gravity from its snapshot): the reference
/// set (Bullet SI 10 and 50, ODE QuickStep 20, dWorldStep where it finishes, MuJoCo Newton) and Impetus.
const std::set<std::string> kDynamicMethods = {
    "bullet_si_10",  "bullet_si_50",       "ode_quickstep_20",    "ode_worldstep_shipped",
    "mujoco_newton", "impetus_ledas_step", "impetus_mirtich_step"};

void register_all() {
  const char* cap = std::getenv("IMPETUS_BENCH_MAX_BODIES");
  const std::size_t max_bodies = cap ? static_cast<std::size_t>(std::atol(cap)) : std::size_t(1) << 40;
  std::vector<std::pair<std::string, std::size_t>> scenes;
  for (int k : {3, 4, 10, 20, 50}) scenes.emplace_back("pyramid_" + std::to_string(k), k * (k + 1) / 2);
  for (int n : {10, 100, 1000}) {
    scenes.emplace_back("line_" + std::to_string(n) + "_e0", n);
    scenes.emplace_back("line_" + std::to_string(n) + "_e1", n);
  }
  // With friction (every body's μ; bench_resolve has the same scenes): the dropped pyramid where every
  // contact can stick (0.7) and where the supports slide (0.5).
  for (const char* mu : {"0.7", "0.5"})
    for (int k : {3, 10, 20}) scenes.emplace_back("pyramid_" + std::to_string(k) + "_mu" + mu, k * (k + 1) / 2);
  StepSettings gravity;
  gravity.gravity = Vec3(0.0, 0.0, -9.81);
  for (const Method& method : methods()) {
    for (const auto& [key, bodies] : scenes) {
      if (bodies > max_bodies || bodies > method.max_bodies || method.gravity_only) continue;
      if (key.ends_with("_e1") && !method.restitution) continue;
      const bool frictional = bench::key_friction(key) > 0.0;
      if (frictional ? !method.friction : method.friction_only) continue;
      benchmark::RegisterBenchmark(("peers/" + method.name + "/" + key).c_str(),
                                   [&method, key](benchmark::State& st) {
                                     run(st, method, bench::prepared_scene(key), StepSettings{});
                                   })
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.1);
    }
    if (kGravityMethods.contains(method.name) && max_bodies >= 210) {
      benchmark::RegisterBenchmark(("peers/" + method.name + "_gravity/pyramid_20").c_str(),
                                   [&method, gravity](benchmark::State& st) {
                                     run(st, method, bench::prepared_scene("pyramid_20"), gravity);
                                   })
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.1);
    }
    if (!kDynamicMethods.contains(method.name)) continue;
    for (int n : {1000, 10000}) {
      if (static_cast<std::size_t>(n) > std::min(max_bodies, method.max_bodies)) continue;
      benchmark::RegisterBenchmark(("peers/" + method.name + "_gravity/heap_" + std::to_string(n)).c_str(),
                                   [&method, gravity, n](benchmark::State& st) {
                                     run(st, method, dynamic_prepared("heap", n), gravity);
                                   })
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.1);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  // The banner goes to stderr so that --benchmark_format=json keeps stdout parseable.
  std::fprintf(stderr, "bench_peers: engines compiled in:");
#ifdef IMPETUS_PEERS_BULLET
  std::fprintf(stderr, " %s;", bullet_description().c_str());
  add_bullet_methods(methods());
#endif
#ifdef IMPETUS_PEERS_ODE
  std::fprintf(stderr, " %s;", ode_description().c_str());
  add_ode_methods(methods());
#endif
#ifdef IMPETUS_PEERS_MUJOCO
  std::fprintf(stderr, " %s;", mujoco_description().c_str());
  add_mujoco_methods(methods());
#endif
  std::fprintf(stderr, " Impetus (ledas, ledas_paper, mirtich)\n");
  add_impetus_methods(methods());
  register_all();
  const auto reporter = bench::initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks(reporter.get());
  benchmark::Shutdown();
  return 0;
}
