// Determinism: the same scene, build and settings give bit-identical trajectories.
//
// What is promised: one binary on one platform (CPU architecture, OS, libm) steps a given scene to the
// same bits every time — in one process or across processes, whatever the heap addresses, and for
// every resolver. What is not: identical bits across compilers, optimization levels, sanitizer builds,
// CPU architectures or libm versions (everything builds with -ffp-contract=off, which removes FMA
// contraction as one source of difference, but not the others), or after any change to a plugin.
//
// Two tests:
//  - Twin run: two worlds from one scene, built with a heap churned in between (so any dependence on
//    addresses would show), stepped in lockstep; every body's state is compared bit for bit after every
//    step, with the contact count.
//  - Golden hashes: a hash of every body's state bits after every step, over N steps of a few bundled
//    scenes per resolver (ledas complementary, ledas paper, mirtich), compared with
//    tests/reliability/golden_hashes.txt. A resolver change that moves trajectories by one rounding
//    changes the hashes; after checking the change is intended, regenerate the file with
//        IMPETUS_UPDATE_GOLDEN=1 ctest --test-dir build -R GoldenHash
//    and commit it. On a mismatch the test prints the new table.

#include "reliability_support.hpp"

#include <cstdlib>
#include <iomanip>
#include <map>
#include <random>
#include <sstream>

namespace impetus::reliability {
namespace {

// The resolvers as --set modules.resolver values.
const std::map<std::string, std::string>& resolvers() {
  static const std::map<std::string, std::string> r = {
      {"ledas", "{plugin: ledas, mode: complementary}"},
      {"ledas_paper", "{plugin: ledas, mode: paper}"},
      {"mirtich", "{plugin: mirtich}"},
  };
  return r;
}

std::vector<SceneOverride> with_resolver(const std::string& resolver) {
  return {{"modules.resolver", resolvers().at(resolver)}};
}

// FNV-1a, 64-bit, over 64-bit words.
struct Fnv1a {
  std::uint64_t h = 0xcbf29ce484222325ull;
  void add(std::uint64_t word) {
    for (int i = 0; i < 8; ++i) {
      h ^= (word >> (8 * i)) & 0xFF;
      h *= 0x100000001b3ull;
    }
  }
};

std::string hex(std::uint64_t x) {
  std::ostringstream out;
  out << "0x" << std::hex << std::setw(16) << std::setfill('0') << x;
  return out.str();
}

// ---- twin run ------------------------------------------------------------------------------------

struct TwinCase {
  const char* scene;
  const char* resolver;
  int steps;
};

void PrintTo(const TwinCase& c, std::ostream* out) { *out << c.scene << " " << c.resolver; }

class TwinRun : public testing::TestWithParam<TwinCase> {};

TEST_P(TwinRun, TwoWorldsInLockstepStayBitIdentical) {
  const TwinCase& c = GetParam();
  const auto host = make_host();
  const auto first = bundled_world(c.scene, *host, with_resolver(c.resolver));
  // Churn the heap so the second world's bodies, contacts and solver buffers live at other addresses.
  std::mt19937 random(12345);
  std::vector<std::vector<char>> churn;
  for (int i = 0; i < 200; ++i) churn.emplace_back(random() % 4096 + 1);
  const auto second = bundled_world(c.scene, *host, with_resolver(c.resolver));
  churn.clear();

  ASSERT_EQ(state_bits(*first), state_bits(*second));
  for (int step = 0; step < c.steps; ++step) {
    const StepStatus& a = first->step();
    ASSERT_TRUE(a.ok) << a.message;
    const std::size_t contacts_a = a.detector.contacts;
    const StepStatus& b = second->step();
    ASSERT_TRUE(b.ok) << b.message;
    ASSERT_EQ(contacts_a, b.detector.contacts) << "step " << step;
    const std::vector<std::uint64_t> bits_a = state_bits(*first), bits_b = state_bits(*second);
    for (std::size_t i = 0; i < bits_a.size(); ++i)
      ASSERT_EQ(bits_a[i], bits_b[i]) << "step " << step << ": body " << first->bodies()[i / 18].name
                                      << ", state word " << i % 18
                                      << " (0-2 position, 3-11 rotation, 12-14 velocity, 15-17 angular velocity)";
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, TwinRun,
                         testing::Values(TwinCase{"pyramid_drop_10", "ledas", 300},
                                         TwinCase{"pyramid_drop_10", "ledas_paper", 300},
                                         TwinCase{"pyramid_drop_10", "mirtich", 300},
                                         TwinCase{"box_stack_10", "ledas", 300},
                                         TwinCase{"box_stack_10", "ledas_paper", 100},
                                         TwinCase{"box_stack_10", "mirtich", 20},
                                         TwinCase{"meshes_drop", "ledas", 300},
                                         TwinCase{"pendulum_chain", "ledas", 300}),
                         [](const testing::TestParamInfo<TwinCase>& info) {
                           return std::string(info.param.scene) + "_" + info.param.resolver;
                         });

// ---- golden hashes -------------------------------------------------------------------------------

struct GoldenCase {
  std::string scene;
  std::string resolver;
  int steps;
  std::string key() const { return scene + " " + resolver + " " + std::to_string(steps); }
};

// The cases, in file order. Scenes are chosen to cover spheres, boxes (manifolds), meshes, joints and friction
// (sliding and sticking boxes, a stack, a sphere that slides then rolls), and the interior point in body
// space (the knocked wall's redundant island).
const std::vector<GoldenCase>& golden_cases() {
  static const std::vector<GoldenCase> cases = {
      {"pyramid_drop_10", "ledas", 200},  {"pyramid_drop_10", "ledas_paper", 200},
      {"pyramid_drop_10", "mirtich", 200}, {"box_stack_10", "ledas", 200},
      {"box_stack_10", "ledas_paper", 100}, {"box_stack_10", "mirtich", 20},
      {"newtons_cradle_5", "ledas", 400},  {"newtons_cradle_5", "ledas_paper", 400},
      {"newtons_cradle_5", "mirtich", 400}, {"meshes_drop", "ledas", 300},
      {"meshes_drop", "mirtich", 300},     {"pendulum_chain", "ledas", 300},
      {"friction_ramp", "ledas", 300},     {"friction_stack_10", "ledas", 100},
      {"friction_sphere", "ledas", 400},   {"knocked_wall", "ledas", 150},
  };
  return cases;
}

std::uint64_t trajectory_hash(const GoldenCase& c, PluginHost& host) {
  const auto world = bundled_world(c.scene, host, with_resolver(c.resolver));
  Fnv1a hash;
  for (int step = 0; step < c.steps; ++step) {
    const StepStatus& status = world->step();
    if (!status.ok) throw Error(c.key() + ": step " + std::to_string(step) + " failed: " + status.message);
    for (std::uint64_t word : state_bits(*world)) hash.add(word);
  }
  return hash.h;
}

fs::path golden_file() { return source_dir() / "tests" / "reliability" / "golden_hashes.txt"; }

std::map<std::string, std::string> read_golden() {
  std::map<std::string, std::string> golden;
  std::ifstream in(golden_file());
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t last = line.rfind(' ');
    golden[line.substr(0, last)] = line.substr(last + 1);
  }
  return golden;
}

std::string table_text(const std::vector<std::pair<std::string, std::string>>& rows) {
  std::string text =
      "# Golden trajectory hashes: scene resolver steps hash (FNV-1a 64 of every body's position, rotation,\n"
      "# velocity and angular velocity bits after every step). Written by tests/reliability/determinism_test.cpp;\n"
      "# regenerate after an intended change with: IMPETUS_UPDATE_GOLDEN=1 ctest --test-dir build -R GoldenHash\n";
  for (const auto& [key, hash] : rows) text += key + " " + hash + "\n";
  return text;
}

TEST(Determinism, GoldenHashPerResolver) {
  const auto host = make_host();
  std::vector<std::pair<std::string, std::string>> computed;
  for (const GoldenCase& c : golden_cases()) computed.emplace_back(c.key(), hex(trajectory_hash(c, *host)));
  const std::string table = table_text(computed);

  const char* update = std::getenv("IMPETUS_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    std::ofstream(golden_file()) << table;
    GTEST_SKIP() << "wrote " << golden_file() << ":\n" << table;
  }
  const std::map<std::string, std::string> golden = read_golden();
  int mismatches = 0;
  for (const auto& [key, hash] : computed) {
    const auto it = golden.find(key);
    if (it == golden.end()) {
      ADD_FAILURE() << key << ": no golden hash in " << golden_file();
      ++mismatches;
    } else if (it->second != hash) {
      ADD_FAILURE() << key << ": trajectory hash " << hash << ", golden " << it->second;
      ++mismatches;
    }
  }
  if (mismatches > 0)
    std::cout << "\nThe trajectories changed. If that is intended (e.g. a resolver change), regenerate with\n"
                 "  IMPETUS_UPDATE_GOLDEN=1 ctest --test-dir build -R GoldenHash\n"
                 "New table:\n"
              << table << std::flush;
}

// Threads (docs/conventions.md, "Threads"): islands solved in parallel (ledas) and the narrowphase split
// across threads (fcl) give the same bits for 1, 2 and 4 threads, as Box2D tests its solver: one hash
// for every thread count. Scenes with many islands and many pairs (several chunks of the narrowphase),
// with and without friction; 2 and 4 threads on a 2-core machine still interleave the lanes differently.
// The dropped pyramid of 40 rows is one island large enough for ledas to factorize subtrees of its
// elimination tree in parallel (masked_ldlt.hpp), and to solve its impact and its position correction
// at once (LedasResolver::solve_island); the knocked wall does the same with both problems in body space.
TEST(Determinism, SameHashForEveryThreadCount) {
  const auto host = make_host();
  const std::pair<const char*, std::vector<SceneOverride>> scenes[] = {
      {"friction_ramp", {}},  {"resting_shapes", {}},      {"billiards", {}},
      {"demo", {}},           {"friction_card_house", {}}, {"pyramid_drop_10", {{"generators.0.pyramid.rows", "40"}}},
      {"knocked_wall", {}}};
  for (const auto& [scene, extra] : scenes) {
    std::uint64_t first = 0;
    for (const char* threads : {"1", "2", "4"}) {
      std::vector<SceneOverride> overrides = with_resolver("ledas");
      overrides.insert(overrides.end(), extra.begin(), extra.end());
      overrides.push_back({"threads", threads});
      const auto world = bundled_world(scene, *host, overrides);
      ASSERT_EQ(world->threads(), static_cast<std::uint32_t>(std::stoi(threads)));
      Fnv1a hash;
      for (int step = 0; step < 150; ++step) {
        const StepStatus& status = world->step();
        ASSERT_TRUE(status.ok) << scene << " threads " << threads << ": " << status.message;
        for (std::uint64_t word : state_bits(*world)) hash.add(word);
      }
      if (std::string(threads) == "1") first = hash.h;
      EXPECT_EQ(hash.h, first) << scene << ": " << threads << " threads give another trajectory than 1";
    }
  }
}

// The hash itself is deterministic within one process: computing a case twice gives the same value.
TEST(Determinism, GoldenHashRepeatsWithinOneProcess) {
  const auto host = make_host();
  const GoldenCase c{"pyramid_drop_10", "ledas", 50};
  EXPECT_EQ(trajectory_hash(c, *host), trajectory_hash(c, *host));
}

}  // namespace
}  // namespace impetus::reliability
