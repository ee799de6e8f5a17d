// The method grid and one run of a scenario with a method, timed step by step with a steady clock.
#include "accuracy.hpp"
#include "report.hpp"

#include "impetus/core/error.hpp"
#include "impetus/plugins/host.hpp"

#include <nlohmann/json.hpp>

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <ctime>
#include <string>
#include <vector>

namespace impetus::accuracy {
namespace {

using Clock = std::chrono::steady_clock;

void count(RunCounters& c, const StepStatus& status) {
  const ResolverCounters& r = status.resolver;
  c.rounds += r.rounds;
  c.max_rounds_step = std::max<unsigned long long>(c.max_rounds_step, r.rounds);
  c.non_converged += r.non_converged;
  c.singular_systems += r.singular_systems;
  c.redundant_systems += r.redundant_systems;
  c.pulling_impulses += r.pulling_impulses;
  c.nan_caught += r.nan_caught + status.nan_caught;
  c.energy_gain_events += r.energy_gain_events;
  c.max_contacts = std::max<unsigned long long>(c.max_contacts, status.detector.contacts);
}

struct State {
  Vec3 position, velocity, angular_velocity;
  Mat3 rotation;
};

std::vector<State> save(const World& world) {
  std::vector<State> out;
  for (const RigidBody& b : world.bodies()) out.push_back({b.position, b.velocity, b.angular_velocity, b.rotation});
  return out;
}

void restore(World& world, const std::vector<State>& states) {
  for (std::size_t i = 0; i < states.size(); ++i) {
    RigidBody& b = world.bodies()[i];
    b.position = states[i].position;
    b.velocity = states[i].velocity;
    b.angular_velocity = states[i].angular_velocity;
    b.rotation = states[i].rotation;
  }
}

bool all_errors_finite(const Errors& errors) {
  return std::all_of(errors.begin(), errors.end(), [](const auto& e) { return std::isfinite(e.second); });
}

}  // namespace

std::string Method::resolver_label() const { return resolver == "ledas" ? "ledas/" + mode : resolver; }

std::string Method::cap_option() const { return resolver == "ledas" ? "max_rounds" : "max_impulses"; }

std::string Method::label() const {
  std::string out = resolver_label() + " " + integrator;
  if (dt > 0) out += " dt=" + format_dt(dt);
  if (cap > 0) out += " " + cap_option() + "=" + std::to_string(cap);
  return out;
}

std::vector<SceneOverride> Method::overrides() const {
  std::string entry = "{plugin: " + resolver;
  if (resolver == "ledas") entry += ", mode: " + mode;
  if (cap > 0) entry += ", " + cap_option() + ": " + std::to_string(cap);
  entry += "}";
  std::vector<SceneOverride> out{{"modules.resolver", entry}, {"modules.integrator", integrator}};
  if (dt > 0) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.17g", dt);
    out.push_back({"dt", buffer});
  }
  return out;
}

std::string format_dt(double dt) {
  const double n = std::round(1.0 / dt);
  if (n >= 1 && std::abs(1.0 / dt - n) < 1e-6 * n) return "1/" + std::to_string(static_cast<long long>(n));
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", dt);
  return buffer;
}

std::vector<Method> methods_for(const Scenario& scenario, bool quick) {
  std::vector<Method> out;
  auto caps_of = [&](const std::string& label) -> std::vector<long long> {
    if (quick) return {};
    if (scenario.kind == Kind::impact) {
      if (label == "ledas/complementary") return {3};
      if (label == "ledas/paper") return {10, 100, 1000};
      return {100, 1000, 1000000};
    }
    if (label == "ledas/paper") return {100};
    if (label == "mirtich") return {100, 1000};
    return {};
  };
  for (const std::string& label : scenario.resolvers) {
    Method base;
    base.resolver = label == "mirtich" ? "mirtich" : "ledas";
    base.mode = label == "mirtich" ? "" : label.substr(label.find('/') + 1);
    if (scenario.kind == Kind::impact) {
      out.push_back(base);
      for (const long long cap : caps_of(label)) {
        Method m = base;
        m.cap = cap;
        out.push_back(m);
      }
      continue;
    }
    // Resting scenes: the paper's mode takes one round per layer in every step (tens of ms per step), so
    // it is run at the reference step only, with momentum.
    const bool paper_resting = label == "ledas/paper" && scenario.sweep == IntegratorSweep::reference;
    for (const double dt : scenario.dts) {
      if (paper_resting && dt != scenario.reference_dt) continue;
      Method m = base;
      m.dt = dt;
      out.push_back(m);
      const bool euler = scenario.sweep == IntegratorSweep::every_dt ||
                         (scenario.sweep == IntegratorSweep::reference && dt == scenario.reference_dt && !paper_resting);
      if (euler) {
        for (const char* integrator : {"euler", "splitting"}) {
          m.integrator = integrator;
          out.push_back(m);
        }
      }
    }
    for (const long long cap : caps_of(label)) {
      Method m = base;
      m.dt = scenario.reference_dt;
      m.cap = cap;
      out.push_back(m);
    }
  }
  return out;
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  if (values.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(values.begin(), mid));
}

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return buffer;
}

RunResult run(const Scenario& scenario, const Method& method, const std::filesystem::path& scenes_dir,
              double budget) {
  RunResult result;
  const auto start = Clock::now();
  std::vector<SceneOverride> overrides = scenario.overrides;
  for (SceneOverride& o : method.overrides()) overrides.push_back(std::move(o));
  PluginHost host;
  std::unique_ptr<World> world;
  try {
    world = build_world(load_scene(scenes_dir / scenario.scene, overrides), host);
  } catch (const Error& e) {
    const std::string what = e.what();
    result.status = what.find("does not support") != std::string::npos ? "unsupported" : "error";
    result.message = what;
    return result;
  }
  std::unique_ptr<Probe> probe = scenario.probe();
  std::vector<double> times;
  try {
    probe->start(*world);
    if (scenario.kind == Kind::impact) {
      const std::vector<State> initial = save(*world);
      auto t0 = Clock::now();
      const StepStatus& status = world->detect_and_resolve();
      times.push_back(seconds_since(t0));
      count(result.counters, status);
      probe->after_step(*world, status);
      result.errors = probe->finish(*world, 0.0);
      result.steps = 1;
      // More resolutions of the same state, for a stable median (at least 3, up to 31 or 0.5 s).
      const std::vector<State> final_state = save(*world);
      const auto repeat_start = Clock::now();
      while (times.size() < 3 || (times.size() < 31 && seconds_since(repeat_start) < 0.5)) {
        restore(*world, initial);
        t0 = Clock::now();
        world->detect_and_resolve();
        times.push_back(seconds_since(t0));
      }
      restore(*world, final_state);
    } else {
      const auto steps = static_cast<std::size_t>(std::llround(scenario.duration / world->settings().dt));
      times.reserve(steps);
      for (std::size_t i = 0; i < steps; ++i) {
        const auto t0 = Clock::now();
        const StepStatus& status = world->step();
        times.push_back(seconds_since(t0));
        count(result.counters, status);
        probe->after_step(*world, status);
        if (seconds_since(start) > budget && i + 1 < steps) {
          result.status = "budget";
          char buffer[160];
          std::snprintf(buffer, sizeof buffer, "stopped at the wall-time budget (%.0f s) after %.3g of %.3g s simulated",
                        budget, world->time(), scenario.duration);
          result.message = buffer;
          break;
        }
      }
      result.steps = times.size();
      result.simulated = world->time();
      result.errors = probe->finish(*world, world->time());
    }
  } catch (const std::exception& e) {
    result.status = "error";
    result.message = e.what();
  }
  result.time_per_step = median(times);
  result.wall = seconds_since(start);
  result.pass = result.status == "ok" && result.counters.nan_caught == 0 && all_errors_finite(result.errors) &&
                scenario.passes(result.errors);
  return result;
}

RunResult run_isolated(const Scenario& scenario, const Method& method, const std::filesystem::path& scenes_dir,
                       double budget, double grace) {
  int fds[2];
  if (pipe(fds) != 0) return run(scenario, method, scenes_dir, budget);
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child < 0) {
    close(fds[0]);
    close(fds[1]);
    return run(scenario, method, scenes_dir, budget);
  }
  if (child == 0) {
    close(fds[0]);
    const std::string text = result_to_json(run(scenario, method, scenes_dir, budget)).dump();
    std::size_t written = 0;
    while (written < text.size()) {
      const ssize_t n = write(fds[1], text.data() + written, text.size() - written);
      if (n <= 0) break;
      written += static_cast<std::size_t>(n);
    }
    close(fds[1]);
    _exit(0);
  }
  close(fds[1]);
  const auto start = Clock::now();
  std::string text;
  bool killed = false;
  for (;;) {
    const double left = budget + grace - seconds_since(start);
    if (left <= 0) {
      kill(child, SIGKILL);
      killed = true;
      break;
    }
    pollfd pfd{fds[0], POLLIN, 0};
    const int ready = poll(&pfd, 1, static_cast<int>(std::min(left, 1.0) * 1000) + 1);
    if (ready <= 0) continue;
    char buffer[4096];
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n <= 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  close(fds[0]);
  int wstatus = 0;
  waitpid(child, &wstatus, 0);
  RunResult result;
  if (killed) {
    result.status = "hung";
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, "a single step ran past the budget; killed after %.0f s", seconds_since(start));
    result.message = buffer;
    result.wall = seconds_since(start);
    return result;
  }
  try {
    return result_from_json(nlohmann::json::parse(text));
  } catch (const std::exception& e) {
    result.status = "error";
    result.message = std::string("the run's process ended without a result (") + e.what() + ")";
    return result;
  }
}

}  // namespace impetus::accuracy
