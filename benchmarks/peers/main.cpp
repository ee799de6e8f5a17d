// bench_peers: the paper's benchmark scenes (docs/conventions.md, "Benchmark scenes") stepped once by Bullet, ODE
// and MuJoCo, side by side with Impetus's resolvers, judged by the same velocity-based counters as
// benchmarks/resolve.cpp. What each row measures and the settings are in README.md.
//
// Rows: peers/<method>/<scene>; peers/<method>_gravity/pyramid_20 for the full step under gravity;
// peers/<method>_gravity/<dynamic scene> for a whole step from a dynamic scene's snapshot (heap, pile, wall).
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
#include <limits>
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

/// Whether every pair of bodies touches at one contact (spheres), so that an engine's impulse on the pair
/// is the impulse at that contact.
bool one_contact_per_pair(const std::vector<Contact>& contacts) {
  std::set<std::pair<std::size_t, std::size_t>> pairs;
  for (const Contact& c : contacts)
    if (!pairs.insert(std::minmax(c.a, c.b)).second) return false;
  return true;
}

/// NaN where the engine reports no whole impulses, or where a pair touches at several points (a box on its
/// face): each engine has its own points there, and the natural map is a condition at each point.
FrictionQuality friction_quality(const bench::PreparedScene& prepared, std::span<const RigidBody> after,
                                 const StepResult& r, const StepSettings& settings) {
  FrictionQuality q;
  if (r.impulse_vectors.size() != prepared.contacts.size() || !one_contact_per_pair(prepared.contacts)) return q;
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

/// How far the velocities a step left are from the contact conditions, judged at the Impetus contacts
/// where bodies touch or overlap: `approach`, the largest approach velocity −v_n⁺; `complementarity`, the
/// largest |P s| over the pairs of bodies, with P the engine's impulse on the pair (its points summed, as
/// ContactTally gives it) and s the pair's smallest slack: v_n⁺ at its contacts, and v_n⁺ + g/dt at its
/// `speculative` ones (a gap g ahead, which a step may close: an impulse there is due once it would).
/// A pair that touches at one point gets |p v_n⁺|, as bench::measure_quality; a box on its face is judged
/// as one pair because each engine picks its own points on the face (a lower bound of a point-by-point
/// measure: zero while any of the pair's contacts is closed).
struct ContactJudgement {
  double approach = 0.0, complementarity = kNaN;
};

ContactJudgement judge_contacts(std::span<const RigidBody> after, const std::vector<Contact>& contacts,
                                std::span<const Contact> speculative, const std::vector<double>& impulses, double dt) {
  ContactJudgement j;
  std::map<std::pair<std::size_t, std::size_t>, std::pair<double, double>> pairs;  // impulse, smallest slack
  const auto velocity = [&](const Contact& c) {
    return resolution::row_velocity(resolution::make_contact_row(after, c), after);
  };
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const double v = velocity(contacts[k]);
    j.approach = std::max(j.approach, -v);
    auto [it, added] = pairs.try_emplace(std::minmax(contacts[k].a, contacts[k].b), 0.0, v);
    if (!impulses.empty()) it->second.first += impulses[k];
    it->second.second = std::min(it->second.second, v);
  }
  for (const Contact& c : speculative)
    if (auto it = pairs.find(std::minmax(c.a, c.b)); it != pairs.end())
      it->second.second = std::min(it->second.second, velocity(c) - c.depth / dt);
  if (impulses.empty()) return j;
  j.complementarity = 0.0;
  for (const auto& [pair, judged] : pairs)
    j.complementarity = std::max(j.complementarity, std::abs(judged.first * judged.second));
  return j;
}

std::span<const Contact> speculative_contacts(const bench::PreparedScene& scene);

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
  const bench::Quality q = bench::measure_quality(after, prepared.bodies, prepared.contacts, {});  // the energy
  const ContactJudgement judged =
      judge_contacts(after, prepared.contacts, speculative_contacts(prepared), r.impulses, settings.dt);
  // For e = 1 the exact answer has p·v⁺ ≠ 0, so complementarity is not a failure measure there.
  const double complementarity = have_impulses && inelastic ? judged.complementarity : kNaN;
  state.counters["bodies"] = static_cast<double>(prepared.movable);
  state.counters["contacts"] = static_cast<double>(prepared.contacts.size());
  state.counters["engine_contacts"] = static_cast<double>(r.engine_contacts);
  state.counters["missing"] = static_cast<double>(prepared.contacts.size() - r.matched);
  state.counters["extra"] = static_cast<double>(r.extra);
  state.counters["iterations"] = r.iterations;
  state.counters["failures"] = r.failures;
  state.counters["residual"] = judged.approach;
  state.counters["complementarity"] = complementarity;
  state.counters["energy_change"] = q.energy_change;
  // As bench_resolve: e = 1 rows are exact with no approach and no energy change.
  const bool exact = judged.approach <= 1e-9 && (inelastic ? complementarity <= 1e-9 : std::abs(q.energy_change) <= 1e-9);
  state.counters["exact"] = exact ? 1.0 : 0.0;
  state.counters["solver_ms"] = 1e3 * r.solver_seconds;
  if (bench::key_friction(prepared.name) > 0.0) {
    const FrictionQuality f = friction_quality(prepared, after, r, settings);
    state.counters["natural_map"] = f.natural_map;
    state.counters["impulse_mismatch"] = f.impulse_mismatch;
    state.counters["exact"] = f.natural_map <= 1e-9 && judged.approach <= 1e-9 ? 1.0 : 0.0;
  }
}

/// What a dynamic scene has beyond its PreparedScene: its speculative contacts (a gap ahead that the step
/// may close) and its bodies one step before the snapshot (bench::DynamicStates::before).
struct DynamicExtras {
  std::vector<Contact> speculative;
  std::vector<RigidBody> before;
};

std::map<const bench::PreparedScene*, DynamicExtras>& dynamic_extras() {
  static std::map<const bench::PreparedScene*, DynamicExtras> all;
  return all;
}

/// The dynamic scene `family`_`n` (support/bench_dynamic.hpp), with every body's friction `mu` if it is not
/// empty (the key gains "_mu" and it, as the frictional scenes' keys): its snapshot, and the contacts Impetus's
/// detector finds there that touch or overlap, prepared once per process. The speculative ones (a gap
/// the step may close) are not judged for approach (the bodies are still falling there, and their
/// approach velocity after the step says nothing about a solver), only kept for the slack of their pair
/// (judge_contacts). A step detects after gravity's velocity update, and how far ahead a pair is
/// followed depends on the velocities: the contacts are found as the step finds them, so that where a
/// pair touches at several points (a box's face) they are the points Impetus's step solves.
const bench::PreparedScene& dynamic_prepared(const std::string& family, int n, const std::string& mu) {
  static std::map<std::string, bench::PreparedScene> cache;
  const std::string key = family + "_" + std::to_string(n) + (mu.empty() ? "" : "_mu" + mu);
  auto it = cache.find(key);
  if (it == cache.end()) {
    const double friction = mu.empty() ? 0.0 : std::stod(mu);
    bench::DynamicStates states = bench::dynamic_states(bench::dynamic_scene(family, n, friction));
    bench::PreparedScene s = bench::prepare(key, std::move(states.at));
    std::vector<RigidBody> accelerated = s.bodies;
    for (RigidBody& b : accelerated)
      if (!b.fixed) b.velocity += 1e-3 * Vec3(0.0, 0.0, -9.81);
    std::vector<Contact> all = bench::detect_once(accelerated), speculative;
    s.contacts.clear();
    for (Contact& c : all) (c.depth < 0.0 ? speculative : s.contacts).push_back(std::move(c));
    it = cache.emplace(key, std::move(s)).first;
    dynamic_extras()[&it->second] = {std::move(speculative), std::move(states.before)};
  }
  return it->second;
}

std::span<const Contact> speculative_contacts(const bench::PreparedScene& scene) {
  const auto it = dynamic_extras().find(&scene);
  return it == dynamic_extras().end() ? std::span<const Contact>() : std::span<const Contact>(it->second.speculative);
}

/// A dynamic scene's bodies a step before its snapshot; empty for the other scenes.
std::span<const RigidBody> state_before(const bench::PreparedScene& scene) {
  const auto it = dynamic_extras().find(&scene);
  return it == dynamic_extras().end() ? std::span<const RigidBody>() : std::span<const RigidBody>(it->second.before);
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
  // A dynamic scene's timed step is taken as a running simulation takes it: the engine, emptied of what
  // it learnt, first steps untimed from the state a step before the snapshot, then is put at the snapshot
  // keeping what that step left (warm starts, contact caches, analyses), and the step from there is timed.
  // Every engine thus warm-starts from a previous step: neither from nothing, nor from the answer of the
  // very step it is timed on (what an iteration after the first would carry if the timed step were
  // simply repeated). The other scenes: every timed step from the scene's state, nothing carried.
  const std::span<const RigidBody> before = state_before(prepared);
  for (auto _ : state) {
    state.PauseTiming();
    if (before.empty()) {
      peer->reset(prepared.bodies, Carry::drop);
    } else {
      peer->reset(before, Carry::drop);
      peer->step();
      peer->reset(prepared.bodies, Carry::keep);
    }
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

/// Methods run on the dynamic scenes (whole steps under gravity from their snapshots): the issue's
/// reference set (Bullet SI 10 and 50, ODE QuickStep 20, dWorldStep where it finishes, MuJoCo Newton) and
/// Impetus.
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
    // The wall of 1,000 bricks is left out: its 20 lead-in steps take Impetus minutes (bench_step has
    // the wall of 200 for the same reason). The pyramid K = 100 at rest is the large single island. With friction: the heap (spheres: one point per pair, so
    // fclib's natural map is measured) and the pile (a box's points differ between engines: judged by
    // the normal conditions only).
    const struct {
      const char* family;
      int n;
      const char* mu;
    } dynamic[] = {{"heap", 300, ""},    {"heap", 1000, ""},          {"heap", 3000, ""},
                   {"heap", 10000, ""},  {"pile", 1000, ""},
                   {"knocked_wall", 200, ""}, {"heap", 1000, "0.5"}, {"pile", 1000, "0.5"},
                   {"pyramid", 100, ""}};
    for (const auto& scene : dynamic) {
      const std::string family = scene.family, mu = scene.mu;
      const int n = scene.n;
      // The pyramid's n is its rows K: K(K + 1)/2 bodies. mirtich takes 13 s per step on it (bench_step).
      const bool pyramid = family == "pyramid";
      const auto bodies = static_cast<std::size_t>(pyramid ? n * (n + 1) / 2 : n);
      if (bodies > std::min(max_bodies, method.max_bodies) || (pyramid && method.name == "impetus_mirtich_step")) continue;
      const std::string key = family + "_" + std::to_string(n) + (mu.empty() ? "" : "_mu" + mu);
      benchmark::RegisterBenchmark(("peers/" + method.name + "_gravity/" + key).c_str(),
                                   [&method, gravity, family, n, mu](benchmark::State& st) {
                                     run(st, method, dynamic_prepared(family, n, mu), gravity);
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
