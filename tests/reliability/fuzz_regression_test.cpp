// Every seed input and every kept crash input of the fuzzers (fuzz/corpus/<target>,
// fuzz/regressions/<target>) through the same code the fuzzers run (fuzz/targets.cpp), with any
// compiler and under the sanitizers: none may crash, and each target's corpus must contain both inputs
// it accepts and inputs it rejects (so the corpus exercises both paths).

#include "reliability_support.hpp"
#include "targets.hpp"

#include <algorithm>

namespace impetus::reliability {
namespace {

std::vector<fs::path> inputs(const std::string& target) {
  std::vector<fs::path> files;
  for (const char* kind : {"corpus", "regressions"}) {
    const fs::path dir = source_dir() / "fuzz" / kind / target;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
      if (it->is_regular_file()) files.push_back(it->path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class FuzzInputs : public testing::TestWithParam<std::string> {};

TEST_P(FuzzInputs, RunWithoutCrashing) {
  const std::string target = GetParam();
  const std::vector<fs::path> files = inputs(target);
  ASSERT_FALSE(files.empty()) << "no seed corpus for " << target;
  int accepted = 0, rejected = 0;
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    const std::string bytes = bytes_of(file);
    const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
    const fuzz::Outcome outcome = target == "scene" ? fuzz::scene_one_input(data, bytes.size())
                                  : target == "set" ? fuzz::overrides_one_input(data, bytes.size())
                                                    : fuzz::mesh_one_input(data, bytes.size(), target.substr(5));
    ++(outcome == fuzz::Outcome::accepted ? accepted : rejected);
  }
  EXPECT_GT(accepted, 0) << target << ": the corpus must hold inputs the pipeline accepts";
  if (target == "scene" || target == "set" || target == "mesh_obj" || target == "mesh_stl") {
    EXPECT_GT(rejected, 0) << target << ": the corpus must hold inputs the pipeline rejects";
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzInputs,
                         testing::Values("scene", "set", "mesh_obj", "mesh_stl", "mesh_ply", "mesh_off", "mesh_gltf",
                                         "mesh_glb", "mesh_dae"));

}  // namespace
}  // namespace impetus::reliability
