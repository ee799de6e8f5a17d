// No allocation in the steady state: once a scene's contact pattern is stable, a whole step (detection,
// resolution, integration) allocates nothing, for every thread count. Counted by the replaced global
// operator new and C's malloc, calloc and realloc (benchmarks/support/allocation_counter.cpp, linked into
// this program only); under AddressSanitizer the sanitizer owns malloc and the test is skipped.
//
// What is asserted is exact: zero allocations over kMeasuredSteps steps after kWarmSteps steps, with the
// ledas resolver (complementary mode) on frictionless and frictional scenes, and with the sequential
// resolver (mirtich).

#include "reliability_support.hpp"
#include "support/allocation_counter.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace impetus::reliability {
namespace {

constexpr int kWarmSteps = 20;
constexpr int kMeasuredSteps = 50;

struct SteadyScene {
  std::string name;
  std::string yaml;
};

void PrintTo(const SteadyScene& s, std::ostream* out) { *out << s.name; }

class SteadyState : public testing::TestWithParam<SteadyScene> {};

// Allocations made by `steps` steps of `world`.
std::uint64_t allocations_over(World& world, int steps) {
  const std::uint64_t before = bench::allocations();
  for (int i = 0; i < steps; ++i) world.step();
  return bench::allocations() - before;
}

TEST_P(SteadyState, StepsAllocateNothing) {
  if (!bench::counts_malloc()) GTEST_SKIP() << "sanitizer build: malloc is the sanitizer's, not counted";
  const auto host = make_host();
  for (const std::uint32_t threads : {1u, 2u}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    const std::unique_ptr<World> world =
        build_world(load_scene_text(GetParam().yaml, "steady.yaml", scenes_dir(),
                                    {{"threads", std::to_string(threads)}}),
                    *host);
    const std::uint64_t warm = allocations_over(*world, kWarmSteps);
    EXPECT_GT(warm, 0u);  // the counter counts: the first steps size every buffer
    const std::size_t contacts = world->contacts().size();
    EXPECT_EQ(allocations_over(*world, kMeasuredSteps), 0u);
    EXPECT_EQ(world->contacts().size(), contacts);  // the contact pattern was stable
    EXPECT_GT(contacts, 0u);
    EXPECT_EQ(world->last_status().resolver.non_converged, 0u);
  }
}

const std::string kModules = "modules: {integrator: momentum, detector: fcl, resolver: {plugin: ledas, mode: complementary}}\n";

INSTANTIATE_TEST_SUITE_P(
    Frictionless, SteadyState,
    testing::Values(
        // One island: the pyramid of 55 spheres resting on the ground under gravity.
        SteadyScene{"pyramid_10", kModules + "generators:\n  - pyramid: {rows: 10, radius: 0.5}\n"},
        // A line of 100 spheres against a wall, the first moving in: the impact runs through the line.
        SteadyScene{"line_100", kModules + "gravity: [0, 0, 0]\ngenerators:\n  - line: {count: 100, radius: 0.5}\n"},
        // Many islands of different sizes: pyramids of 1 to 6 rows side by side on one ground.
        SteadyScene{"islands", kModules + [] {
                      std::string text = "bodies:\n  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1]}}}\n";
                      double x = 0.0;
                      for (int rows = 1; rows <= 6; ++rows) {
                        for (int r = 0; r < rows; ++r)
                          for (int i = 0; i < rows - r; ++i)
                            text += "  - {name: p" + std::to_string(rows) + "_" + std::to_string(r) + "_" +
                                    std::to_string(i) + ", shape: {sphere: {radius: 0.5}}, mass: 1, position: [" +
                                    std::to_string(x + i + 0.5 * r) + ", 0, " +
                                    std::to_string(0.4999 + r * 0.86593) + "]}\n";
                        x += rows + 2.0;
                      }
                      return text;
                    }()}),
    [](const testing::TestParamInfo<SteadyScene>& info) { return info.param.name; });

// `count` unit boxes stacked on the ground, 10 µm into each other and the ground, all with friction μ.
std::string box_stack(int count, double mu) {
  const std::string friction = std::to_string(mu);
  std::string text = "bodies:\n  - {name: ground, fixed: true, friction: " + friction +
                     ", shape: {plane: {normal: [0, 0, 1]}}}\n";
  for (int i = 0; i < count; ++i)
    text += "  - {name: box" + std::to_string(i) + ", shape: {box: {size: [1, 1, 1]}}, mass: 1, friction: " + friction +
            ", position: [0, 0, " + std::to_string(0.49999 + 0.99999 * i) + "]}\n";
  return text;
}

// A test name from the scene's name (a test name has no dots).
std::string test_name(const testing::TestParamInfo<SteadyScene>& info) {
  std::string name = info.param.name;
  std::replace(name.begin(), name.end(), '.', '_');
  return name;
}

// With Coulomb friction: the frictional solver (resolution/ledas/frictional_solver.hpp) from its warm
// start, polished by Newton steps where it does not solve at once, in each island's buffers. Newton's
// systems of more than FrictionalSettings::dense_limit rows (96) where no contact slides are the symmetric
// LDLᵀ on W's kept analysis, which does not allocate (the pyramid of 10 rows, 300 rows); where a contact
// slides they are factorized by KLU, whose refactorization on the last pivot sequence does not allocate
// either, but a factorization with pivoting does (a pattern's first, or when the refactorization's
// direction fails its check; README.md), so sliding scenes are not among these.
std::vector<SteadyScene> frictional_scenes(const std::string& modules) {
  return {
      // A pyramid of 10 spheres at rest with μ = 0.7 (every contact sticks).
      SteadyScene{"pyramid_4_mu0.7", modules + "generators:\n  - pyramid: {rows: 4, radius: 0.5, friction: 0.7}\n"},
      // The pyramid of 55 spheres at rest with μ = 0.7: 300 rows, above dense_limit; Newton's steps, where
      // every contact sticks, are the symmetric LDLᵀ on W's kept analysis.
      SteadyScene{"pyramid_10_mu0.7", modules + "generators:\n  - pyramid: {rows: 10, radius: 0.5, friction: 0.7}\n"},
      // Five unit boxes stacked on the ground with μ = 0.5: four contacts per face, more rows than
      // degrees of freedom (a redundant contact set; the warm start needs Newton's polish).
      SteadyScene{"stack_5_mu0.5", modules + box_stack(5, 0.5)}};
}

INSTANTIATE_TEST_SUITE_P(Frictional, SteadyState, testing::ValuesIn(frictional_scenes(kModules)), test_name);

// Without warm starts every step's frictional solve is cold: the interior point on the convex relaxation
// (its LDLᵀ, on the sparse path for the 300 rows of the larger pyramid), then Newton's polish (with W
// shifted on the redundant stack), in the island's buffers, with the analyses kept while W's pattern holds.
INSTANTIATE_TEST_SUITE_P(
    FrictionalCold, SteadyState,
    testing::ValuesIn(frictional_scenes(
        "modules: {integrator: momentum, detector: fcl, resolver: {plugin: ledas, mode: complementary, warm_start: false}}\n")),
    test_name);

// The sequential resolver (mirtich) keeps its buffers too: the same resting pyramid, and the stack of
// boxes with friction (Mirtich's frictional collision integration). Not the line: a line of 100 spheres
// is where the sequential sweep reaches its impulse cap every step (resolution/mirtich/README.md), so
// there is no converged steady state to measure.
const std::string kMirtich = "modules: {integrator: momentum, detector: fcl, resolver: mirtich}\n";

INSTANTIATE_TEST_SUITE_P(
    Sequential, SteadyState,
    testing::Values(SteadyScene{"pyramid_10", kMirtich + "generators:\n  - pyramid: {rows: 10, radius: 0.5}\n"},
                    SteadyScene{"stack_5_mu0.5", kMirtich + box_stack(5, 0.5)}),
    test_name);

}  // namespace
}  // namespace impetus::reliability
