// The viewer page (README.md, "Seeing a run"), tested as a person would look at it: `impetus run SCENE
// --out run.html` and `impetus view run.glb --out run.html` write the same page; headless Chromium (Debian's
// `chromium`, installed by scripts/setup.sh) opens it from file:// with no console error; and at two chosen
// times, in a screenshot with a camera the test fixes, the pixel at the projection of the ball's centre
// (its pose from the CSV of the same run, projected here, not by the page) has the ball's colour, and
// after the ball has moved on it no longer does. The run's data the page shows besides the motion
// (velocities, energies, contacts in the glTF's extras) is checked against the CSV and the contact log.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <png.h>
#include <tiny_gltf.h>

#include "impetus_test/process.hpp"

#include <unistd.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

using Vec = std::array<double, 3>;

const std::string kExe = IMPETUS_EXE;
const std::string kScene = IMPETUS_CLI_SCENES "/viewer_marker.yaml";
constexpr int kSteps = 100;  // dt 0.01: one second
constexpr double kRadius = 0.4, kMass = 2.0, kGravity = 9.81;

// The test's files and Chromium's profiles, removed when the test program ends.
fs::path temp_dir() {
  struct Dir {
    fs::path path = fs::temp_directory_path() / ("impetus_viewer_test_" + std::to_string(::getpid()));
    Dir() {
      fs::remove_all(path);
      fs::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

impetus::test::CommandResult run(const std::string& command) { return impetus::test::run_shell(command); }

std::string read_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Headless Chromium on a page, with a fresh profile each time and a bound on how long it may take.
std::string chromium(const fs::path& page, const std::string& hash, const std::string& what, int width = 1000,
                     int height = 700) {
  static int profiles = 0;
  const fs::path profile = temp_dir() / ("profile_" + std::to_string(profiles++));
  const std::string command = std::string("timeout 120 ") + IMPETUS_CHROMIUM +
                              " --headless --no-sandbox --disable-gpu --enable-unsafe-swiftshader --disable-quic"
                              " --no-first-run --disable-background-networking --disable-component-update"
                              " --disable-sync --hide-scrollbars --host-resolver-rules='MAP * ~NOTFOUND' --user-data-dir=" + profile.string() +
                              " --window-size=" + std::to_string(width) + "," + std::to_string(height) +
                              " --virtual-time-budget=10000 " + what + " 'file://" + page.string() + "#" + hash + "'";
  const auto r = impetus::test::run_shell(command, "/dev/null");
  EXPECT_EQ(r.status, 0) << command;
  return r.out;
}

// The page's own report (#impetus-status) after it loaded and drew.
nlohmann::json page_status(const fs::path& page, const std::string& hash) {
  const std::string dom = chromium(page, hash, "--dump-dom");
  const std::string open = "<pre id=\"impetus-status\" hidden=\"\">";
  const std::size_t at = dom.find(open);
  if (at == std::string::npos) {
    ADD_FAILURE() << "no #impetus-status in the page's DOM:\n" << dom.substr(0, 2000);
    return {};
  }
  const std::size_t end = dom.find("</pre>", at);
  return nlohmann::json::parse(dom.substr(at + open.size(), end - at - open.size()));
}

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgba;
  std::array<double, 3> pixel(int x, int y) const {
    const unsigned char* p = &rgba.at(4 * (static_cast<std::size_t>(y) * width + x));
    return {p[0] / 255.0, p[1] / 255.0, p[2] / 255.0};
  }
};

Image screenshot(const fs::path& page, const std::string& hash, const fs::path& png) {
  chromium(page, hash, "--screenshot=" + png.string());
  Image image;
  png_image reader;
  std::memset(&reader, 0, sizeof reader);
  reader.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&reader, png.c_str())) {
    ADD_FAILURE() << png << ": not a PNG: " << reader.message;
    return image;
  }
  reader.format = PNG_FORMAT_RGBA;
  image.width = static_cast<int>(reader.width);
  image.height = static_cast<int>(reader.height);
  image.rgba.resize(PNG_IMAGE_SIZE(reader));
  if (!png_image_finish_read(&reader, nullptr, image.rgba.data(), 0, nullptr)) ADD_FAILURE() << reader.message;
  return image;
}

// Hue (degrees) and saturation of an RGB colour.
std::pair<double, double> hue_saturation(const std::array<double, 3>& c) {
  const double hi = std::max({c[0], c[1], c[2]}), lo = std::min({c[0], c[1], c[2]}), d = hi - lo;
  if (d <= 0) return {0.0, 0.0};
  double h = hi == c[0] ? std::fmod((c[1] - c[2]) / d, 6.0) : hi == c[1] ? (c[2] - c[0]) / d + 2 : (c[0] - c[1]) / d + 4;
  h *= 60.0;
  if (h < 0) h += 360.0;
  return {h, d / hi};
}

double hue_distance(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 360.0);
  return std::min(d, 360.0 - d);
}

// sRGB encoding of a linear colour component (what the page's renderer writes).
double srgb(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

// The pixel (x right, y down) where a perspective camera at `eye` looking at `target` with `up` and a
// vertical field of view `fov` (degrees) sees `p`, on a `width` × `height` view: three.js's camera model.
std::array<double, 2> project(const Vec& p, const Vec& eye, const Vec& target, const Vec& up, double fov, int width,
                              int height) {
  const auto sub = [](const Vec& a, const Vec& b) { return Vec{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  const auto dot = [](const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const auto cross = [](const Vec& a, const Vec& b) {
    return Vec{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  const auto unit = [&](const Vec& a) {
    const double n = std::sqrt(dot(a, a));
    return Vec{a[0] / n, a[1] / n, a[2] / n};
  };
  const Vec forward = unit(sub(target, eye)), right = unit(cross(forward, up)), camera_up = cross(right, forward);
  const Vec d = sub(p, eye);
  const double depth = dot(d, forward), t = std::tan(fov * std::numbers::pi / 360.0);
  const double ndc_x = dot(d, right) / (depth * t * width / height), ndc_y = dot(d, camera_up) / (depth * t);
  return {(ndc_x + 1.0) / 2.0 * width, (1.0 - ndc_y) / 2.0 * height};
}

struct Row {
  double time;
  Vec position, velocity;
};

std::vector<Row> marker_rows(const fs::path& csv) {
  std::vector<Row> rows;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
    if (f.size() != 16 || f[2] != "marker") continue;
    rows.push_back({std::stod(f[1]), {std::stod(f[3]), std::stod(f[4]), std::stod(f[5])},
                    {std::stod(f[10]), std::stod(f[11]), std::stod(f[12])}});
  }
  return rows;
}

std::vector<float> floats(const tinygltf::Model& model, int accessor) {
  const tinygltf::Accessor& a = model.accessors.at(accessor);
  const tinygltf::BufferView& view = model.bufferViews.at(a.bufferView);
  const std::size_t components = a.type == TINYGLTF_TYPE_SCALAR ? 1 : a.type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
  std::vector<float> out(a.count * components);
  std::memcpy(out.data(), model.buffers.at(view.buffer).data.data() + view.byteOffset + a.byteOffset,
              out.size() * sizeof(float));
  return out;
}

// The run, written once as CSV, contact log, glTF and page (the same scene and build: the same numbers).
struct Outputs {
  fs::path csv, contacts, glb, page, viewed;
};

const Outputs& outputs() {
  static const Outputs o = [] {
    Outputs out{temp_dir() / "run.csv", temp_dir() / "contacts.csv", temp_dir() / "run.glb", temp_dir() / "run.html",
                temp_dir() / "viewed.html"};
    const std::string steps = " run " + kScene + " --steps " + std::to_string(kSteps) + " --overwrite";
    for (const std::string& args : {steps + " --out " + out.csv.string() + " --contacts " + out.contacts.string(),
                                    steps + " --out " + out.glb.string(), steps + " --out " + out.page.string(),
                                    " view " + out.glb.string() + " --out " + out.viewed.string()}) {
      const auto r = run(kExe + args);
      EXPECT_EQ(r.status, 0) << args << "\n" << r.out;
    }
    return out;
  }();
  return o;
}

// A camera looking across the ball's path from the side and above.
const Vec kEye{0.0, -7.0, 2.5}, kTarget{0.0, 0.0, 0.4}, kUp{0.0, 0.0, 1.0};
std::string camera_hash(double time) {
  std::ostringstream s;
  s << "time=" << time << "&camera=" << kEye[0] << "," << kEye[1] << "," << kEye[2] << "," << kTarget[0] << ","
    << kTarget[1] << "," << kTarget[2];
  return s.str();
}

TEST(CliViewer, RunAndViewWriteTheSamePage) {
  const Outputs& o = outputs();
  const std::string page = read_file(o.page);
  EXPECT_GT(page.size(), 100000u) << "the page carries three.js";
  EXPECT_EQ(page, read_file(o.viewed));
  EXPECT_EQ(page.find("@@IMPETUS_"), std::string::npos) << "a placeholder was left in the page";
  // Nothing from elsewhere: no script, style sheet or image by address (Chromium runs it with every host
  // unresolvable, so a fetch would fail there as a console error).
  for (const char* external : {"<script src", "<link", "<img", "@import"})
    EXPECT_EQ(page.find(external), std::string::npos) << external;
}

TEST(CliViewer, TheGltfCarriesVelocitiesEnergiesAndContacts) {
  const Outputs& o = outputs();
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &error, &warning, o.glb.string())) << error;
  const std::vector<Row> rows = marker_rows(o.csv);
  ASSERT_EQ(rows.size(), kSteps + 1u);
  const auto& extras = model.asset.extras;
  const auto& series = extras.Get("series");
  const std::vector<float> times = floats(model, series.Get("times").GetNumberAsInt());
  const std::vector<float> kinetic = floats(model, series.Get("kinetic_energy").GetNumberAsInt());
  const std::vector<float> potential = floats(model, series.Get("potential_energy").GetNumberAsInt());
  ASSERT_EQ(times.size(), rows.size());
  const tinygltf::Node& marker = model.nodes.at(1);
  ASSERT_EQ(marker.name, "marker");
  const std::vector<float> velocity = floats(model, marker.extras.Get("velocity").GetNumberAsInt());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(times[i], static_cast<float>(rows[i].time));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(velocity[3 * i + k], static_cast<float>(rows[i].velocity[k])) << i;
    // A frictionless ball slides without turning: K = ½ m |v|², U = m g z (the ground plane's height 0),
    // each to float32 precision.
    const Vec& v = rows[i].velocity;
    const double k_expected = 0.5 * kMass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    EXPECT_NEAR(kinetic[i], k_expected, 1e-6 * k_expected) << i;
    EXPECT_NEAR(potential[i], kMass * kGravity * rows[i].position[2], 1e-6) << i;
  }
  // The contacts are the contact log's, sample by sample (step 0 has none: nothing was detected yet).
  const auto& contacts = extras.Get("contacts");
  EXPECT_TRUE(contacts.Get("complete").Get<bool>());
  const std::vector<float> counts = floats(model, contacts.Get("counts").GetNumberAsInt());
  const std::vector<float> points = floats(model, contacts.Get("points").GetNumberAsInt());
  const std::vector<float> impulses = floats(model, contacts.Get("normal_impulses").GetNumberAsInt());
  std::ifstream log(o.contacts);
  std::string line;
  std::getline(log, line);
  std::vector<std::vector<double>> logged;
  while (std::getline(log, line)) {
    std::vector<double> f;
    std::stringstream fields(line);
    int column = 0;
    for (std::string x; std::getline(fields, x, ','); ++column)
      f.push_back(column == 2 || column == 3 || column == 15 ? 0.0 : std::stod(x));
    logged.push_back(f);
  }
  ASSERT_EQ(counts.size(), rows.size());
  EXPECT_EQ(counts[0], 0.0f);
  double total = 0;
  for (const float c : counts) total += c;
  ASSERT_EQ(total, static_cast<double>(logged.size()));
  ASSERT_EQ(points.size(), 3 * logged.size());
  for (std::size_t c = 0; c < logged.size(); ++c) {
    const auto& f = logged[c];  // step,time,a,b,x,y,z,nx,ny,nz,depth,impulse,…
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(points[3 * c + k], static_cast<float>(f[4 + k]));
      EXPECT_EQ(impulses[3 * c + k], static_cast<float>(f[11] * f[7 + k]));
    }
    // Resting on the ground, each step's contact takes gravity's m g dt.
    EXPECT_NEAR(f[11], kMass * kGravity * 0.01, 1e-9) << "contact " << c;
  }
}

TEST(CliViewer, ChromiumDrawsTheBallWhereItsPoseSays) {
  ASSERT_TRUE(fs::exists(IMPETUS_CHROMIUM)) << "no chromium (Debian's `chromium`): run scripts/setup.sh";
  const Outputs& o = outputs();
  const std::vector<Row> rows = marker_rows(o.csv);
  ASSERT_EQ(rows.size(), kSteps + 1u);
  const int early = 20, late = 90;  // samples: x = -1.4 and x = 0.7, 2.1 m (five radii) apart

  // Loaded, drawn, no console error, and the run's size as the page reads it.
  const nlohmann::json status = page_status(o.page, camera_hash(rows[early].time));
  ASSERT_EQ(status.value("state", ""), "ready") << status.dump();
  EXPECT_TRUE(status["errors"].empty()) << status["errors"].dump();
  EXPECT_EQ(status["bodies"], 2);
  EXPECT_EQ(status["samples"], kSteps + 1);
  EXPECT_NEAR(status["duration"].get<double>(), rows.back().time, 1e-6);
  EXPECT_NEAR(status["time"].get<double>(), rows[early].time, 1e-12);
  EXPECT_EQ(status["fov"], 45);

  // A body picked (as a click does): its state at that time is the run's, at float32.
  const nlohmann::json picked = page_status(o.page, camera_hash(rows[early].time) + "&select=marker");
  ASSERT_TRUE(picked["selected"].is_object()) << picked.dump();
  EXPECT_EQ(picked["selected"]["name"], "marker");
  EXPECT_EQ(picked["selected"]["mass"], kMass);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(picked["selected"]["velocity"][k].get<double>(), rows[early].velocity[k], 1e-6);
    EXPECT_NEAR(picked["selected"]["position"][k].get<double>(), rows[early].position[k], 1e-6);
  }
  // A run exported as .gltf (JSON, its buffer a data: address) makes a page that loads the same way.
  const fs::path gltf = temp_dir() / "run.gltf", gltf_page = temp_dir() / "run_gltf.html";
  ASSERT_EQ(run(kExe + " run " + kScene + " --steps " + std::to_string(kSteps) + " --out " + gltf.string()).status, 0);
  ASSERT_EQ(run(kExe + " view " + gltf.string() + " --out " + gltf_page.string()).status, 0);
  const nlohmann::json from_gltf = page_status(gltf_page, camera_hash(rows[early].time) + "&select=marker");
  EXPECT_TRUE(from_gltf["errors"].empty()) << from_gltf.dump();
  EXPECT_EQ(from_gltf["selected"], picked["selected"]);
  // Opened without a time, the page plays forward from 0 (how far it gets depends on how many frames a
  // loaded machine draws), stopping at the end.
  const nlohmann::json played = page_status(o.page, "speed=4");
  EXPECT_TRUE(played["errors"].empty()) << played["errors"].dump();
  EXPECT_GT(played["time"].get<double>(), 0.0) << played.dump();
  EXPECT_LE(played["time"].get<double>(), played["duration"].get<double>()) << played.dump();
  EXPECT_TRUE(played["playing"].get<bool>() || played["time"] == played["duration"]) << played.dump();

  // The ball's colour as the exporter gave it, seen through the page's sRGB output.
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &error, &warning, o.glb.string())) << error;
  const auto& factor =
      model.materials.at(model.meshes.at(model.nodes.at(1).mesh).primitives.at(0).material).pbrMetallicRoughness.baseColorFactor;
  const auto [ball_hue, ball_saturation] = hue_saturation({srgb(factor[0]), srgb(factor[1]), srgb(factor[2])});
  ASSERT_GT(ball_saturation, 0.25);
  ASSERT_GT(hue_distance(ball_hue, 218.0), 90.0) << "the ball's hue must differ from the page's background";

  const Image at_early = screenshot(o.page, camera_hash(rows[early].time), temp_dir() / "early.png");
  const Image at_late = screenshot(o.page, camera_hash(rows[late].time), temp_dir() / "late.png");
  ASSERT_GT(at_early.width, 0);
  ASSERT_EQ(at_early.width, 1000);
  ASSERT_EQ(at_early.height, 700);

  // Not blank: many colours (ground, grid, ball, panels).
  std::vector<std::uint32_t> colours;
  for (std::size_t i = 0; i < at_early.rgba.size(); i += 4 * 97)
    colours.push_back(at_early.rgba[i] << 16 | at_early.rgba[i + 1] << 8 | at_early.rgba[i + 2]);
  std::sort(colours.begin(), colours.end());
  EXPECT_GT(std::unique(colours.begin(), colours.end()) - colours.begin(), 20);

  for (const auto& [sample, shot, other] : {std::tuple{early, &at_early, &at_late}, std::tuple{late, &at_late, &at_early}}) {
    const auto [x, y] = project(rows[sample].position, kEye, kTarget, kUp, 45.0, shot->width, shot->height);
    SCOPED_TRACE("sample " + std::to_string(sample) + " at pixel " + std::to_string(x) + ", " + std::to_string(y));
    ASSERT_TRUE(x > 0 && x < shot->width && y > 0 && y < shot->height);
    // Where the pose says, the ball's hue, lit (3 × 3 pixels around the centre, all of them).
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy) {
        const auto [hue, saturation] = hue_saturation(shot->pixel(static_cast<int>(x) + dx, static_cast<int>(y) + dy));
        EXPECT_LT(hue_distance(hue, ball_hue), 20.0);
        EXPECT_GT(saturation, 0.2);
      }
    // The same pixel at the other time shows the ground, not the ball.
    const auto [hue, saturation] = hue_saturation(other->pixel(static_cast<int>(x), static_cast<int>(y)));
    EXPECT_TRUE(saturation < 0.15 || hue_distance(hue, ball_hue) > 60.0) << hue << " " << saturation;
  }
}

TEST(CliViewer, ViewRefusesWhatIsNotAnImpetusRun) {
  const fs::path out = temp_dir() / "refused.html";
  // A scene (YAML), not glTF.
  auto r = run(kExe + " view " + kScene + " --out " + out.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("viewer_marker.yaml: not a glTF 2.0 file"), std::string::npos) << r.out;
  // Valid glTF that Impetus did not write.
  const fs::path foreign = temp_dir() / "foreign.gltf";
  std::ofstream(foreign) << R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0})";
  r = run(kExe + " view " + foreign.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("foreign.gltf: a glTF file Impetus did not write"), std::string::npos) << r.out;
  // A buffer in another file: the page could not stand alone.
  const fs::path external = temp_dir() / "external.gltf";
  std::ofstream(external) << R"({"asset": {"version": "2.0", "extras": {"impetus_scene": "x"}}, "buffers": [{"uri": "../data.bin", "byteLength": 4}]})";
  r = run(kExe + " view " + external.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("a buffer lives in another file"), std::string::npos) << r.out;
  // A truncated binary glTF.
  const fs::path truncated = temp_dir() / "truncated.glb";
  const std::string glb = read_file(outputs().glb);
  std::ofstream(truncated, std::ios::binary) << glb.substr(0, glb.size() / 2);
  r = run(kExe + " view " + truncated.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("truncated.glb: not a valid glTF 2.0 file"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out)) << "nothing is written for a refused input";
  // The page is never written over an existing file without --overwrite, nor as anything but .html.
  r = run(kExe + " view " + outputs().glb.string() + " --out " + outputs().page.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("file exists; pass --overwrite"), std::string::npos) << r.out;
  r = run(kExe + " view " + outputs().glb.string() + " --out " + (temp_dir() / "page.htm").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("the viewer page is written as .html"), std::string::npos) << r.out;
}

}  // namespace
