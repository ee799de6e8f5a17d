// `impetus mass` as a user runs it: the JSON and text reports, --density, --mass, --scale, --part,
// and a broken mesh refused with a non-zero exit and one message naming the file and the defect.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "impetus_test/process.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace {

struct Result {
  int status = -1;
  std::string out;  // stdout only
  std::string all;  // stdout and stderr
};

Result run(const std::string& args) {
  const std::string command = std::string(IMPETUS_EXE) + " " + args;
  const impetus::test::CommandResult quiet = impetus::test::run_shell(command, "/dev/null");
  const impetus::test::CommandResult all = impetus::test::run_shell(command);
  return {all.status, quiet.out, all.out};
}

std::string mesh(const std::string& name) { return std::string(IMPETUS_SOURCE_DIR) + "/assets/meshes/" + name; }

// Box 0.5 × 1.25 × 2 m from (1, −2, 0.25): V = 1.25, center (1.25, −1.375, 1.25),
// I = m/12 diag(b² + c², a² + c², a² + b²).
TEST(MassCli, JsonReportOfABox) {
  const Result r = run("mass " + mesh("box.glb") + " --density 7800 --json");
  ASSERT_EQ(r.status, 0) << r.all;
  const auto j = nlohmann::json::parse(r.out);
  const double m = 7800 * 1.25;
  EXPECT_NEAR(j["volume"].get<double>(), 1.25, 1e-14);
  EXPECT_NEAR(j["mass"].get<double>(), m, 1e-9);
  EXPECT_NEAR(j["density"].get<double>(), 7800, 1e-9);
  const std::vector<double> com = j["center_of_mass"];
  EXPECT_NEAR(com[0], 1.25, 1e-14);
  EXPECT_NEAR(com[1], -1.375, 1e-14);
  EXPECT_NEAR(com[2], 1.25, 1e-14);
  const double Ixx = m / 12 * (1.25 * 1.25 + 4), Iyy = m / 12 * (0.25 + 4), Izz = m / 12 * (0.25 + 1.25 * 1.25);
  EXPECT_NEAR(j["inertia"][0][0].get<double>(), Ixx, 1e-12 * Ixx);
  EXPECT_NEAR(j["inertia"][1][1].get<double>(), Iyy, 1e-12 * Ixx);
  EXPECT_NEAR(j["inertia"][2][2].get<double>(), Izz, 1e-12 * Ixx);
  EXPECT_NEAR(j["inertia"][0][1].get<double>(), 0.0, 1e-12 * Ixx);
  EXPECT_NEAR(j["principal_moments"][0].get<double>(), Izz, 1e-12 * Ixx);
  EXPECT_NEAR(j["principal_moments"][2].get<double>(), Ixx, 1e-12 * Ixx);
  EXPECT_EQ(j["principal_axes"].size(), 3u);
  EXPECT_EQ(j["vertices"], 8);
  EXPECT_EQ(j["triangles"], 12);
  EXPECT_EQ(j["convex"], true);
  EXPECT_EQ(j["format"], "glTF2 Importer");
}

TEST(MassCli, MassAndScaleOptions) {
  const Result r = run("mass " + mesh("cube.stl") + " --mass 2 --scale 0.5 --json");
  ASSERT_EQ(r.status, 0) << r.all;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["volume"].get<double>(), 0.125, 1e-15);
  EXPECT_NEAR(j["mass"].get<double>(), 2.0, 1e-15);
  EXPECT_NEAR(j["inertia"][0][0].get<double>(), 2.0 * 0.25 / 6, 1e-15);  // m a² / 6
  EXPECT_NEAR(j["center_of_mass"][0].get<double>(), 0.25, 1e-15);
  EXPECT_NE(run("mass " + mesh("cube.stl") + " --mass 2 --density 3").status, 0);  // one or the other
}

TEST(MassCli, PartOfAFile) {
  const Result r = run("mass " + mesh("two_boxes.gltf") + " --part right --json");
  ASSERT_EQ(r.status, 0) << r.all;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["part"], "right");
  EXPECT_NEAR(j["volume"].get<double>(), 1.0, 1e-15);
  EXPECT_NEAR(j["center_of_mass"][0].get<double>(), 3.5, 1e-14);
}

TEST(MassCli, TextReportNamesEveryQuantity) {
  const Result r = run("mass " + mesh("t_handle.obj") + " --density 1200");
  ASSERT_EQ(r.status, 0) << r.all;
  for (const char* word : {"volume", "mass", "center of mass", "inertia about the center of mass", "principal moments",
                           "principal axes", "not convex", "16 vertices, 28 triangles"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << "\n" << r.out;
}

// A fixable problem is a warning on stderr; the numbers still come out.
TEST(MassCli, WarningGoesToStderr) {
  const Result r = run("mass " + mesh("broken/inverted_cube.obj") + " --json");
  ASSERT_EQ(r.status, 0) << r.all;
  EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out;
  EXPECT_NE(r.all.find("impetus: warning: " + mesh("broken/inverted_cube.obj") + ": the mesh is wound inward"),
            std::string::npos)
      << r.all;
}

// Each broken mesh: exit status 1 and exactly one line, naming the file and the defect.
TEST(MassCli, BrokenMeshIsOneErrorLine) {
  for (const auto& [name, defect] : std::vector<std::pair<std::string, std::string>>{
           {"broken/open_cube.obj", "4 boundary edges: the mesh is not closed"},
           {"broken/truncated.stl", "truncated binary STL"},
           {"broken/nan_cube.obj", "a vertex is not a finite point"},
           {"nowhere.stl", "no such mesh file"}}) {
    const Result r = run("mass " + mesh(name));
    EXPECT_EQ(r.status, 1) << name;
    EXPECT_EQ(r.all.rfind("impetus: error: " + mesh(name) + ": " + defect, 0), 0u) << r.all;
    EXPECT_EQ(std::count(r.all.begin(), r.all.end(), '\n'), 1) << r.all;
  }
}

}  // namespace
