// Validation before any physics: every broken bundled mesh is refused with its own message naming
// the file and the defect (and never crashes); an inward-wound mesh is flipped with a warning;
// cavities are kept, overlapping solids refused.
#include "asset_test_support.hpp"

#include "impetus/assets/mesh_body.hpp"
#include "impetus/assets/mesh_validation.hpp"
#include "impetus/core/error.hpp"

#include <set>

namespace impetus::test {
namespace {

using assets::MeshDefect;
using assets::validate_mesh;

std::string load_error(const std::string& name) {
  try {
    assets::load_mesh_body(mesh_path(name));
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << name << " was accepted";
  return {};
}

// Each broken file: the message starts with the file and names the defect, with an example.
TEST(MeshValidation, EveryBrokenMeshIsRefusedWithItsOwnMessage) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"broken/open_cube.obj", ": 4 boundary edges: the mesh is not closed (one runs from ("},
      {"broken/flipped_face_cube.obj",
       ": 3 edges are run the same way by both triangles that share it: the mesh is not consistently oriented"},
      {"broken/degenerate_cube.obj", ": 1 degenerate triangle (zero area): the first has corners (0, 0, 0), (1, 0, 0), (0.5, 0, 0)"},
      {"broken/nan_cube.obj", ": a vertex is not a finite point (NaN or infinite): ("},
      {"broken/nonmanifold.obj", ": 1 edge is shared by more than two triangles: the mesh is not manifold (the one from ("},
      {"broken/flat.obj", ": the mesh encloses no volume: it is flat or its faces cancel"},
      {"broken/overlapping.obj", ": two closed shells are wound outward and one lies inside the other"},
      {"broken/empty.obj", ": the mesh file is empty"},
      {"broken/no_triangles.obj", ": the file holds no triangles"},
      {"broken/truncated.stl", ": truncated binary STL: its header announces 12 triangles"},
  };
  std::set<std::string> messages;
  for (const auto& [file, expected] : cases) {
    const std::string message = load_error(file);
    EXPECT_EQ(message.rfind(mesh_path(file) + expected, 0), 0u) << "got:      " << message << "\nexpected: " << expected;
    messages.insert(message.substr(mesh_path(file).size()));
  }
  EXPECT_EQ(messages.size(), cases.size()) << "two defects share a message";
}

// An inward-wound cube is a cube: flipped with a warning, same mass properties.
TEST(MeshValidation, InvertedMeshIsFlippedWithAWarning) {
  const assets::MeshBody flipped = assets::load_mesh_body(mesh_path("broken/inverted_cube.obj"));
  ASSERT_EQ(flipped.warnings.size(), 1u);
  EXPECT_EQ(flipped.warnings[0], mesh_path("broken/inverted_cube.obj") +
                                     ": the mesh is wound inward (its triangles run clockwise seen from outside); flipped it");
  const assets::MeshBody cube = assets::load_mesh_body(mesh_path("cube.obj"));
  EXPECT_DOUBLE_EQ(flipped.unit.volume, 1.0);
  EXPECT_LT(relative_error(flipped.unit.inertia, cube.unit.inertia), 1e-15);
}

TEST(MeshValidation, IndexOutOfRangeIsReported) {
  TriangleMesh m = box_mesh(Vec3::Zero(), Vec3::Ones());
  m.triangles[3][1] = 99;
  const auto r = validate_mesh(m);
  EXPECT_EQ(r.defect, MeshDefect::bad_index);
  EXPECT_EQ(r.message, "triangle 3 refers to vertex 99, but there are 8 vertices");
  TriangleMesh empty;
  EXPECT_EQ(validate_mesh(empty).defect, MeshDefect::empty);
}

// A hollow box: the inner shell wound inward is a cavity, kept; volume = outer − inner.
TEST(MeshValidation, CavityWoundInwardIsKept) {
  TriangleMesh m = box_mesh(Vec3::Zero(), Vec3::Constant(2));
  TriangleMesh inner = box_mesh(Vec3::Constant(0.5), Vec3::Constant(1.5));
  const auto base = std::uint32_t(m.vertices.size());
  m.vertices.insert(m.vertices.end(), inner.vertices.begin(), inner.vertices.end());
  for (const auto& t : inner.triangles) m.triangles.push_back({base + t[0], base + t[2], base + t[1]});
  TriangleMesh hollow = m;
  const auto r = validate_mesh(hollow);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.flipped_shells, 0u);
  EXPECT_DOUBLE_EQ(assets::signed_volume(hollow), 8.0 - 1.0);
  // The same mesh entirely inside out is flipped as a whole and is still a hollow box.
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  const auto flipped = validate_mesh(m);
  ASSERT_TRUE(flipped.ok()) << flipped.message;
  EXPECT_EQ(flipped.flipped_shells, 2u);
  EXPECT_DOUBLE_EQ(assets::signed_volume(m), 7.0);
}

// Two separate boxes, one wound inward: only that shell is flipped.
TEST(MeshValidation, OneInvertedShellAmongSeveralIsFlipped) {
  TriangleMesh m = box_mesh(Vec3::Zero(), Vec3::Constant(2));
  const TriangleMesh other = box_mesh(Vec3(5, 0, 0), Vec3(6, 1, 1));
  const auto base = std::uint32_t(m.vertices.size());
  m.vertices.insert(m.vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const auto& t : other.triangles) m.triangles.push_back({base + t[0], base + t[2], base + t[1]});
  const auto r = validate_mesh(m);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.flipped_shells, 1u);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0], "a shell of the mesh (near (5, 0, 0)) is wound inward; flipped it");
  EXPECT_DOUBLE_EQ(assets::signed_volume(m), 9.0);
}

// A sliver far below the mesh's size is degenerate; a thin but real triangle is not.
TEST(MeshValidation, DegenerateThresholdIsRelativeToTheMeshSize) {
  TriangleMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  TriangleMesh thin = m;
  thin.vertices[3].z() = 1e-5;  // a flat but real tetrahedron: twice its smallest area is 1e-5
  EXPECT_TRUE(validate_mesh(thin).ok());
  thin.vertices[3].z() = 1e-13;
  EXPECT_EQ(validate_mesh(thin).defect, MeshDefect::degenerate);
}

}  // namespace
}  // namespace impetus::test
