// Detection time per step of the `fcl` detector on the paper's benchmark scenes (pyramid K, line N) and
// on towers of resting boxes, with the broadphase / narrowphase split measured inside the detector
// (FclDetector::last_profile(), steady clock). Every iteration nudges the movable bodies by ±1 nm so
// the broadphase refreshes every box and updates its tree as in a real step; contacts are unchanged.
#include "support/bench_main.hpp"

#include "impetus/detection/fcl/fcl_detector.hpp"
#include "impetus/engine/generators.hpp"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

namespace {

using namespace impetus;

/// `towers` columns of 10 unit boxes, exactly touching each other and the ground, 1.5 m apart.
std::vector<RigidBody> box_towers(int towers) {
  std::vector<RigidBody> bodies;
  const int columns = towers >= 100 ? 40 : 10;
  for (int t = 0; t < towers; ++t) {
    for (int level = 0; level < 10; ++level) {
      RigidBody b;
      b.name = "box_" + std::to_string(t) + "_" + std::to_string(level);
      b.shape = Box{Vec3(1, 1, 1)};
      b.position = Vec3(1.5 * (t % columns), 1.5 * (t / columns), 0.5 + level);
      bodies.push_back(b);
    }
  }
  RigidBody ground;
  ground.name = "ground";
  ground.shape = Plane{Vec3::UnitZ(), 0.0};
  make_fixed(ground);
  bodies.push_back(ground);
  return bodies;
}

void run(benchmark::State& state, std::vector<RigidBody> bodies) {
  FclDetector detector;
  if (const ModuleStatus s = detector.set_bodies(bodies, {}); !s) {
    state.SkipWithError(s.message.c_str());
    return;
  }
  std::vector<Contact> contacts;
  DetectorCounters counters;
  double broadphase = 0.0, narrowphase = 0.0;
  double nudge = 1e-9;
  for (auto _ : state) {
    for (RigidBody& b : bodies)
      if (!b.fixed) b.position.z() += nudge;
    nudge = -nudge;
    counters = DetectorCounters{};
    detector.detect(bodies, StepContext{}, contacts, counters);
    benchmark::DoNotOptimize(contacts.data());
    broadphase += detector.last_profile().broadphase;
    narrowphase += detector.last_profile().narrowphase;
  }
  const auto per_step = benchmark::Counter::kAvgIterations;
  state.counters["bodies"] = static_cast<double>(bodies.size());
  state.counters["contacts"] = static_cast<double>(counters.contacts);
  state.counters["pairs_tested"] = static_cast<double>(counters.pairs_tested);
  state.counters["narrowphase_calls"] = static_cast<double>(counters.narrowphase_calls);
  state.counters["broadphase_ms"] = benchmark::Counter(1e3 * broadphase, per_step);
  state.counters["narrowphase_ms"] = benchmark::Counter(1e3 * narrowphase, per_step);
}

void pyramid(benchmark::State& state) {
  PyramidParams p;
  p.rows = static_cast<int>(state.range(0));
  run(state, make_pyramid(p));
}
void line(benchmark::State& state) {
  LineParams p;
  p.count = static_cast<int>(state.range(0));
  run(state, make_line(p));
}
void resting_boxes(benchmark::State& state) { run(state, box_towers(static_cast<int>(state.range(0)) / 10)); }

BENCHMARK(pyramid)->Name("detect/pyramid")->Arg(3)->Arg(4)->Arg(10)->Arg(20)->Arg(50)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK(line)->Name("detect/line")->Arg(10)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(resting_boxes)->Name("detect/resting_boxes")->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace

IMPETUS_BENCHMARK_MAIN();
