// The bundled scenes as a user meets them: every file loads, and `impetus resolve … --json` works with
// the resolver swapped on the command line.
#include "scenario_support.hpp"

#include "impetus_test/process.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iterator>

namespace impetus::scenario {
namespace {

struct Result {
  int status = -1;
  std::string out;  // stdout only: the JSON
  std::string err;  // where a failure's message went (stderr is sent to a file)
};

// Runs the `impetus` binary of this build with `args`.
Result run_impetus(const std::string& args) {
  const std::filesystem::path err_file =
      std::filesystem::temp_directory_path() / ("impetus_scenario_cli_" + std::to_string(::getpid()) + ".err");
  const impetus::test::CommandResult run = impetus::test::run_shell(std::string(IMPETUS_EXE) + " " + args, err_file.string());
  Result r{run.status, run.out, ""};
  std::ifstream err(err_file);
  r.err.assign(std::istreambuf_iterator<char>(err), std::istreambuf_iterator<char>());
  err.close();
  std::filesystem::remove(err_file);
  return r;
}

// Every bundled scene parses and validates (no plugin is loaded by load_scene), so a typo in one is
// caught even before the plugins it names exist.
TEST(ScenarioScenes, EveryBundledSceneLoads) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(IMPETUS_SCENES)) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    EXPECT_NO_THROW(load_scene(entry.path())) << entry.path();
  }
  EXPECT_GE(count, 11);
}

// `impetus resolve billiards.yaml --json --resolver mirtich`: valid JSON naming the resolver, 2 or 3
// contacts (P23 is detector-dependent), impulses ≥ 0, and the three balls' velocities.
TEST(ScenarioCli, ResolveBilliardsWithTheSequentialResolver) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "mirtich"});
  const Result r = run_impetus("resolve " + scene_path("billiards.yaml") + " --json --resolver mirtich");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["resolver"], "mirtich");
  const std::size_t contacts = j["contacts"].size();
  EXPECT_TRUE(contacts == 2 || contacts == 3) << r.out;
  EXPECT_GE(j["iterations"].get<std::uint64_t>(), 2u);
  for (const auto& c : j["contacts"]) EXPECT_GE(c["impulse"].get<double>(), 0.0) << c.dump();
  EXPECT_EQ(j["bodies"].size(), 3u);
}

// `impetus resolve friction_slope.yaml --json` with the box moving at (1, 0, −0.1) m/s: its four corner
// contacts slide; each prints its tangential impulse (⊥ normal, pointing uphill, within the cone ‖p_t‖ ≤ μ p_n,
// on it to 1e-9 since the box slides) and mode "slide"; the resolve prints its natural-map residual
// (≤ 1e-12) and the friction counts.
TEST(ScenarioCli, ResolvePrintsTangentialImpulsesAndModes) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"});
  const Result r = run_impetus("resolve " + scene_path("friction_slope.yaml") +
                                 " --json --set \"bodies.box.velocity=[1, 0, -0.1]\"");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["contacts"].size(), 4u) << r.out;
  double normal = 0.0;
  for (const auto& c : j["contacts"]) {
    const auto t = c["tangent_impulse"].get<std::vector<double>>();
    const auto n = c["normal"].get<std::vector<double>>();
    const double p = c["impulse"].get<double>(), pt = std::hypot(t[0], t[1], t[2]);
    normal += p;
    EXPECT_EQ(c["mode"], "slide") << c.dump();
    EXPECT_NEAR(t[0] * n[0] + t[1] * n[1] + t[2] * n[2], 0.0, 1e-15) << c.dump();
    EXPECT_NEAR(pt, 0.5 * p, 1e-9 * p) << c.dump();
    EXPECT_LT(t[0], 0.0) << "friction on the box opposes its slip: " << c.dump();
  }
  EXPECT_GT(normal, 0.0);
  EXPECT_LE(j["natural_map_residual"].get<double>(), 1e-12);
  EXPECT_EQ(j["sliding"].get<std::uint64_t>(), 4u);
  EXPECT_EQ(j["sticking"].get<std::uint64_t>(), 0u);
  EXPECT_LT(j["friction_work_j"].get<double>(), 0.0);
}

// `impetus run box_stack_10.yaml --resolver mirtich` finishes (the sequential resolver caps its work
// instead of freezing) and prints a summary.
TEST(ScenarioCli, SequentialResolverNeverFreezesOnTheBoxStack) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "mirtich"});
  const Result r = run_impetus("run " + scene_path("box_stack_10.yaml") + " --steps 60 --json --resolver mirtich");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["steps"].get<std::uint64_t>(), 60u);
  EXPECT_GT(j["resolver"]["rounds"].get<std::uint64_t>(), 0u);
  std::printf("[ scenario ] box stack 10 (mirtich), 60 steps via the CLI: resolver %s, max penetration %.3g m\n",
              j["resolver"].dump().c_str(), j["max_penetration_m"].get<double>());
}

}  // namespace
}  // namespace impetus::scenario
