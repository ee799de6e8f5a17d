// bench_accuracy_peers: the accuracy suite's scenarios (benchmarks/accuracy/) run in Bullet, ODE and
// MuJoCo, judged by the suite's own probes on the engines' body states, written as the suite's JSON
// (same schema, one extra field per run: "peer") for scripts/accuracy.py to merge into the atlas and the
// charts. The parent folder's README.md says what is translated and how.
//
//   bench_accuracy_peers [--quick] [--out FILE.json] [--filter TEXT]... [--budget S] [--scenes DIR] [--list]
#include "peer_world.hpp"

#include "accuracy.hpp"
#include "report.hpp"

#include "impetus/core/error.hpp"
#include "impetus/plugins/host.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace impetus;
using namespace impetus::accuracy;
using namespace impetus::peers::accuracy;
using Clock = std::chrono::steady_clock;

/// The judging world's resolver: applies nothing, only writes the engine's impulses onto the contacts the
/// Impetus detector found (each engine point goes to the nearest Impetus contact on the same pair of
/// bodies), so that the probes that read impulses (Figure 2's minimum-norm distance) see the engine's.
class ImpulseStamp final : public CollisionResolver {
 public:
  std::vector<PeerContact> points;

  ModuleStatus accept_constraints(std::span<const Constraint>) noexcept override { return ModuleStatus::success(); }
  /// The engine applied the friction; this resolver only records its normal impulses.
  ModuleStatus accept_friction() noexcept override { return ModuleStatus::success(); }

  void resolve(std::span<RigidBody>, std::span<Contact> contacts, std::span<const Constraint>, const StepContext&,
               ResolverCounters&) noexcept override {
    for (Contact& c : contacts) c.impulse = 0.0;
    for (const PeerContact& p : points) {
      Contact* nearest = nullptr;
      double best = std::numeric_limits<double>::infinity();
      for (Contact& c : contacts) {
        const bool same = (c.a == p.a && c.b == p.b) || (c.a == p.b && c.b == p.a);
        const double d = (c.point - p.point).norm();
        if (same && d < best) {
          best = d;
          nearest = &c;
        }
      }
      if (nearest) nearest->impulse += p.impulse;
    }
  }
};

bool finite_state(std::span<const RigidBody> bodies) {
  for (const RigidBody& b : bodies)
    if (!b.fixed && !(b.position.allFinite() && b.rotation.allFinite() && b.velocity.allFinite() &&
                      b.angular_velocity.allFinite()))
      return false;
  return true;
}

/// Prints one body's state (--trace).
void trace(const World& world, const std::string& name, double time) {
  const auto index = world.find_body(name);
  if (!index) return;
  const RigidBody& b = world.bodies()[*index];
  std::fprintf(stderr, "  t=%-5.3g %s x=(%.4g %.4g %.4g) v=(%.3g %.3g %.3g) w=(%.3g %.3g %.3g)\n", time, name.c_str(),
               b.position.x(), b.position.y(), b.position.z(), b.velocity.x(), b.velocity.y(), b.velocity.z(),
               b.angular_velocity.x(), b.angular_velocity.y(), b.angular_velocity.z());
}

struct Options {
  bool quick = false, list = false;
  double budget = 0.0;
  std::string out = "accuracy_peers.json";
  std::string trace;  ///< a body whose state is printed once per simulated second (debugging)
  std::vector<std::string> filters;
  std::filesystem::path scenes = std::filesystem::path(IMPETUS_SOURCE_DIR) / "assets" / "scenes";
};

/// One scenario in one engine setting at one time step (0: the scene's, for impacts).
RunResult run(const Scenario& scenario, const PeerMethod& method, double dt, const Options& o) {
  RunResult result;
  const auto start = Clock::now();
  std::vector<SceneOverride> overrides = scenario.overrides;
  Method step;  // the suite's defaults; only its time step matters here
  step.dt = dt;
  for (SceneOverride& ov : step.overrides()) overrides.push_back(std::move(ov));
  PluginHost host;
  std::unique_ptr<World> world;
  try {
    world = build_world(load_scene(o.scenes / scenario.scene, overrides), host);
  } catch (const Error& e) {
    result.status = "error";
    result.message = e.what();
    return result;
  }
  // Applied loads and prescribed motions are not translated to the peers yet: such a scene is refused for
  // every engine rather than run without them. (Friction is: each engine's translation says how.)
  for (const RigidBody& b : world->bodies()) {
    const char* missing = b.loaded()                           ? "an applied load"
                          : b.motion != PrescribedMotion::none ? "a prescribed motion"
                                                                 : nullptr;
    if (missing) {
      result.status = "unsupported";
      result.message =
          method.label() + ": body '" + b.name + "' has " + missing + ", which is not translated to the peers yet";
      return result;
    }
  }
  auto stamp = std::make_shared<ImpulseStamp>();
  world->set_resolver(stamp);
  const bool impact = scenario.kind == Kind::impact;
  PeerScene scene{world->bodies(), world->constraints(), {}};
  scene.settings.dt = world->settings().dt;
  // Impacts are the paper's experiment (one solve on the initial velocities): gravity off, as bench_peers.
  scene.settings.gravity = impact ? Vec3::Zero() : world->settings().gravity;
  scene.settings.impulse_problem = impact;
  if (const std::string why = method.unsupported(scene); !why.empty()) {
    result.status = "unsupported";
    result.message = method.label() + ": " + why;
    return result;
  }
  std::unique_ptr<Probe> probe = scenario.probe();
  std::vector<double> times;
  std::vector<RigidBody> initial(world->bodies().begin(), world->bodies().end());
  const PeerScene initial_scene{initial, world->constraints(), scene.settings};
  try {
    probe->start(*world);
    if (impact) {
      // One engine step from the initial state; the velocities it leaves are judged at the initial
      // positions, with the contacts the Impetus detector finds there (as the suite's resolve-only runs).
      std::unique_ptr<PeerWorld> peer = method.make(initial_scene);
      auto t0 = Clock::now();
      peer->step();
      times.push_back(seconds_since(t0));
      std::vector<RigidBody> after = initial;
      peer->read(after);
      for (std::size_t i = 0; i < after.size(); ++i) {
        world->bodies()[i].velocity = after[i].velocity;
        world->bodies()[i].angular_velocity = after[i].angular_velocity;
      }
      stamp->points = peer->contacts();
      result.counters.non_converged = static_cast<unsigned long long>(peer->failures());
      const StepStatus& status = world->detect_and_resolve();
      result.counters.max_contacts = status.detector.contacts;
      probe->after_step(*world, status);
      result.errors = probe->finish(*world, 0.0);
      result.steps = 1;
      const auto repeat_start = Clock::now();
      while (times.size() < 3 || (times.size() < 31 && seconds_since(repeat_start) < 0.5)) {
        std::unique_ptr<PeerWorld> again = method.make(initial_scene);
        t0 = Clock::now();
        again->step();
        times.push_back(seconds_since(t0));
      }
    } else {
      std::unique_ptr<PeerWorld> peer = method.make(initial_scene);
      const auto steps = static_cast<std::size_t>(std::llround(scenario.duration / scene.settings.dt));
      times.reserve(steps);
      for (std::size_t i = 0; i < steps; ++i) {
        const auto t0 = Clock::now();
        peer->step();
        times.push_back(seconds_since(t0));
        peer->read(world->bodies());
        result.simulated = static_cast<double>(i + 1) * scene.settings.dt;
        if (!finite_state(world->bodies())) {
          result.status = "error";
          result.message = "the engine's state became non-finite at t = " + std::to_string(result.simulated) + " s";
          break;
        }
        if (!o.trace.empty() && (i + 1) % static_cast<std::size_t>(std::llround(1.0 / scene.settings.dt)) == 0)
          trace(*world, o.trace, result.simulated);
        const StepStatus& status = world->detect_and_resolve();
        unsigned long long& contacts = result.counters.max_contacts;
        contacts = std::max<unsigned long long>(contacts, status.detector.contacts);
        probe->after_step(*world, status);
        if (seconds_since(start) > o.budget && i + 1 < steps) {
          result.status = "budget";
          char buffer[160];
          std::snprintf(buffer, sizeof buffer,
                        "stopped at the wall-time budget (%.0f s) after %.3g of %.3g s simulated", o.budget,
                        result.simulated, scenario.duration);
          result.message = buffer;
          break;
        }
      }
      result.counters.non_converged = static_cast<unsigned long long>(peer->failures());
      result.steps = times.size();
      if (result.status != "error") result.errors = probe->finish(*world, result.simulated);
    }
  } catch (const std::exception& e) {
    result.status = "error";
    result.message = e.what();
  }
  result.time_per_step = median(times);
  result.wall = seconds_since(start);
  bool finite = !result.errors.empty();
  for (const auto& [name, value] : result.errors) finite = finite && std::isfinite(value);
  result.pass = result.status == "ok" && finite && scenario.passes(result.errors);
  return result;
}

nlohmann::json method_json(const PeerMethod& m, double dt) {
  const std::string dt_label = dt > 0 ? format_dt(dt) : "";
  return {{"method", m.label()},
          {"resolver", m.engine},
          {"mode", m.setting},
          {"integrator", "engine"},
          {"dt", dt > 0 ? nlohmann::json(dt) : nlohmann::json(nullptr)},
          {"dt_label", dt_label},
          {"cap_option", ""},
          {"cap", nullptr},
          {"label", m.label() + (dt > 0 ? " dt=" + dt_label : "")},
          {"peer", true},
          {"engine", m.engine},
          {"setting", m.setting},
          {"engine_integrator", m.integrator},
          {"settings", m.description}};
}

[[noreturn]] void usage(int status) {
  std::fprintf(status ? stderr : stdout,
               "usage: bench_accuracy_peers [--quick] [--out FILE.json] [--filter TEXT]... [--budget S] [--scenes DIR] "
               "[--list] [--trace BODY]\n"
               "  --quick   the suite's quick scenarios, reference time step only\n"
               "  --out     the JSON (default accuracy_peers.json; scripts/accuracy.py merges it)\n"
               "  --filter  only scenarios whose id contains TEXT (repeatable)\n"
               "  --budget  wall-time budget per run in seconds (default 10, quick 3)\n"
               "  --scenes  scene directory (default: the source tree's assets/scenes)\n"
               "  --list    list scenarios and engine settings, run nothing\n"
               "  --trace   print BODY's state once per simulated second (simulations; debugging)\n");
  std::exit(status);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(2);
      return argv[++i];
    };
    if (arg == "--quick") o.quick = true;
    else if (arg == "--list") o.list = true;
    else if (arg == "--out") o.out = value();
    else if (arg == "--filter") o.filters.push_back(value());
    else if (arg == "--scenes") o.scenes = value();
    else if (arg == "--budget") o.budget = std::atof(value().c_str());
    else if (arg == "--trace") o.trace = value();
    else if (arg == "--help" || arg == "-h") usage(0);
    else {
      std::fprintf(stderr, "bench_accuracy_peers: unknown argument '%s'\n", arg.c_str());
      usage(2);
    }
  }
  if (o.budget <= 0) o.budget = o.quick ? 3.0 : 10.0;
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  std::vector<PeerMethod> methods;
  nlohmann::json engines = nlohmann::json::array();
#ifdef IMPETUS_PEERS_BULLET
  engines.push_back(bullet_version());
  add_bullet_methods(methods);
#endif
#ifdef IMPETUS_PEERS_ODE
  engines.push_back(ode_version());
  add_ode_methods(methods);
#endif
#ifdef IMPETUS_PEERS_MUJOCO
  engines.push_back(mujoco_version());
  add_mujoco_methods(methods);
#endif
  std::fprintf(stderr, "bench_accuracy_peers: engines compiled in: %s\n", engines.dump().c_str());
  nlohmann::json settings = nlohmann::json::object();
  for (const PeerMethod& m : methods) settings[m.label()] = m.description;
  const auto start = Clock::now();
  char host[256] = "unknown";
  gethostname(host, sizeof host - 1);
  nlohmann::json suite{{"suite", "impetus accuracy peers"},
                       {"format", 1},
                       {"quick", o.quick},
                       {"generated_utc", utc_now()},
                       {"host", host},
                       {"cores", sysconf(_SC_NPROCESSORS_ONLN)},
                       {"build_type", IMPETUS_BUILD_TYPE},
                       {"budget_s", o.budget},
                       {"engines", engines},
                       {"settings", settings},
                       {"scenarios", nlohmann::json::array()}};
  std::size_t runs = 0, passed = 0;
  for (const Scenario& s : scenarios(o.quick)) {
    if (!o.filters.empty() && std::none_of(o.filters.begin(), o.filters.end(), [&](const std::string& f) {
          return s.id.find(f) != std::string::npos;
        }))
      continue;
    const std::vector<double> dts = s.kind == Kind::impact ? std::vector<double>{0.0} : s.dts;
    if (o.list) {
      std::printf("%-22s %3zu runs  %s\n", s.id.c_str(), dts.size() * methods.size(), s.title.c_str());
      continue;
    }
    nlohmann::json entry = scenario_to_json(s);
    entry["runs"] = nlohmann::json::array();
    for (const PeerMethod& m : methods) {
      for (const double dt : dts) {
        const RunResult r = run(s, m, dt, o);
        const auto primary = r.errors.find(s.primary);
        std::fprintf(stderr, "%-20s %-28s %-11s %9.3g s/step  %s %-10.3g %s\n", s.id.c_str(),
                     (m.label() + (dt > 0 ? " dt=" + format_dt(dt) : "")).c_str(), r.status.c_str(), r.time_per_step,
                     s.primary.c_str(), primary != r.errors.end() ? primary->second : 0.0, r.pass ? "pass" : "FAIL");
        if (r.status == "error") std::fprintf(stderr, "    %s\n", r.message.c_str());
        nlohmann::json row = method_json(m, dt);
        row.update(result_to_json(r));
        entry["runs"].push_back(row);
        ++runs;
        passed += r.pass ? 1 : 0;
        if (r.status == "unsupported") break;  // at any time step
      }
    }
    suite["scenarios"].push_back(entry);
  }
  if (o.list) return 0;
  const double total = seconds_since(start);
  suite["total_wall_s"] = total;
  std::ofstream out(o.out);
  if (!out) {
    std::fprintf(stderr, "bench_accuracy_peers: cannot write %s\n", o.out.c_str());
    return 1;
  }
  out << suite.dump(1) << "\n";
  std::fprintf(stderr, "bench_accuracy_peers: %zu runs (%zu pass the criterion) in %.0f s -> %s\n", runs, passed, total,
               o.out.c_str());
  return 0;
}
