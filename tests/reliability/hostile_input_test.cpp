// Hostile and broken input: one row per input a program embedding Impetus may be handed, each with the
// fragment its error message must contain. Every row must end in an impetus::Error (never a crash,
// never another exception type, never silent acceptance). Scenes are read as "scene.yaml" in the
// bundled scene directory, so `../meshes/…` names the bundled meshes.
//
// Scenes cannot include other scenes (the format has no include key, and an unknown key is an error);
// the paths a scene names are mesh files and plugin directories, and those rows are here.

#include "impetus/assets/mesh_body.hpp"
#include "impetus/core/mass.hpp"
#include "reliability_support.hpp"

#include <unistd.h>

#include <cmath>
#include <limits>

namespace impetus::reliability {
namespace {

// A scene with a ground and one ball; `ball` replaces the ball's keys after its name, `top` is added at
// the top level.
std::string ball_scene(const std::string& ball = "shape: {sphere: {radius: 0.5}}\n    mass: 1",
                       const std::string& top = "") {
  return top + "bodies:\n  - name: ground\n    fixed: true\n    shape: {plane: {normal: [0, 0, 1], offset: 0}}\n"
               "  - name: ball\n    " + ball + "\n";
}

std::string load_text(const std::string& yaml) {
  return error_of([&] { load_scene_text(yaml, "scene.yaml", scenes_dir()); });
}

std::string load_file(const fs::path& file) {
  return error_of([&] { load_scene(file); });
}

std::string load_mesh(const fs::path& file) {
  return error_of([&] { assets::load_mesh_body(file); });
}

std::string build_text(const std::string& yaml) {
  return error_of([&] {
    const auto host = make_host();
    build_world(load_scene_text(yaml, "scene.yaml", scenes_dir()), *host);
  });
}

std::string add_body_with_rotation(const Mat3& rotation) {
  return error_of([&] {
    World world;
    RigidBody body;
    body.name = "spun";
    body.shape = Sphere{0.5};
    set_primitive_mass(body, 1.0);
    body.rotation = rotation;
    world.add_body(body);
  });
}

struct Row {
  std::string name;                    // gtest-safe: letters, digits, underscores
  std::function<std::string()> error;  // runs the input, returns the error message
  std::string expected;                // a fragment the message must contain
};

std::vector<Row> rows() {
  std::vector<Row> table;
  const auto scene = [&](std::string name, std::string yaml, std::string expected) {
    table.push_back({std::move(name), [yaml] { return load_text(yaml); }, std::move(expected)});
  };

  // NaN and infinity anywhere a number goes (YAML's .nan/.inf spellings, and overflow to inf).
  const std::pair<const char*, std::string> non_finite_places[] = {
      {"dt", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1", "dt: X\n")},
      {"gravity", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1", "gravity: [0, X, -9.81]\n")},
      {"position", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    position: [X, 0, 1]")},
      {"orientation", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    orientation: [1, 0, X, 0]")},
      {"velocity", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    velocity: [0, 0, X]")},
      {"angular_velocity", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    angular_velocity: [X, 0, 0]")},
      {"mass", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: X")},
      {"density", ball_scene("shape: {sphere: {radius: 0.5}}\n    density: X")},
      {"inertia", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    inertia: [1, X, 1]")},
      {"restitution", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    restitution: X")},
      {"friction", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    friction: X")},
      {"radius", ball_scene("shape: {sphere: {radius: X}}\n    mass: 1")},
      {"size", ball_scene("shape: {box: {size: [1, X, 1]}}\n    mass: 1")},
      {"length", ball_scene("shape: {capsule: {radius: 0.5, length: X}}\n    mass: 1")},
      {"offset", "bodies:\n  - {name: g, fixed: true, shape: {plane: {normal: [0, 0, 1], offset: X}}}\n"},
      {"normal", "bodies:\n  - {name: g, fixed: true, shape: {plane: {normal: [0, X, 1]}}}\n"},
      {"scale", ball_scene("shape: {mesh: {file: ../meshes/cube.obj, scale: X}}\n    mass: 1")},
      {"pyramid_radius", "generators:\n  - pyramid: {rows: 2, radius: X}\n"},
      {"line_velocity", "generators:\n  - line: {count: 2, velocity: [X, 0, 0]}\n"},
      {"point", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1") +
                    "constraints:\n  - point_point: {bodies: [ground, ball], point: [0, X, 0]}\n"},
      {"axis", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1") +
                   "constraints:\n  - coaxial: {bodies: [ground, ball], point: [0, 0, 0], axis: [X, 0, 1]}\n"},
  };
  const std::pair<const char*, const char*> spellings[] = {{"nan", ".nan"}, {"inf", ".inf"}, {"minus_inf", "-.Inf"},
                                                           {"overflow", "1e999"}};
  for (const auto& [place, yaml] : non_finite_places)
    for (const auto& [spelling, text] : spellings) {
      std::string s = yaml;
      s.replace(s.find('X'), 1, text);
      const bool overflow = std::string(spelling) == "overflow";
      scene(std::string("non_finite_") + place + "_" + spelling, s,
            overflow ? "is out of the range of a double" : "must be a finite number");
    }

  // Mass.
  scene("negative_mass", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: -1"), "'mass' must be positive, got -1");
  scene("zero_mass", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 0"), "'mass' must be positive, got 0");
  scene("negative_zero_mass", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: -0.0"), "'mass' must be positive");
  scene("zero_density", ball_scene("shape: {sphere: {radius: 0.5}}\n    density: 0"), "'density' must be positive");
  scene("no_mass", ball_scene("shape: {sphere: {radius: 0.5}}"), "needs 'mass' or 'density'");
  scene("negative_inertia", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    inertia: [1, -1, 1]"),
        "'inertia' must be positive definite");
  scene("impossible_inertia", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    inertia: [1, 1, 5]"),
        "break I1 + I2 >= I3");
  scene("volume_overflow", ball_scene("shape: {sphere: {radius: 1e200}}\n    density: 1"),
        "the shape has no finite, positive volume");
  scene("inertia_underflow", ball_scene("shape: {sphere: {radius: 1e-100}}\n    mass: 1e300"),
        "are not finite numbers");
  scene("generator_zero_mass", "generators:\n  - pyramid: {rows: 2, mass: 0}\n", "pyramid 'mass' must be a positive number");
  scene("generator_huge", "generators:\n  - pyramid: {rows: 100000}\n", "pyramid 'rows' must be between 1 and 1000");

  // Zero-size shapes.
  scene("zero_radius_sphere", ball_scene("shape: {sphere: {radius: 0}}\n    mass: 1"), "'radius' must be positive, got 0");
  scene("zero_edge_box", ball_scene("shape: {box: {size: [1, 0, 1]}}\n    mass: 1"),
        "'size' must have three positive edge lengths");
  scene("zero_radius_capsule", ball_scene("shape: {capsule: {radius: 0, length: 1}}\n    mass: 1"),
        "'radius' must be positive");
  scene("zero_length_cylinder", ball_scene("shape: {cylinder: {radius: 1, length: 0}}\n    mass: 1"),
        "'length' must be positive");
  scene("zero_mesh_scale", ball_scene("shape: {mesh: {file: ../meshes/cube.obj, scale: 0}}\n    mass: 1"),
        "'scale' must be positive");
  scene("flat_mesh", ball_scene("shape: {mesh: {file: ../meshes/broken/flat.obj}}\n    mass: 1"),
        "flat.obj: ");
  scene("zero_plane_normal", "bodies:\n  - {name: g, fixed: true, shape: {plane: {normal: [0, 0, 0]}}}\n",
        "'normal' must not be the zero vector");
  scene("zero_time_step", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1", "dt: 0\n"),
        "'dt' must be positive, got 0");

  // Orientations: a scene gives a quaternion (normalized on load, so only the zero one has no
  // direction); a body built in code gives a matrix, which must be a proper rotation.
  scene("zero_quaternion", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    orientation: [0, 0, 0, 0]"),
        "'orientation' is the zero quaternion");
  scene("short_quaternion", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    orientation: [1, 0, 0]"),
        "'orientation' expects a list of 4 numbers");
  table.push_back({"scaled_rotation_matrix", [] { return add_body_with_rotation(2.0 * Mat3::Identity()); },
                   "body 'spun': rotation is not a proper rotation matrix"});
  table.push_back({"sheared_rotation_matrix",
                   [] {
                     Mat3 m = Mat3::Identity();
                     m(0, 1) = 0.1;
                     return add_body_with_rotation(m);
                   },
                   "rotation is not a proper rotation matrix"});
  table.push_back({"mirror_rotation_matrix",
                   [] { return add_body_with_rotation(Vec3(1, 1, -1).asDiagonal()); },
                   "rotation is not a proper rotation matrix"});
  table.push_back({"nan_rotation_matrix",
                   [] { return add_body_with_rotation(Mat3::Constant(std::nan(""))); },
                   "must be finite"});

  // Names and references.
  scene("duplicate_body_name",
        ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1") +
            "  - name: ball\n    shape: {sphere: {radius: 0.5}}\n    mass: 1\n",
        "duplicate body name 'ball' (first at scene.yaml:");
  scene("generated_name_collides",
        "bodies:\n  - {name: line_0, shape: {sphere: {radius: 1}}, mass: 1}\ngenerators:\n  - line: {count: 2}\n",
        "duplicate body name 'line_0'");
  scene("constraint_missing_body",
        ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1") +
            "constraints:\n  - point_point: {bodies: [ball, ghost], point: [0, 0, 0]}\n",
        "no body named 'ghost'");
  scene("constraint_same_body",
        ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1") +
            "constraints:\n  - point_point: {bodies: [ball, ball], point: [0, 0, 0]}\n",
        "a constraint needs two different bodies");
  scene("unknown_key", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    positon: [0, 0, 1]"),
        "unknown key 'positon' in body 'ball'");
  scene("include_key", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1", "include: other.yaml\n"),
        "unknown key 'include' in scene");

  // Plugins.
  table.push_back({"unknown_plugin_option",
                   [] { return build_text(ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1",
                                                     "modules:\n  detector: {plugin: fcl, margn: 1.0e-4}\n")); },
                   "plugin 'fcl' (detector) has no option 'margn' (scene.yaml:2:"});
  table.push_back({"non_finite_plugin_option",
                   [] { return build_text(ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1",
                                                     "modules:\n  detector: {plugin: fcl, margin: .nan}\n")); },
                   "option 'margin' expects a finite number"});
  table.push_back({"unknown_plugin",
                   [] { return build_text(ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1",
                                                     "modules:\n  resolver: ledsa\n")); },
                   "no resolver plugin named 'ledsa'"});
  table.push_back({"missing_plugin_path",
                   [] { return build_text(ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1",
                                                     "plugin_path: [no_such_dir]\nmodules:\n  integrator: mine\n")); },
                   "no_such_dir (missing)"});

  // YAML itself.
  scene("not_yaml", "bodies: [\n  {name: a", "invalid YAML");
  scene("binary_garbage", std::string("\x00\xff\xfe{[\x01", 6), "scene.yaml");
  scene("deep_nesting", std::string(100000, '[') + std::string(100000, ']'), "scene.yaml");
  scene("not_a_mapping", "- a\n- b\n", "a scene is a mapping of keys");
  scene("repeated_key", ball_scene("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    mass: 2"),
        "key 'mass' appears twice");

  // Scene files.
  table.push_back({"scene_missing", [] { return load_file("/nonexistent/scene.yaml"); },
                   "cannot open the scene file"});
  table.push_back({"scene_is_a_directory", [] { return load_file(scenes_dir()); }, "is a directory"});
  table.push_back({"scene_empty",
                   [] {
                     Scratch dir("empty-scene");
                     return load_file(dir.write("empty.yaml", ""));
                   },
                   "the scene file is empty"});
  table.push_back({"scene_enormous",
                   [] {
                     Scratch dir("big-scene");
                     const fs::path file = dir.write("big.yaml", "");
                     fs::resize_file(file, std::uintmax_t{1} << 30);  // sparse: costs no disk
                     return load_file(file);
                   },
                   "larger than the limit"});

  // Mesh files (the paths a scene names).
  table.push_back({"mesh_missing", [] { return load_mesh(meshes_dir() / "no_such.obj"); }, "no such mesh file"});
  table.push_back({"mesh_is_a_directory", [] { return load_mesh(meshes_dir()); }, "is a directory"});
  table.push_back({"mesh_is_a_directory_in_scene",
                   [] { return load_text(ball_scene("shape: {mesh: {file: ../meshes}}\n    mass: 1")); },
                   "is a directory"});
  table.push_back({"mesh_empty", [] { return load_mesh(meshes_dir() / "broken" / "empty.obj"); },
                   "the mesh file is empty"});
  table.push_back({"mesh_truncated_stl", [] { return load_mesh(meshes_dir() / "broken" / "truncated.stl"); },
                   "truncated binary STL"});
  table.push_back({"mesh_truncated_obj",
                   [] {
                     Scratch dir("truncated-obj");
                     std::ifstream in(meshes_dir() / "cube.obj");
                     std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
                     return load_mesh(dir.write("cut.obj", text.substr(0, text.size() * 3 / 4)));
                   },
                   "the mesh is not closed"});
  table.push_back({"mesh_truncated_glb",
                   [] {
                     Scratch dir("truncated-glb");
                     std::ifstream in(meshes_dir() / "cube.glb", std::ios::binary);
                     std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
                     return load_mesh(dir.write("cut.glb", bytes.substr(0, bytes.size() / 2)));
                   },
                   "cut.glb: "});
  table.push_back({"mesh_enormous",
                   [] {
                     Scratch dir("big-mesh");
                     const fs::path file = dir.write("big.stl", "");
                     fs::resize_file(file, std::uintmax_t{1} << 32);  // sparse: costs no disk
                     return load_mesh(file);
                   },
                   "larger than the limit"});
  table.push_back({"mesh_not_a_mesh", [] { return load_mesh(scenes_dir() / "demo.yaml"); }, "demo.yaml: "});
  table.push_back({"mesh_symlink_loop",
                   [] {
                     Scratch dir("loop");
                     fs::create_symlink(dir.path() / "b.obj", dir.path() / "a.obj");
                     fs::create_symlink(dir.path() / "a.obj", dir.path() / "b.obj");
                     return load_mesh(dir.path() / "a.obj");
                   },
                   "a.obj: "});
  // Found by the fuzzers (fuzz/regressions): assimp's PLY reader ran past its buffer or looped on these, and a
  // self-intersecting mesh passed validation with an impossible inertia.
  table.push_back({"mesh_ply_without_end_header",
                   [] { return load_mesh(source_dir() / "fuzz/regressions/mesh_ply/segv-assimp-no-end-header.ply"); },
                   "malformed PLY header"});
  table.push_back({"mesh_ply_faces_without_vertices",
                   [] {
                     return load_mesh(source_dir() /
                                      "fuzz/regressions/mesh_ply/slow-assimp-faces-without-vertices.ply");
                   },
                   "malformed PLY header: 20 faces but no vertices"});
  table.push_back({"mesh_ply_truncated",
                   [] {
                     Scratch dir("truncated-ply");
                     std::ifstream in(meshes_dir() / "tetrahedron.ply", std::ios::binary);
                     std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
                     return load_mesh(dir.write("cut.ply", bytes.substr(0, bytes.size() - 60)));
                   },
                   "truncated binary PLY"});
  table.push_back({"mesh_self_intersecting",
                   [] { return load_mesh(source_dir() / "fuzz/regressions/mesh_off/self-intersecting-t-handle.off"); },
                   "the mesh probably intersects itself"});
  // Inputs that crash assimp 5.2 itself: the importer process takes the crash, the caller gets an error
  // naming the file and what became of the importer (assets/src/import_process.cpp).
  table.push_back({"mesh_ply_assimp_abort",
                   [] {
                     return load_mesh(source_dir() /
                                      "fuzz/regressions/mesh_ply/abort-assimp-triangulate-149-sided-faces.ply");
                   },
                   "abort-assimp-triangulate-149-sided-faces.ply: the mesh importer (assimp 5.2) crashed with "
                   "signal 6 (SIGABRT) while reading the file; the file is malformed"});
  table.push_back({"mesh_dae_assimp_segv",
                   [] { return load_mesh(source_dir() / "fuzz/regressions/mesh_dae/segv-assimp-null-dereference.dae"); },
                   "segv-assimp-null-dereference.dae: the mesh importer (assimp 5.2) crashed with signal 11 "
                   "(SIGSEGV) while reading the file; the file is malformed"});
  table.push_back({"mesh_glb_assimp_out_of_memory",
                   [] { return load_mesh(source_dir() / "fuzz/regressions/mesh_glb/oom-assimp-1500-mb-buffer.glb"); },
                   "oom-assimp-1500-mb-buffer.glb: the mesh importer (assimp 5.2) ran out of memory while reading "
                   "the file: it needed more than its limit of 1024 MiB"});
  table.push_back({"mesh_with_nan_vertex", [] { return load_mesh(meshes_dir() / "broken" / "nan_cube.obj"); },
                   "not a finite point"});
  table.push_back({"mesh_open", [] { return load_mesh(meshes_dir() / "broken" / "open_cube.obj"); },
                   "the mesh is not closed"});
  return table;
}

// gtest prints a parameter on failure: the row's name, not its bytes.
void PrintTo(const Row& row, std::ostream* out) { *out << row.name; }

class HostileInput : public testing::TestWithParam<Row> {};

TEST_P(HostileInput, IsRefusedWithItsOwnMessage) {
  const Row& row = GetParam();
  const std::string message = row.error();
  EXPECT_NE(message, "<no error>") << "accepted, but it must be refused";
  EXPECT_NE(message.find(row.expected), std::string::npos)
      << "message: " << message << "\nexpected it to contain: " << row.expected;
}

INSTANTIATE_TEST_SUITE_P(Table, HostileInput, testing::ValuesIn(rows()),
                         [](const testing::TestParamInfo<Row>& info) { return info.param.name; });

// Not an error: a quaternion far from unit length is normalized without overflow or underflow (its
// squared norm would be inf or 0 in double).
TEST(HostileInputLimits, ExtremeQuaternionsAreNormalizedWithoutOverflow) {
  for (const char* q : {"[1e300, 1e300, 0, 0]", "[1e-200, 1e-200, 0, 0]"}) {
    const Scene scene = load_scene_text(
        ball_scene(std::string("shape: {sphere: {radius: 0.5}}\n    mass: 1\n    orientation: ") + q), "scene.yaml",
        scenes_dir());
    // 90° about x: R maps y to z. Tolerance 1e-15 (rounding of the normalization).
    const Mat3& r = scene.bodies[1].rotation;
    EXPECT_NEAR((r * Vec3::UnitY() - Vec3::UnitZ()).norm(), 0.0, 1e-15) << q << "\n" << r;
  }
}

}  // namespace
}  // namespace impetus::reliability
