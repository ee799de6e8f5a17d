// The second hostile-input sweep (README.md, "Reliability"), the classes found in the library: YAML
// that expands beyond any scene, numbers that lose digits on their way through text, counts that
// overflow or cost quadratic time, paths that are not regular files, names that break CSV rows and
// messages, finite values whose products overflow, and errors raised far from where the fault is
// visible. Each row is refused with a message naming the file and line (or the option) and the problem,
// never a crash, a hang or an exception of another type. The command-line rows (outputs, flags) are in
// tests/cli/test_cli.cpp.

#include "impetus/core/format.hpp"
#include "impetus/core/mass.hpp"
#include "reliability_support.hpp"

#include <sys/stat.h>

#include <cmath>
#include <string>

namespace impetus::reliability {
namespace {

std::string load_text(const std::string& yaml, const std::vector<SceneOverride>& overrides = {}) {
  return error_of([&] { load_scene_text(yaml, "scene.yaml", scenes_dir(), overrides); });
}

std::string build_text(const std::string& yaml) {
  return error_of([&] {
    const auto host = make_host();
    build_world(load_scene_text(yaml, "scene.yaml", scenes_dir()), *host);
  });
}

const std::string kBall =
    "bodies:\n"
    "  - {name: ground, fixed: true, shape: {plane: {normal: [0, 0, 1]}}}\n"
    "  - name: ball\n"
    "    shape: {sphere: {radius: 0.5}}\n"
    "    mass: 1\n";

// Nine aliases of the previous list, `levels` times: 9^levels scalars from a few hundred bytes.
std::string alias_bomb(int levels) {
  std::string text = "[&l0 [1, 1, 1, 1, 1, 1, 1, 1, 1]";
  for (int i = 1; i < levels; ++i) {
    const std::string prev = "*l" + std::to_string(i - 1);
    text += ", &l" + std::to_string(i) + " [" + prev;
    for (int k = 1; k < 9; ++k) text += ", " + prev;
    text += "]";
  }
  return text + "]";
}

struct Row {
  std::string name;
  std::function<std::string()> error;
  std::string expected;  // a fragment the message must contain
};

void PrintTo(const Row& row, std::ostream* out) { *out << row.name; }

std::vector<Row> rows() {
  std::vector<Row> t;
  const auto scene = [&](std::string name, std::string yaml, std::string expected) {
    t.push_back({std::move(name), [yaml] { return load_text(yaml); }, std::move(expected)});
  };
  const auto set = [&](std::string name, std::string key, std::string value, std::string expected) {
    t.push_back({std::move(name), [key, value] { return load_text(kBall, {{key, value}}); }, std::move(expected)});
  };

  // YAML expansion: bounded in nodes and depth with aliases counted as written out; cycles and second
  // documents refused.
  set("alias_bomb_in_set", "gravity", alias_bomb(8),
      "--set gravity:1:");  // located in the value
  set("alias_bomb_message", "bodies", alias_bomb(8), "expands to more than 1000000 nodes");
  set("self_alias_in_set", "dt", "&a [*a]", "an alias refers to the node that contains it (a cycle)");
  scene("self_alias_in_file", "dt: &a [1, *a]\n", "scene.yaml:1:12: an alias refers to the node that contains it");
  scene("alias_bomb_in_file", "junk: " + alias_bomb(8) + "\n", "scene.yaml:1:");
  scene("deep_nesting", "dt: " + std::string(100, '[') + std::string(100, ']') + "\n",
        "nests more than 64 levels deep");
  scene("very_deep_nesting", "dt: " + std::string(100000, '[') + "\n", "nests more than 64 levels deep");
  scene("deep_through_aliases",
        [] {
          std::string text = "a: &d0 [1]\n";
          for (int i = 1; i <= 70; ++i)
            text += "a" + std::to_string(i) + ": &d" + std::to_string(i) + " [*d" + std::to_string(i - 1) + "]\n";
          return text;
        }(),
        "nests more than 64 levels deep (counting every alias as written out)");
  scene("second_document", kBall + "---\ndt: 0.5\n", "scene.yaml:6:1: a second YAML document");
  set("second_document_in_set", "dt", "0.1\n---\n0.2", "a second YAML document");
  scene("long_flow_list", "junk: [" + [] {
    std::string s;
    for (int i = 0; i < 1'000'001; ++i) s += "1,";
    return s;
  }() + "1]\n",
        "expands to more than 1000000 nodes");

  // Non-regular files as the scene.
  t.push_back({"scene_is_a_device", [] { return error_of([] { load_scene("/dev/zero"); }); },
               "/dev/zero: is not a regular file (a character device)"});

  // Names that would break a CSV row or cut a message short.
  scene("name_with_newline", kBall + "  - {name: \"a\\nb\", shape: {sphere: {radius: 0.5}}, mass: 1}\n",
        "scene.yaml:6:12: 'name' holds a control character");
  scene("name_with_nul", kBall + "  - {name: \"a\\0b\", shape: {sphere: {radius: 0.5}}, mass: 1}\n",
        "'name' holds a control character");

  // Finite values whose products are not.
  scene("velocity_overflows_energy", kBall + "    velocity: [1e200, 0, 0]\n",
        "scene.yaml:6:15: 'velocity' with mass 1 overflows the kinetic energy");
  scene("angular_velocity_overflows_energy", kBall + "    angular_velocity: [0, 1e200, 0]\n",
        "'angular_velocity' overflows the kinetic energy");
  scene("position_overflows_moments",
        "bodies:\n  - {name: b, shape: {sphere: {radius: 0.5}}, mass: 1e10, position: [1e300, 0, 0]}\n",
        "'position' with mass 1e+10 overflows the moments");
  scene("generator_radius_overflows_inertia", "generators:\n  - line: {count: 3, radius: 1e200}\n",
        "scene.yaml:2:30: line 'radius' 1e+200 with 'mass' 1 overflows");
  scene("generator_velocity_overflows_energy", "generators:\n  - line: {count: 3, velocity: [1e200, 0, 0]}\n",
        "line 'velocity' overflows the kinetic energy");
  scene("coaxial_length_overflows_rows",
        kBall + "constraints:\n  - coaxial: {bodies: [ground, ball], point: [0, 0, 0], axis: [0, 0, 1], length: 1e300}\n",
        "scene.yaml:7:82: 'length' 1e+300 overflows the constraint's rows");

  // Numbers keep their digits in messages: shortest round-trip form, not six decimals.
  scene("message_keeps_digits", kBall + "    restitution: 1.0000001\n", "got 1.0000001");

  // Errors found when the world is built name where the scene wrote the fault.
  t.push_back({"constraint_refused_by_resolver_is_located",
               [] {
                 return build_text("modules: {resolver: mirtich}\n" + kBall +
                                   "constraints:\n  - point_point: {bodies: [ground, ball], point: [0, 0, 0]}\n");
               },
               "scene.yaml:8:5: resolver 'mirtich' refuses this constraint"});
  t.push_back({"friction_refused_by_resolver_is_located",
               [] {
                 return build_text("modules: {resolver: {plugin: ledas, mode: paper}}\n" + kBall +
                                   "    friction: 0.5\n");
               },
               "scene.yaml:4:11: body 'ball' has friction 0.5, but resolver 'ledas': ledas in paper mode"});
  return t;
}

class HostileInputRound2 : public testing::TestWithParam<Row> {};

TEST_P(HostileInputRound2, IsRefusedWithItsOwnMessage) {
  const Row& row = GetParam();
  const std::string message = row.error();
  EXPECT_NE(message, "<no error>") << "accepted, but it must be refused";
  EXPECT_NE(message.find(row.expected), std::string::npos)
      << "message: " << message << "\nexpected it to contain: " << row.expected;
}

INSTANTIATE_TEST_SUITE_P(Table, HostileInputRound2, testing::ValuesIn(rows()),
                         [](const testing::TestParamInfo<Row>& info) { return info.param.name; });

// A FIFO as the scene or as a plugin's `path:` is refused at once (reading or dlopen-ing it would wait
// for a writer forever); a directory named like a plugin library is listed as a failure, not skipped.
TEST(HostileInputRound2Files, FifosAndDirectoriesAreRefusedWithoutBlocking) {
  const Scratch dir("fifo");
  const fs::path fifo = dir.path() / "scene.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(error_of([&] { load_scene(fifo); }).find("scene.yaml: is not a regular file (a FIFO)"), std::string::npos);

  const fs::path library = dir.path() / "impetus_resolver_fake.so";
  ASSERT_EQ(::mkfifo(library.c_str(), 0600), 0);
  const std::string message = error_of([&] {
    const auto host = make_host();
    Scene scene = load_scene_text(kBall + "modules: {resolver: {plugin: fake, path: " + library.string() + "}}\n",
                                  "scene.yaml", dir.path());
    build_world(scene, *host);
  });
  EXPECT_NE(message.find("is not a regular file (a device, FIFO or socket), not a shared library"), std::string::npos)
      << message;

  const fs::path plugins = dir.path() / "plugins";
  fs::create_directories(plugins / "impetus_resolver_folder.so");
  PluginHost host;
  host.prepend_directories({plugins});
  const PluginListing listing = host.discover();
  ASSERT_EQ(listing.failures.size(), 1u);
  EXPECT_NE(listing.failures[0].reason.find("is a directory, not a shared library"), std::string::npos)
      << listing.failures[0].reason;
}

// Numbers through text: the shortest round-trip form reads back bit for bit, so a flag passed on as a
// scene override keeps every digit (1e-7 was "0.000000" through six decimals, refused as 0).
TEST(HostileInputRound2Numbers, FormattedNumbersReadBackExactly) {
  for (double x : {1e-7, 0.0001234567, 1.0 / 3.0, 1e308, 5e-324, -2.5}) {
    const Scene scene = load_scene_text(kBall, "scene.yaml", scenes_dir(), {{"dt", format_number(std::abs(x))}});
    EXPECT_EQ(scene.settings.dt, std::abs(x)) << format_number(x);
  }
  EXPECT_EQ(format_number(1e-7), "1e-07");
  EXPECT_EQ(format_number(1e308), "1e+308");  // not 309 digits
}

// Directions are normalized after dividing by the largest component: [0, 1e200, 1e200] is 45° between
// y and z, not the zero vector (its squared norm overflows). Tolerance 1e-15 (rounding).
TEST(HostileInputRound2Numbers, HugeAndTinyDirectionsKeepTheirDirection) {
  const Scene plane = load_scene_text("bodies:\n  - {name: g, fixed: true, shape: {plane: {normal: [0, 1e200, 1e200]}}}\n",
                                      "scene.yaml", scenes_dir());
  const Vec3 n = std::get<Plane>(plane.bodies[0].shape).normal;
  EXPECT_NEAR((n - Vec3(0, 1, 1) / std::sqrt(2.0)).norm(), 0.0, 1e-15) << n.transpose();
  for (const char* axis : {"[0, 0, 1e300]", "[0, 0, 1e-300]"}) {
    const Scene scene = load_scene_text(
        kBall + "constraints:\n  - coaxial: {bodies: [ground, ball], point: [0, 0, 0], axis: " + axis + "}\n",
        "scene.yaml", scenes_dir());
    const auto& c = std::get<CoaxialConstraint>(scene.constraints[0]);
    EXPECT_NEAR((c.axis_b - Vec3::UnitZ()).norm(), 0.0, 1e-15) << axis;
  }
}

// Many bodies at once are checked against each other and the world with a hash set, all or nothing.
TEST(HostileInputRound2Counts, AddBodiesChecksNamesAndAddsAllOrNothing) {
  const auto ball = [](std::string name) {
    RigidBody b;
    b.name = std::move(name);
    b.shape = Sphere{0.5};
    set_primitive_mass(b, 1.0);
    return b;
  };
  World world;
  world.add_body(ball("first"));
  std::vector<RigidBody> batch;
  for (int i = 0; i < 1000; ++i) batch.push_back(ball("b" + std::to_string(i)));
  batch.push_back(ball("first"));
  EXPECT_NE(error_of([&] { world.add_bodies(batch); }).find("body 'first': a body with this name already exists"),
            std::string::npos);
  EXPECT_EQ(world.bodies().size(), 1u);  // none of the batch was added
  batch.pop_back();
  EXPECT_EQ(world.add_bodies(batch), 1u);
  ASSERT_EQ(world.bodies().size(), 1001u);
  EXPECT_EQ(world.bodies()[1000].name, "b999");
  EXPECT_NE(error_of([&] { world.add_body(ball("a\nb")); }).find("its name holds a control character"),
            std::string::npos);
}

// A scene's bodies, written and generated, are bounded together (SceneLimits::bodies): each generator is
// bounded alone, but a few lines of generators could otherwise ask for any number of them. The one that
// crosses the limit is refused at its line before it makes a body.
TEST(HostileInputRound2Counts, SceneBodiesAreBoundedTogether) {
  const std::string lines =
      "generators:\n"
      "  - line: {count: 6, radius: 0.1}\n"
      "  - pyramid: {rows: 3, radius: 0.1, ground: false}\n";
  const SceneLimits ten{.bodies = 10};
  // 6 spheres and a wall, then 6 more: 13 > 10, refused at the pyramid's rows.
  const std::string error =
      error_of([&] { load_scene_text(lines, "scene.yaml", scenes_dir(), {}, ten); });
  EXPECT_NE(error.find("scene.yaml:3:21: this pyramid makes 6 bodies, and with the 7 before it the scene would hold "
                       "more than 10 bodies (the limit)"),
            std::string::npos)
      << error;
  // Exactly at the limit loads.
  EXPECT_EQ(load_scene_text(lines, "scene.yaml", scenes_dir(), {{"generators.1.pyramid.rows", "2"}}, ten).bodies.size(),
            10u);
  // Written bodies count too, at the entry past the limit.
  std::string written = "bodies:\n";
  for (int i = 0; i < 3; ++i)
    written += "  - {name: b" + std::to_string(i) + ", shape: {sphere: {radius: 0.5}}, mass: 1, position: [" +
               std::to_string(2 * i) + ", 0, 0]}\n";
  EXPECT_NE(error_of([&] { load_scene_text(written, "scene.yaml", scenes_dir(), {}, SceneLimits{.bodies = 2}); })
                .find("scene.yaml:4:5: the scene holds more than 2 bodies (the limit)"),
            std::string::npos);
  // A generator's own range is still reported as such, not as the scene's limit.
  EXPECT_NE(load_text("generators:\n  - pyramid: {rows: 5000}\n").find("pyramid 'rows' must be between 1 and 1000"),
            std::string::npos);
  // The default limit, 2^20 = 1,048,576: the largest pyramid (500,501 bodies with the ground) and a line
  // of 548,076 spheres cross it by one, and the line is refused before it is made.
  const std::string pyramid_and_line =
      "generators:\n"
      "  - pyramid: {rows: 1000, radius: 0.1}\n"
      "  - line: {count: 548076, radius: 0.1, wall: false}\n";
  const std::string two_error = load_text(pyramid_and_line);
  EXPECT_NE(two_error.find("scene.yaml:3:19: this line makes 548076 bodies, and with the 500501 "
                           "before it the scene would hold more than 1048576 bodies (the limit)"),
            std::string::npos)
      << two_error;
}

}  // namespace
}  // namespace impetus::reliability
