#pragma once
/// \file
/// The accuracy suite: scenarios with analytic answers or invariants (scene files in assets/scenes/),
/// the grid of methods each is run with, and one run of a scenario with a method. Shared by
/// `bench_accuracy` (the whole grid, timed, written as JSON/CSV; benchmarks/accuracy/README.md) and the
/// tests (tests/accuracy/, coarse settings, asserting each scenario's criterion for the methods
/// expected to pass it).

#include "impetus/engine/scene.hpp"
#include "impetus/engine/world.hpp"

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace impetus::accuracy {

/// A method and its settings: resolver (plugin and mode), integrator, time step and iteration cap.
struct Method {
  std::string resolver = "ledas";        ///< plugin: "ledas" or "mirtich"
  std::string mode = "complementary";    ///< ledas: "complementary" or "paper"; empty for mirtich
  std::string integrator = "momentum";   ///< "euler" (the paper's eq. 2), "momentum" or "splitting"
  double dt = 0.0;                       ///< time step (s); 0 keeps the scene's (impact scenarios)
  long long cap = 0;                     ///< ledas `max_rounds`, mirtich `max_impulses`; 0 = default

  /// "ledas/complementary", "ledas/paper" or "mirtich".
  std::string resolver_label() const;
  /// The option the cap sets: "max_rounds" (ledas) or "max_impulses" (mirtich).
  std::string cap_option() const;
  /// "ledas/paper momentum dt=1/60 max_rounds=100", for messages.
  std::string label() const;
  /// Scene overrides selecting this method (the resolver entry is replaced as a whole).
  std::vector<SceneOverride> overrides() const;
};

/// Error measures of one run, by name (units in the scenario's `error_doc`).
using Errors = std::map<std::string, double>;

/// Watches one run: sees the world before the first step (or resolve), after each, and at the end.
class Probe {
 public:
  virtual ~Probe() = default;
  virtual void start(const World& world) { (void)world; }
  virtual void after_step(const World& world, const StepStatus& status) {
    (void)world;
    (void)status;
  }
  /// The error measures; `simulated` is the simulated time reached (s).
  virtual Errors finish(const World& world, double simulated) = 0;
};

/// How a scenario is run.
enum class Kind {
  impact,     ///< one detection and one resolution on the initial state (the paper's experiment)
  simulation  ///< `duration` seconds of steps
};

/// Where a simulation scenario runs the paper's integrator (`euler`) and `splitting` besides `momentum`.
enum class IntegratorSweep {
  none,       ///< momentum only (the integrator plays no part)
  reference,  ///< euler and splitting at the reference step only (resting bodies hardly turn)
  every_dt    ///< euler and splitting at every step swept
};

/// One scenario: a scene file with overrides, what is measured, and the criterion.
struct Scenario {
  std::string id;        ///< "two_balls_e0.5", "box_stack_20", …
  std::string group;     ///< scenarios charted together ("two_balls", "box_stack", …)
  std::string title;     ///< one line for the atlas
  std::string scene;     ///< file name in assets/scenes/
  std::vector<SceneOverride> overrides;  ///< applied before the method's
  Kind kind = Kind::impact;
  double duration = 0.0;          ///< simulation: seconds simulated
  double reference_dt = 0.0;      ///< simulation: the step the atlas judges at (s)
  std::vector<double> dts;        ///< simulation: steps swept (s)
  IntegratorSweep sweep = IntegratorSweep::none;  ///< simulation: where euler and splitting run too
  std::vector<std::string> resolvers;  ///< resolver labels run ("ledas/complementary", …)
  std::string measures;           ///< what is measured, one sentence
  std::map<std::string, std::string> error_doc;  ///< each error's meaning and unit
  std::string primary;            ///< the error charted against time per step
  std::string criterion;          ///< the pass criterion, as the atlas states it
  /// The criterion as bounds: every named error at most its bound (and finite).
  std::vector<std::pair<std::string, double>> bounds;

  /// True when every bound holds.
  bool passes(const Errors& errors) const;
  std::function<std::unique_ptr<Probe>()> probe;
};

/// All scenarios; `quick` gives shorter simulations and fewer variants (and the tests use it).
std::vector<Scenario> scenarios(bool quick);

/// The methods a scenario is run with: every resolver × integrator × time step at default caps, and
/// the caps swept at the reference step with the `momentum` integrator (impact scenarios: caps only).
std::vector<Method> methods_for(const Scenario& scenario, bool quick);

/// Resolver counters summed (or maxed) over a run.
struct RunCounters {
  unsigned long long rounds = 0;            ///< resolver rounds or single impulses, all steps
  unsigned long long max_rounds_step = 0;   ///< the most in one step
  unsigned long long non_converged = 0;     ///< islands that hit the cap, all steps
  unsigned long long singular_systems = 0;   ///< systems the resolver could not satisfy (failures)
  unsigned long long redundant_systems = 0;  ///< redundant contact sets solved by minimum norm (normal)
  unsigned long long pulling_impulses = 0;
  unsigned long long nan_caught = 0;        ///< resolver and world
  unsigned long long energy_gain_events = 0;
  unsigned long long max_contacts = 0;
};

/// Outcome of one run.
struct RunResult {
  std::string status = "ok";  ///< "ok", "budget" (stopped at the wall-time budget), "unsupported"
                              ///< (the method refuses the scene), "error", "hung" (killed)
  std::string message;        ///< why not ok
  std::size_t steps = 0;      ///< steps (or resolves) measured
  double simulated = 0.0;     ///< simulated time reached (s)
  double time_per_step = 0.0; ///< median wall time of one step (or one detection + resolution) (s)
  double wall = 0.0;          ///< wall time of the whole run (s)
  Errors errors;
  bool pass = false;          ///< the scenario's criterion (false unless status is "ok")
  RunCounters counters;
};

/// Runs one scenario with one method in this process. Simulations stop between steps once `budget`
/// seconds of wall time have passed (status "budget", errors over the part simulated).
RunResult run(const Scenario& scenario, const Method& method, const std::filesystem::path& scenes_dir,
              double budget = 1e300);

/// Same in a child process, killed if it overruns `budget` by more than `grace` seconds (a single step
/// that never ends): status "hung". Falls back to run() where fork is unavailable.
RunResult run_isolated(const Scenario& scenario, const Method& method,
                       const std::filesystem::path& scenes_dir, double budget, double grace);

/// "1/60" for 1/60 s and similar round reciprocals, else the number.
std::string format_dt(double dt);

/// Wall time (s) since `start` on the steady clock every run is timed with.
double seconds_since(std::chrono::steady_clock::time_point start);

/// The median of `values` (the mean of the two middle ones for an even count); 0 when empty.
double median(std::vector<double> values);

/// The current time as ISO 8601 UTC ("2026-11-22T03:04:05Z"), for the JSON header.
std::string utc_now();

}  // namespace impetus::accuracy
