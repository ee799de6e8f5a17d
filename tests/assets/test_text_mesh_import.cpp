// The text formats (OBJ, ASCII STL, ASCII PLY, OFF) are read at double precision: a regular
// tetrahedron, an icosphere and a rotated box with irrational coordinates, written with %.17g, give the
// closed-form (or long-double) volume, center of mass and inertia to 1e-12, where assimp's float32
// vertices are off by about 1e-8 (measured here on the same files, so a return to assimp is caught).
// Malformed files are refused with the file, the line and the defect.
#include "asset_test_support.hpp"

#include "impetus/assets/mass_properties.hpp"
#include "impetus/assets/mesh_body.hpp"
#include "impetus/assets/mesh_import.hpp"
#include "impetus/assets/mesh_validation.hpp"
#include "impetus/core/error.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <string>
#include <cstdlib>
#include <unistd.h>
#include <vector>

namespace impetus::test {
namespace {

namespace fs = std::filesystem;
using assets::import_mesh;

constexpr double kTolerance = 1e-12;

// What a body's mass properties must be (density 1).
struct Expected {
  double volume;
  Vec3 center;
  Mat3 inertia;
  double size;  // a length scale for the center's error
};

struct Case {
  std::string name;
  TriangleMesh mesh;
  Expected expected;
};

// A regular tetrahedron of edge 2√2·s (s = 1/√3 · π/2) centered at an irrational point: volume a³/(6√2),
// inertia about the centroid isotropic, m a²/20.
Case tetrahedron() {
  const double s = std::numbers::pi / 2 / std::sqrt(3.0);
  const Vec3 c(std::sqrt(2.0), -std::sqrt(5.0), std::numbers::e);
  TriangleMesh m;
  for (const Vec3& v : {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)}) m.vertices.push_back(c + s * v);
  m.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  const double a = 2 * std::sqrt(2.0) * s, volume = a * a * a / (6 * std::sqrt(2.0));
  return {"tetrahedron", m, {volume, c, Mat3::Identity() * volume * a * a / 20, a}};
}

// A box of irrational edges rotated by 1 rad about the axis (1, 2, 3)/√14: volume abc, inertia
// R diag(m(b²+c²)/12, …) Rᵀ.
Case rotated_box() {
  const Vec3 edges(std::sqrt(2.0), std::sqrt(3.0), std::numbers::pi / 3);
  const Vec3 c(std::numbers::e, -std::sqrt(7.0), 0.1);
  const Mat3 r = Eigen::AngleAxisd(1.0, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const TriangleMesh m = transformed(box_mesh(-edges / 2, edges / 2), r, c);
  const double volume = edges.prod();
  const Vec3 e2 = edges.cwiseProduct(edges);
  const Vec3 moments = volume / 12 * Vec3(e2.y() + e2.z(), e2.x() + e2.z(), e2.x() + e2.y());
  return {"rotated_box", m, {volume, c, r * moments.asDiagonal() * r.transpose(), edges.norm()}};
}

// An icosahedron subdivided twice, projected on a sphere of radius √3 around an irrational center.
// The reference is the exact signed-tetrahedra sum over the same (double) vertices in long double.
Case icosphere() {
  const double t = (1 + std::sqrt(5.0)) / 2, radius = std::sqrt(3.0);
  const Vec3 c(-std::numbers::pi, std::sqrt(11.0) / 7, 1 / std::sqrt(13.0));
  std::vector<Vec3> unit = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& v : unit) v.normalize();
  std::vector<std::array<std::uint32_t, 3>> faces = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
      {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},   {4, 9, 5}, {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < 2; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middle;
    const auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto [it, added] = middle.emplace(key, static_cast<std::uint32_t>(unit.size()));
      if (added) unit.push_back((unit[a] + unit[b]).normalized());
      return it->second;
    };
    std::vector<std::array<std::uint32_t, 3>> finer;
    for (const auto& [a, b, d] : faces) {
      const std::uint32_t ab = mid(a, b), bd = mid(b, d), da = mid(d, a);
      finer.insert(finer.end(), {{a, ab, da}, {b, bd, ab}, {d, da, bd}, {ab, bd, da}});
    }
    faces = std::move(finer);
  }
  TriangleMesh m;
  for (const Vec3& v : unit) m.vertices.push_back(c + radius * v);
  m.triangles = faces;

  using Vec3l = Eigen::Matrix<long double, 3, 1>;
  using Mat3l = Eigen::Matrix<long double, 3, 3>;
  long double volume = 0;
  Vec3l first = Vec3l::Zero();
  Mat3l second = Mat3l::Zero();
  const Vec3l o = c.cast<long double>();
  for (const auto& tri : m.triangles) {
    const Vec3l a = m.vertices[tri[0]].cast<long double>() - o, b = m.vertices[tri[1]].cast<long double>() - o,
                d = m.vertices[tri[2]].cast<long double>() - o;
    const long double v = a.dot(b.cross(d)) / 6;
    const Vec3l sum = a + b + d;  // the fourth vertex is the origin
    volume += v;
    first += v * sum / 4;
    second += v / 20 * (a * a.transpose() + b * b.transpose() + d * d.transpose() + sum * sum.transpose());
  }
  const Vec3l com = first / volume;
  const Mat3l covariance = second - volume * com * com.transpose();
  const Mat3l inertia = covariance.trace() * Mat3l::Identity() - covariance;
  return {"icosphere", m, {static_cast<double>(volume), (com + o).cast<double>(), inertia.cast<double>(), radius}};
}

std::string g17(double x) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

std::string xyz(const Vec3& v) { return g17(v.x()) + " " + g17(v.y()) + " " + g17(v.z()); }

std::string write_obj(const TriangleMesh& m, const std::string& name) {
  std::string s = "# " + name + "\no " + name + "\n";
  for (const Vec3& v : m.vertices) s += "v " + xyz(v) + "\n";
  for (const auto& t : m.triangles)
    s += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  return s;
}

std::string write_stl(const TriangleMesh& m, const std::string& name) {
  std::string s = "solid " + name + "\n";
  for (const auto& t : m.triangles) {
    const Vec3 n = (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).normalized();
    s += "  facet normal " + xyz(n) + "\n    outer loop\n";
    for (std::uint32_t i : t) s += "      vertex " + xyz(m.vertices[i]) + "\n";
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid " + name + "\n";
}

std::string write_ply(const TriangleMesh& m, const std::string&) {
  std::string s = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(m.vertices.size()) +
                  "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
                  std::to_string(m.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& v : m.vertices) s += xyz(v) + "\n";
  for (const auto& t : m.triangles)
    s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  return s;
}

std::string write_off(const TriangleMesh& m, const std::string& name) {
  std::string s = "OFF\n# " + name + "\n" + std::to_string(m.vertices.size()) + " " + std::to_string(m.triangles.size()) + " 0\n";
  for (const Vec3& v : m.vertices) s += xyz(v) + "\n";
  for (const auto& t : m.triangles)
    s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  return s;
}

struct Format {
  std::string suffix;
  std::function<std::string(const TriangleMesh&, const std::string&)> write;
};

const std::vector<Format> kFormats = {
    {".obj", write_obj}, {"_ascii.stl", write_stl}, {"_ascii.ply", write_ply}, {".off", write_off}};

// A fresh directory for this test's files, removed at the end.
class TempDir {
 public:
  TempDir() : path_(fs::temp_directory_path() / ("impetus_text_mesh_" + std::to_string(::getpid()))) {
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    std::ofstream(file, std::ios::binary) << text;
    return file.string();
  }

 private:
  fs::path path_;
};

struct Errors {
  double volume, center, inertia;
  double worst() const { return std::max({volume, center, inertia}); }
};

Errors errors_of(const assets::MassProperties& got, const Expected& expected) {
  return {relative_error(got.volume, expected.volume), (got.center_of_mass - expected.center).norm() / expected.size,
          relative_error(got.inertia, expected.inertia)};
}

// The file as assimp reads it (float32 vertices), welded, through the same mass properties.
assets::MassProperties through_assimp(const std::string& file) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file, aiProcess_Triangulate);
  EXPECT_NE(scene, nullptr) << file << ": " << importer.GetErrorString();
  TriangleMesh m;
  if (!scene) return {};
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    const aiMesh& mesh = *scene->mMeshes[i];
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    for (unsigned v = 0; v < mesh.mNumVertices; ++v)
      m.vertices.emplace_back(mesh.mVertices[v].x, mesh.mVertices[v].y, mesh.mVertices[v].z);
    for (unsigned f = 0; f < mesh.mNumFaces; ++f)
      m.triangles.push_back({base + mesh.mFaces[f].mIndices[0], base + mesh.mFaces[f].mIndices[1],
                             base + mesh.mFaces[f].mIndices[2]});
  }
  assets::weld_identical_vertices(m);
  return assets::polyhedral_mass_properties(m);
}

TEST(TextMeshImport, IrrationalCoordinatesGiveTheClosedFormsInEveryTextFormat) {
  const TempDir dir;
  for (const Case& c : {tetrahedron(), icosphere(), rotated_box()}) {
    for (const Format& format : kFormats) {
      const std::string file = dir.write(c.name + format.suffix, format.write(c.mesh, c.name));
      SCOPED_TRACE(file);
      const assets::MeshBody body = assets::load_mesh_body(file);
      EXPECT_TRUE(body.warnings.empty());
      EXPECT_NE(body.format.find("double precision"), std::string::npos) << body.format;
      const Errors ours = errors_of(body.unit, c.expected);
      // load_mesh_body moves the frame to the center of mass; its position in the file is kept apart.
      const Errors ours_com{ours.volume, (body.center_of_mass_file - c.expected.center).norm() / c.expected.size,
                            ours.inertia};
      const Errors theirs = errors_of(through_assimp(file), c.expected);
      std::printf("[ precision ] %-28s volume %.1e / %.1e, center %.1e / %.1e, inertia %.1e / %.1e (ours / assimp)\n",
                  (c.name + format.suffix).c_str(), ours_com.volume, theirs.volume, ours_com.center, theirs.center,
                  ours_com.inertia, theirs.inertia);
      EXPECT_LT(ours_com.volume, kTolerance);
      EXPECT_LT(ours_com.center, kTolerance);
      EXPECT_LT(ours_com.inertia, kTolerance);
      // The loss this reader exists to avoid is real: assimp's float32 vertices are far off the 1e-12.
      EXPECT_GT(theirs.worst(), 1e-10);
    }
  }
}

// The isolated importer and the in-process path give the same double vertices, bit for bit, and
// each format gives the same welded mesh.
TEST(TextMeshImport, EveryTextFormatGivesTheSameVerticesInAndOutOfProcess) {
  const TempDir dir;
  const Case c = icosphere();
  for (const Format& format : kFormats) {
    const std::string file = dir.write(c.name + format.suffix, format.write(c.mesh, c.name));
    SCOPED_TRACE(file);
    const assets::ImportedMesh isolated = import_mesh(file);
    ::setenv("IMPETUS_MESH_IMPORT", "in-process", 1);
    const assets::ImportedMesh local = import_mesh(file);
    ::unsetenv("IMPETUS_MESH_IMPORT");
    ASSERT_EQ(isolated.parts.size(), 1u);
    ASSERT_EQ(local.parts.size(), 1u);
    EXPECT_EQ(isolated.parts[0].mesh.vertices.size(), c.mesh.vertices.size());
    EXPECT_EQ(isolated.parts[0].mesh.triangles.size(), c.mesh.triangles.size());
    EXPECT_EQ(isolated.parts[0].mesh.vertices, local.parts[0].mesh.vertices);
    EXPECT_EQ(isolated.parts[0].mesh.triangles, local.parts[0].mesh.triangles);
    // %.17g round-trips: every vertex is the one written, exactly.
    for (const Vec3& v : isolated.parts[0].mesh.vertices)
      EXPECT_NE(std::find(c.mesh.vertices.begin(), c.mesh.vertices.end(), v), c.mesh.vertices.end());
  }
}

// Parts: OBJ objects and groups, STL solids; scale; polygons; points and lines dropped with a warning.
TEST(TextMeshImport, PartsScalePolygonsAndDroppedElements) {
  const TempDir dir;
  const std::string two = dir.write("two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                               "v 3 0 0\nv 4 0 0\nv 3 1 0\nv 3 0 1\n"
                                               "o first\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
                                               "g second\nf -4 -2 -3\nf -4 -3 -1\nf -4 -1 -2\nf -3 -2 -1\nl 1 2 3\n");
  const assets::ImportedMesh separate = import_mesh(two, {0.5, assets::PartMode::separate, assets::UnitMode::convert});
  ASSERT_EQ(separate.parts.size(), 2u);
  EXPECT_EQ(separate.parts[0].name, "first");
  EXPECT_EQ(separate.parts[1].name, "second");
  EXPECT_DOUBLE_EQ(assets::signed_volume(separate.parts[1].mesh), 0.125 / 6);
  EXPECT_EQ(separate.warnings, std::vector<std::string>{two + ": dropped 2 points and lines (a solid is made of triangles only)"});
  const assets::ImportedMesh merged = import_mesh(two);
  ASSERT_EQ(merged.parts.size(), 1u);
  EXPECT_EQ(merged.parts[0].name, "two");
  EXPECT_EQ(merged.parts[0].mesh.vertices.size(), 8u);

  // A quad-faced cube: each quad a fan of two triangles.
  const std::string quads = dir.write("quads.off", "OFF\n8 6 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
                                                   "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n");
  const assets::MeshBody cube = assets::load_mesh_body(quads);
  EXPECT_DOUBLE_EQ(cube.unit.volume, 1.0);

  // An L-shaped prism whose caps are non-convex hexagons: ear-clipped, so the triangles cover the caps
  // exactly (a fan from the first corner would also cover the notch, counted twice over).
  const std::string l_prism =
      dir.write("l_prism.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n"
                               "v 0 0 1\nv 2 0 1\nv 2 1 1\nv 1 1 1\nv 1 2 1\nv 0 2 1\n"
                               "f 6 5 4 3 2 1\nf 7 8 9 10 11 12\n"
                               "f 1 2 8 7\nf 2 3 9 8\nf 3 4 10 9\nf 4 5 11 10\nf 5 6 12 11\nf 6 1 7 12\n");
  const assets::MeshBody l_body = assets::load_mesh_body(l_prism);
  EXPECT_DOUBLE_EQ(l_body.unit.volume, 3.0);
  double area = 0.0;
  for (const auto& t : l_body.mesh->triangles)
    area += (l_body.mesh->vertices[t[1]] - l_body.mesh->vertices[t[0]])
                .cross(l_body.mesh->vertices[t[2]] - l_body.mesh->vertices[t[0]])
                .norm() / 2;
  EXPECT_DOUBLE_EQ(area, 2 * 3.0 + 8 * 1.0);

  const std::string solids = dir.write("solids_ascii.stl", write_stl(box_mesh(Vec3(0, 0, 0), Vec3(1, 1, 1)), "a") +
                                                               write_stl(box_mesh(Vec3(2, 0, 0), Vec3(3, 2, 1)), "b"));
  const assets::ImportedMesh stl = import_mesh(solids, {1.0, assets::PartMode::separate, assets::UnitMode::convert});
  ASSERT_EQ(stl.parts.size(), 2u);
  EXPECT_EQ(stl.parts[1].name, "b");
  EXPECT_DOUBLE_EQ(assets::signed_volume(stl.parts[1].mesh), 2.0);

  // Capitals after the first "solid" (which must be lower case to tell ASCII from binary STL, as in
  // assimp), as some older exporters write them; a '+' sign.
  std::string upper = write_stl(box_mesh(Vec3(0, 0, 0), Vec3(1, 2, 3)), "C");
  for (char& ch : upper) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  upper.replace(0, 5, "solid");
  const std::string capitals = dir.write("capitals_ascii.stl", upper);
  EXPECT_DOUBLE_EQ(assets::load_mesh_body(capitals).unit.volume, 6.0);
  const std::string plus = dir.write("plus.obj", "v +0 0 0\nv +1 0 0\nv 0 +1.0 0\nv 0 0 +1e0\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  EXPECT_DOUBLE_EQ(assets::load_mesh_body(plus).unit.volume, 1.0 / 6);
}

// Each defect: the file, the format, the line and what is wrong, in the calling process's error.
TEST(TextMeshImport, MalformedFilesNameTheLineAndTheDefect) {
  const TempDir dir;
  const std::string tetra_off = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      // OFF: truncated, wrong counts, huge counts, bad numbers, bad indices, extra data.
      {"truncated.off", tetra_off.substr(0, tetra_off.size() - 16)},
      {"short_counts.off", "OFF\n4 4\n"},
      {"huge.off", "OFF\n4000000000 1 0\n0 0 0\n"},
      {"negative.off", "OFF\n-4 4 0\n"},
      {"word.off", "OFF\n4 4 0\n0 0 0\n1 zero 0\n"},
      {"huge_ascii_element.ply", "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n0\n"},
      {"range.off", "OFF\n1 0 0\n1e999 0 0\n"},
      {"index.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 4\n"},
      {"extra.off", tetra_off + "3 0 1 2\n"},
      // OBJ
      {"index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"},
      {"zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"},
      {"short.obj", "v 0 0\n"},
      {"number.obj", "v 0 0 0x1\n"},
      {"sign.obj", "v +1 +.5 +-1\n"},
      {"first_bad.obj", "v 0 x y\n"},
      {"bytes.obj", std::string("v 0 0 0\n\x1b[2J\xff\0 1 2\n", 19)},
      {"unknown.obj", "v 0 0 0\nvertex 1 2 3\n"},
      {"surface.obj", "cstype bspline\n"},
      // ASCII STL
      {"truncated_ascii.stl", "solid t\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n"},
      {"four_ascii.stl",
       "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex 1 1 0\n"},
      {"nan_normal_is_fine_but_word_is_not_ascii.stl",
       "solid t\nfacet normal nan 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 x\n"},
      // ASCII PLY
      {"truncated_ascii.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n"},
      {"values_ascii.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0\n"},
      {"huge_ascii.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3000000000 0 0 0\n"},
  };
  const std::map<std::string, std::string> expected = {
      {"truncated.off", "malformed OFF: line 8: the file ends before face 2 of 4"},
      {"short_counts.off", "malformed OFF: line 2: expected the vertex, face and edge counts"},
      // These four the checks in the calling process (mesh_file_checks.cpp) refuse before any reader runs.
      {"huge.off", "malformed OFF: it announces 4e+09 vertices and 1 faces, more than its 25 bytes can hold"},
      {"negative.off", "malformed OFF: no vertex and face counts"},
      {"word.off", "malformed OFF: line 2 of its data holds a character that is not part of a number"},
      {"huge_ascii_element.ply", "malformed PLY header: element 'vertex' announces more items than the file has bytes"},
      {"range.off", "malformed OFF: line 3: coordinate '1e999' is out of the range of a double"},
      {"index.off", "malformed OFF: line 7: vertex index 4 does not name one of the 4 vertices"},
      {"extra.off", "malformed OFF: line 11: more data than its counts announce"},
      {"index.obj", "malformed OBJ: line 4: vertex index 4 does not name one of the 3 vertices defined before it"},
      {"zero.obj", "malformed OBJ: line 4: vertex index 0 does not name one of the 3 vertices defined before it"},
      {"short.obj", "malformed OBJ: line 1: a vertex needs three coordinates"},
      {"number.obj", "malformed OBJ: line 1: coordinate '0x1' is not a number"},
      {"sign.obj", "malformed OBJ: line 1: coordinate '+-1' is not a number"},
      {"first_bad.obj", "malformed OBJ: line 1: coordinate 'x' is not a number"},
      {"bytes.obj", "malformed OBJ: line 2: unknown statement '\\x1B[2J\\xFF\\x00'"},
      {"unknown.obj", "malformed OBJ: line 2: unknown statement 'vertex'"},
      {"surface.obj",
       "malformed OBJ: line 1: free-form geometry ('cstype') is not supported: export the mesh as polygons"},
      {"truncated_ascii.stl", "malformed ASCII STL: line 4: the file ends inside a solid (no 'endsolid')"},
      {"four_ascii.stl", "malformed ASCII STL: line 7: a facet has more than three vertices"},
      {"nan_normal_is_fine_but_word_is_not_ascii.stl", "malformed ASCII STL: line 5: coordinate 'x' is not a number"},
      {"truncated_ascii.ply", "malformed PLY: line 9: the file ends in element 'vertex' #2 of 3"},
      {"values_ascii.ply", "malformed PLY: line 8: element 'vertex' #0 has too few values"},
      {"huge_ascii.ply", "malformed PLY: line 11: list length 3000000000 is more than the file's 177 bytes can hold"},
  };
  for (const auto& [name, text] : cases) {
    const std::string file = dir.write(name, text);
    EXPECT_EQ(error_of([&] { import_mesh(file); }), file + ": " + expected.at(name));
  }
}

// Ear clipping is bounded: a non-convex face of more than 1,024 corners, or non-convex faces that take
// more than 2e8 point-in-triangle tests in all (here 400 star-shaped 1,024-gons), are refused.
TEST(TextMeshImport, NonConvexFacesAreBoundedByWork) {
  const TempDir dir;
  const auto star = [](int n, int faces) {
    std::string s;
    for (int i = 0; i < n; ++i) {
      const double r = i % 2 ? 0.5 : 1.0, a = 2 * std::numbers::pi * i / n;
      s += "v " + g17(r * std::cos(a)) + " " + g17(r * std::sin(a)) + " 0\n";
    }
    std::string face = "f";
    for (int i = 1; i <= n; ++i) face += " " + std::to_string(i);
    for (int k = 0; k < faces; ++k) s += face + "\n";
    return s;
  };
  const std::string big = dir.write("big.obj", star(1025, 1));
  EXPECT_EQ(error_of([&] { import_mesh(big); }),
            big + ": malformed OBJ: line 1026: a non-convex face of 1025 vertices (more than 1024): triangulate it when "
                  "exporting");
  const std::string many = dir.write("many.obj", star(1024, 400));
  const std::string message = error_of([&] { import_mesh(many); });
  EXPECT_EQ(message.rfind(many + ": malformed OBJ: line ", 0), 0u) << message;
  EXPECT_NE(message.find(": its non-convex faces take more than 200000000 steps to triangulate: triangulate them "
                         "when exporting"),
            std::string::npos)
      << message;
}

// A NaN coordinate in an OBJ or ASCII STL is read as NaN, as before: validation refuses it naming the
// vertex. (In OFF and ASCII PLY the checks in the calling process refuse any letter first.)
TEST(TextMeshImport, NonFiniteCoordinatesReachValidation) {
  const TempDir dir;
  const std::string file = dir.write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  const std::string message = error_of([&] { assets::load_mesh_body(file); });
  EXPECT_EQ(message.rfind(file + ": a vertex is not a finite point (NaN or infinite): (", 0), 0u) << message;
}

}  // namespace
}  // namespace impetus::test
