// The bundled meshes are what scripts/make_meshes.py writes: regenerate into a temporary directory
// and compare byte for byte (the script is deterministic; nothing in assets/meshes is hand-made).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(MeshGenerator, RegeneratesTheBundledMeshesExactly) {
  const std::string python = IMPETUS_PYTHON;
  if (python.empty()) GTEST_SKIP() << "no python3 found at configure time";
  const fs::path bundled = fs::path(IMPETUS_SOURCE_DIR) / "assets" / "meshes";
  const fs::path out = fs::temp_directory_path() / ("impetus_meshes_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::string command = python + " " + (fs::path(IMPETUS_SOURCE_DIR) / "scripts" / "make_meshes.py").string() +
                              " " + out.string() + " > /dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  std::size_t compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(out)) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), out);
    ASSERT_TRUE(fs::exists(bundled / relative)) << relative << " is generated but not committed";
    EXPECT_EQ(read(entry.path()), read(bundled / relative)) << relative << " differs from what the script writes";
    ++compared;
  }
  for (const auto& entry : fs::recursive_directory_iterator(bundled)) {
    if (entry.is_regular_file()) {
      EXPECT_TRUE(fs::exists(out / fs::relative(entry.path(), bundled))) << entry.path() << " is not generated";
    }
  }
  EXPECT_GT(compared, 60u);
  fs::remove_all(out);
}

}  // namespace
