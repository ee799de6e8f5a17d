// `impetus run SCENE --out run.glb | run.gltf` (README.md, "The `impetus` tool"): the file is valid glTF 2.0
// by the Khronos glTF-Validator (npm `gltf-validator`, pinned in tests/gltf/, installed by
// scripts/setup.sh; no errors and no warnings), and read back with tinygltf it holds one node per body,
// named as the bodies are, and an animation whose times and poses are the CSV of the same run at float32
// precision, exactly.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "impetus_test/process.hpp"

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

using Result = impetus::test::CommandResult;

Result run(const std::string& command) { return impetus::test::run_shell(command); }

fs::path temp_file(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("impetus_gltf_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

// One CSV row of the trajectory.
struct Pose {
  double time;
  float x, y, z, qw, qx, qy, qz;
};

// body name → its rows in order; `order` gets the names in first-seen order.
std::map<std::string, std::vector<Pose>> read_csv(const fs::path& file, std::vector<std::string>& order) {
  std::map<std::string, std::vector<Pose>> poses;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
    if (f.size() != 16) continue;
    if (!poses.count(f[2])) order.push_back(f[2]);
    const auto v = [&](int i) { return static_cast<float>(std::stod(f[i])); };
    poses[f[2]].push_back({std::stod(f[1]), v(3), v(4), v(5), v(6), v(7), v(8), v(9)});
  }
  return poses;
}

// The floats an accessor holds (tightly packed, as the exporter writes them).
std::vector<float> floats(const tinygltf::Model& model, int accessor) {
  const tinygltf::Accessor& a = model.accessors.at(accessor);
  const tinygltf::BufferView& view = model.bufferViews.at(a.bufferView);
  const auto& data = model.buffers.at(view.buffer).data;
  const std::size_t components = a.type == TINYGLTF_TYPE_SCALAR ? 1 : a.type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
  std::vector<float> out(a.count * components);
  std::memcpy(out.data(), data.data() + view.byteOffset + a.byteOffset, out.size() * sizeof(float));
  return out;
}

void check_export(const std::string& scene, const std::string& stem) {
  SCOPED_TRACE(scene);
  const std::string exe = IMPETUS_EXE, args = " run " + scene + " --steps 200 --every 10 --overwrite --out ";
  const fs::path glb = temp_file(stem + ".glb"), gltf = temp_file(stem + ".gltf"), csv = temp_file(stem + ".csv");
  for (const fs::path& f : {glb, gltf, csv}) {
    const Result r = run(exe + args + f.string());
    ASSERT_EQ(r.status, 0) << r.out;
  }

  // Valid glTF 2.0: no errors and no warnings, in both forms.
  const fs::path validator_dir = fs::path(IMPETUS_SOURCE_DIR) / "tests" / "gltf";
  ASSERT_TRUE(fs::exists(validator_dir / "node_modules" / "gltf-validator"))
      << "the glTF-Validator is not installed: run scripts/setup.sh (npm ci in tests/gltf/)";
  for (const fs::path& f : {glb, gltf}) {
    const Result v = run("node " + (validator_dir / "validate.js").string() + " " + f.string());
    ASSERT_EQ(v.status, 0) << v.out;
    const auto report = nlohmann::json::parse(v.out);
    EXPECT_EQ(report["errors"].get<int>(), 0) << f << ": " << report.dump();
    EXPECT_EQ(report["warnings"].get<int>(), 0) << f << ": " << report.dump();
  }

  // Read back: nodes, names, sample times and poses against the CSV of the same run.
  std::vector<std::string> names;
  const auto poses = read_csv(csv, names);
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string error, warning;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &error, &warning, glb.string())) << error;
  ASSERT_EQ(model.nodes.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) EXPECT_EQ(model.nodes[i].name, names[i]);
  EXPECT_EQ(model.asset.extras.Get("impetus_scene").Get<std::string>(), scene);
  ASSERT_EQ(model.animations.size(), 1u);
  const tinygltf::Animation& animation = model.animations[0];
  int checked = 0;
  for (const tinygltf::AnimationChannel& channel : animation.channels) {
    const tinygltf::AnimationSampler& sampler = animation.samplers.at(channel.sampler);
    EXPECT_EQ(sampler.interpolation, "LINEAR");
    const std::vector<float> times = floats(model, sampler.input), values = floats(model, sampler.output);
    const std::vector<Pose>& rows = poses.at(model.nodes.at(channel.target_node).name);
    ASSERT_EQ(times.size(), rows.size());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      ASSERT_EQ(times[k], static_cast<float>(rows[k].time));
      if (channel.target_path == "translation") {
        ASSERT_EQ(values[3 * k], rows[k].x);
        ASSERT_EQ(values[3 * k + 1], rows[k].y);
        ASSERT_EQ(values[3 * k + 2], rows[k].z);
      } else {
        ASSERT_EQ(channel.target_path, "rotation");
        ASSERT_EQ(values[4 * k], rows[k].qx);
        ASSERT_EQ(values[4 * k + 1], rows[k].qy);
        ASSERT_EQ(values[4 * k + 2], rows[k].qz);
        ASSERT_EQ(values[4 * k + 3], rows[k].qw);
      }
    }
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

// Primitives of every kind on a ground plane.
TEST(CliGltf, PrimitivesExportAsValidGltfThatMatchesTheCsv) {
  check_export(std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/resting_shapes.yaml", "shapes");
}

// Imported meshes (OBJ, glTF, STL, PLY), convex and triangle collision.
TEST(CliGltf, MeshesExportAsValidGltfThatMatchesTheCsv) {
  check_export(std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/meshes_drop.yaml", "meshes");
}

// A run too long to keep in memory is refused before it starts, naming --every; nothing is written.
TEST(CliGltf, AnAnimationTooLargeIsRefusedBeforeTheRun) {
  const fs::path glb = temp_file("huge.glb");
  fs::remove(glb);
  const Result r = run(std::string(IMPETUS_EXE) + " run " + IMPETUS_SOURCE_DIR +
                       "/assets/scenes/pyramid_drop_10.yaml --steps 100000000 --out " + glb.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--every"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(glb));
}

}  // namespace
