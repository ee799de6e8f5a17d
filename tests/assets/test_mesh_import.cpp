// Import through assimp: every format of a bundled mesh gives the same welded mesh and the same mass
// properties; STL's per-facet vertices are welded; scale, units, several meshes per file (merged or
// separate), mirrored node transforms; unreadable files are refused with the file named.
#include "asset_test_support.hpp"

#include "impetus/assets/mesh_body.hpp"
#include "impetus/assets/mesh_import.hpp"
#include "impetus/assets/mesh_validation.hpp"
#include "impetus/core/error.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cstdio>
#include <functional>
#include <map>

namespace impetus::test {
namespace {

using assets::import_mesh;
using assets::ImportOptions;

const std::vector<std::string> kAllFormats = {".obj", ".stl", "_ascii.stl", ".ply", "_ascii.ply", ".off", ".gltf", ".glb"};

// name → (vertices, triangles) after welding.
const std::map<std::string, std::pair<std::size_t, std::size_t>> kMeshes = {
    {"cube", {8, 12}}, {"box", {8, 12}}, {"tetrahedron", {4, 4}}, {"l_bracket", {12, 20}},
    {"t_handle", {16, 28}}, {"icosphere_2", {162, 320}}};

// Every format holds the same float32 vertices, so every import gives the same welded mesh and
// bit-identical mass properties (compared to 1e-15 to leave room for summation order).
TEST(MeshImport, EveryFormatGivesTheSameBody) {
  for (const auto& [name, counts] : kMeshes) {
    const assets::MeshBody reference = assets::load_mesh_body(mesh_path(name + ".obj"));
    for (const std::string& suffix : kAllFormats) {
      const std::string file = mesh_path(name + suffix);
      const assets::ImportedMesh imported = import_mesh(file);
      ASSERT_EQ(imported.parts.size(), 1u) << file;
      EXPECT_EQ(imported.parts[0].mesh.vertices.size(), counts.first) << file;
      EXPECT_EQ(imported.parts[0].mesh.triangles.size(), counts.second) << file;
      EXPECT_TRUE(imported.warnings.empty()) << file << ": " << imported.warnings.front();
      const assets::MeshBody body = assets::load_mesh_body(file);
      EXPECT_TRUE(body.warnings.empty()) << file;
      EXPECT_LT(relative_error(body.unit.volume, reference.unit.volume), 1e-15) << file;
      EXPECT_LT((body.center_of_mass_file - reference.center_of_mass_file).norm(), 1e-15) << file;
      EXPECT_LT(relative_error(body.unit.inertia, reference.unit.inertia), 1e-15) << file;
      EXPECT_EQ(body.convex, reference.convex) << file;
    }
  }
}

// STL stores three vertices per facet with the facet's normal. assimp's aiProcess_JoinIdenticalVertices
// compares normals too, so it leaves a cube's corners apart (24 or 36 vertices instead of 8) and the
// mesh open; the importer welds on position instead. Both STL flavours come out closed.
TEST(MeshImport, StlVerticesAreWelded) {
  for (const char* name : {"cube.stl", "cube_ascii.stl", "icosphere_2.stl"}) {
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(mesh_path(name), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
    ASSERT_NE(scene, nullptr);
    std::printf("[ import   ] %s: assimp's JoinIdenticalVertices leaves %u vertices\n", name, scene->mMeshes[0]->mNumVertices);
    assets::ImportedMesh imported = import_mesh(mesh_path(name));
    const std::size_t expected = std::string(name).starts_with("cube") ? 8 : 162;
    EXPECT_EQ(imported.parts[0].mesh.vertices.size(), expected) << name;
    EXPECT_TRUE(assets::validate_mesh(imported.parts[0].mesh).ok()) << name;
  }
}

TEST(MeshImport, WeldKeepsNaNApartAndJoinsSignedZeros) {
  TriangleMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(-0.0, 0, 0), Vec3(NAN, 0, 0), Vec3(NAN, 0, 0), Vec3(1, 1, 1)};
  m.triangles = {{0, 2, 4}, {1, 3, 4}};
  assets::weld_identical_vertices(m);
  EXPECT_EQ(m.vertices.size(), 4u);  // the zeros joined, the NaNs not
  EXPECT_EQ(m.triangles[0][0], m.triangles[1][0]);
  EXPECT_NE(m.triangles[0][1], m.triangles[1][1]);
}

// `scale` multiplies coordinates: volume × s³, inertia × s⁵ (density fixed).
TEST(MeshImport, ScaleMultipliesCoordinates) {
  ImportOptions options;
  options.scale = 0.5;
  const assets::MeshBody half = assets::load_mesh_body(mesh_path("l_bracket.stl"), options);
  const assets::MeshBody full = assets::load_mesh_body(mesh_path("l_bracket.stl"));
  EXPECT_LT(relative_error(half.unit.volume, full.unit.volume / 8), 1e-15);
  EXPECT_LT(relative_error(half.unit.inertia, full.unit.inertia / 32), 1e-15);
  EXPECT_LT((half.center_of_mass_file - full.center_of_mass_file / 2).norm(), 1e-15);
}

// A COLLADA file in centimetres (<unit meter="0.01">) becomes the same body as the file in metres,
// with a warning; with units kept as written it is 100× larger (and the warning says so).
TEST(MeshImport, CentimetreFileIsConvertedToMetresWithAWarning) {
  const assets::MeshBody metres = assets::load_mesh_body(mesh_path("l_bracket.obj"));
  const assets::MeshBody converted = assets::load_mesh_body(mesh_path("l_bracket_cm.dae"));
  EXPECT_LT(relative_error(converted.unit.volume, metres.unit.volume), 1e-6);  // float32 data, cm vs m
  EXPECT_LT(relative_error(converted.unit.inertia, metres.unit.inertia), 1e-6);
  ASSERT_EQ(converted.warnings.size(), 1u);
  EXPECT_NE(converted.warnings[0].find("l_bracket_cm.dae: the file's unit is 0.01 m (centimetres); converted to metres"),
            std::string::npos)
      << converted.warnings[0];
  ImportOptions as_written;
  as_written.units = assets::UnitMode::as_written;
  const assets::ImportedMesh raw = import_mesh(mesh_path("l_bracket_cm.dae"), as_written);
  EXPECT_NEAR(assets::signed_volume(raw.parts[0].mesh), 1e6 * metres.unit.volume, 1e-6 * 1e6 * metres.unit.volume);
  ASSERT_EQ(raw.warnings.size(), 1u);
  EXPECT_NE(raw.warnings[0].find("kept as metres"), std::string::npos) << raw.warnings[0];
}

// A unitless STL written in millimetres is 400 "metres" across: imported as written, with a warning
// that suggests the scale; with the scale, no warning and the right body.
TEST(MeshImport, HugeUnitlessMeshWarnsAboutItsUnit) {
  const assets::ImportedMesh mm = import_mesh(mesh_path("l_bracket_mm.stl"));
  ASSERT_EQ(mm.warnings.size(), 1u);
  EXPECT_NE(mm.warnings[0].find("is 400 m across"), std::string::npos) << mm.warnings[0];
  EXPECT_NE(mm.warnings[0].find("scale 0.001"), std::string::npos) << mm.warnings[0];
  ImportOptions options;
  options.scale = 0.001;
  const assets::MeshBody scaled = assets::load_mesh_body(mesh_path("l_bracket_mm.stl"), options);
  EXPECT_TRUE(scaled.warnings.empty());
  EXPECT_LT(relative_error(scaled.unit.volume, assets::load_mesh_body(mesh_path("l_bracket.obj")).unit.volume), 1e-6);
}

// Two boxes in one file (glTF: two nodes, the second translated 3 m; OBJ: two objects). Default:
// merged into one body (volume 1 + 1). Separate: one part per node, named, placed by its transform.
TEST(MeshImport, SeveralMeshesMergeByDefaultOrStaySeparate) {
  for (const char* name : {"two_boxes.gltf", "two_boxes.obj"}) {
    const assets::MeshBody merged = assets::load_mesh_body(mesh_path(name));
    EXPECT_DOUBLE_EQ(merged.unit.volume, 2.0) << name;
    EXPECT_EQ(merged.mesh->vertices.size(), 16u) << name;
    EXPECT_FALSE(merged.convex) << name;
    ImportOptions separate;
    separate.parts = assets::PartMode::separate;
    const assets::ImportedMesh parts = import_mesh(mesh_path(name), separate);
    ASSERT_EQ(parts.parts.size(), 2u) << name;
    EXPECT_EQ(parts.parts[0].name, "left");
    EXPECT_EQ(parts.parts[1].name, "right");
    EXPECT_DOUBLE_EQ(assets::signed_volume(parts.parts[1].mesh), 1.0);
    const assets::MeshBody right = assets::load_mesh_body(mesh_path(name), {}, "right");
    EXPECT_LT((right.center_of_mass_file - Vec3(3.5, 1.0, 0.25)).norm(), 1e-14) << name;
    EXPECT_TRUE(right.convex);
    const std::string missing = error_of([&] { assets::load_mesh_body(mesh_path(name), {}, "middle"); });
    EXPECT_NE(missing.find("no part named 'middle'; its parts are 'left', 'right'"), std::string::npos) << missing;
  }
}

// A node that mirrors (scale −1 on x) would turn the triangles inside out; the importer reverses them.
TEST(MeshImport, MirroringNodeKeepsTheMeshOutward) {
  const assets::MeshBody body = assets::load_mesh_body(mesh_path("mirrored_box.gltf"));
  EXPECT_TRUE(body.warnings.empty()) << body.warnings.front();
  EXPECT_DOUBLE_EQ(body.unit.volume, 1.0);
  EXPECT_LT((body.center_of_mass_file - Vec3(-1.5, 0.5, 0.5)).norm(), 1e-14);
}

TEST(MeshImport, UnreadableFilesNameTheFileAndTheProblem) {
  EXPECT_EQ(error_of([] { import_mesh(mesh_path("nowhere.obj")); }), mesh_path("nowhere.obj") + ": no such mesh file");
  EXPECT_EQ(error_of([] { import_mesh(mesh_path("broken/empty.obj")); }),
            mesh_path("broken/empty.obj") + ": the mesh file is empty");
  EXPECT_EQ(error_of([] { import_mesh(mesh_path("broken/truncated.stl")); }),
            mesh_path("broken/truncated.stl") +
                ": truncated binary STL: its header announces 12 triangles (684 bytes) but the file has 354 bytes");
  EXPECT_EQ(error_of([] { import_mesh(mesh_path("broken/no_triangles.obj")); }),
            mesh_path("broken/no_triangles.obj") + ": the file holds no triangles (only 2 points or lines)");
  EXPECT_EQ(error_of([] { import_mesh(std::string(IMPETUS_SOURCE_DIR) + "/README.md"); }).rfind(
                std::string(IMPETUS_SOURCE_DIR) + "/README.md: assimp cannot read it: ", 0),
            0u);
}

}  // namespace
}  // namespace impetus::test
