#include "gltf_export.hpp"

#include "report.hpp"
#include "viewer_page.hpp"

#include "impetus/core/error.hpp"
#include "impetus/core/format.hpp"
#include "impetus/engine/metrics.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <numbers>
#include <span>
#include <sstream>
#include <type_traits>
#include <variant>

namespace impetus::cli {
namespace {

constexpr int kSegments = 32;  // around a sphere, capsule or cylinder: round to the eye at any zoom a run needs
constexpr int kRings = 16;     // pole to pole of a sphere (each capsule cap gets half)

/// Triangles in the body frame, with one normal per vertex.
struct Surface {
  std::vector<float> positions, normals;
  std::vector<std::uint32_t> indices;
  std::vector<float> lines;  // a plane's grid (line segments, pairs of points)

  std::uint32_t vertex(const Vec3& p, const Vec3& n) {
    for (int i = 0; i < 3; ++i) positions.push_back(static_cast<float>(p[i]));
    for (int i = 0; i < 3; ++i) normals.push_back(static_cast<float>(n[i]));
    return static_cast<std::uint32_t>(positions.size() / 3 - 1);
  }
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) { indices.insert(indices.end(), {a, b, c}); }
  /// A flat quad a b c d (counter-clockwise seen from outside) with normal n.
  void quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& n) {
    const std::uint32_t i = vertex(a, n), j = vertex(b, n), k = vertex(c, n), l = vertex(d, n);
    triangle(i, j, k);
    triangle(i, k, l);
  }
};

// A band of rings around body z: ring r at height z(r) with radius ρ(r) and outward normal from (dρ, dz);
// `rings` + 1 rows of kSegments + 1 vertices (the seam duplicated so normals stay smooth).
template <typename Ring>
void revolve(Surface& s, int rings, Ring ring) {
  const std::uint32_t first = static_cast<std::uint32_t>(s.positions.size() / 3);
  for (int r = 0; r <= rings; ++r) {
    const auto [rho, z, n_rho, n_z] = ring(r);
    for (int k = 0; k <= kSegments; ++k) {
      const double phi = 2.0 * std::numbers::pi * k / kSegments;
      const Vec3 radial(std::cos(phi), std::sin(phi), 0.0);
      s.vertex(rho * radial + Vec3(0, 0, z), (n_rho * radial + Vec3(0, 0, n_z)).normalized());
    }
  }
  const std::uint32_t row = kSegments + 1;
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < kSegments; ++k) {
      const std::uint32_t a = first + r * row + k, b = a + 1, c = a + row, d = c + 1;
      s.triangle(a, c, b);
      s.triangle(b, c, d);
    }
}

// A disc at height z facing ±z.
void disc(Surface& s, double radius, double z, double facing) {
  const Vec3 n(0, 0, facing);
  const std::uint32_t centre = s.vertex(Vec3(0, 0, z), n);
  std::uint32_t previous = s.vertex(Vec3(radius, 0, z), n);
  for (int k = 1; k <= kSegments; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / kSegments;
    const std::uint32_t next = s.vertex(Vec3(radius * std::cos(phi), radius * std::sin(phi), z), n);
    if (facing > 0) s.triangle(centre, previous, next);
    else s.triangle(centre, next, previous);
    previous = next;
  }
}

// A sphere cap from polar angle θ0 to θ1 (0 at +z), shifted by `dz` along z.
void cap(Surface& s, double radius, double theta0, double theta1, int rings, double dz) {
  revolve(s, rings, [&](int r) {
    const double theta = theta0 + (theta1 - theta0) * r / rings;
    return std::array<double, 4>{radius * std::sin(theta), dz + radius * std::cos(theta), std::sin(theta),
                                 std::cos(theta)};
  });
}

/// The surface of a body's shape in its body frame. `plane_half` is the half size of a plane's quad and
/// `plane_centre` its centre's offset along the plane (body frame).
Surface tessellate(const Shape& shape, double plane_half, const Vec3& plane_centre) {
  Surface s;
  std::visit(
      [&](const auto& g) {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, Sphere>) {
          cap(s, g.radius, 0.0, std::numbers::pi, kRings, 0.0);
        } else if constexpr (std::is_same_v<T, Box>) {
          const Vec3 h = 0.5 * g.size;
          for (int axis = 0; axis < 3; ++axis)
            for (const double sign : {-1.0, 1.0}) {
              const int u = (axis + 1) % 3, v = (axis + 2) % 3;
              Vec3 n = Vec3::Zero(), du = Vec3::Zero(), dv = Vec3::Zero();
              n[axis] = sign;
              du[u] = h[u];
              dv[v] = h[v];
              const Vec3 c = sign * h[axis] * n.cwiseAbs();
              if (sign > 0) s.quad(c - du - dv, c + du - dv, c + du + dv, c - du + dv, n);
              else s.quad(c - du - dv, c - du + dv, c + du + dv, c + du - dv, n);
            }
        } else if constexpr (std::is_same_v<T, Capsule>) {
          const double half = 0.5 * g.length;
          cap(s, g.radius, 0.0, 0.5 * std::numbers::pi, kRings / 2, half);
          revolve(s, 1, [&](int r) { return std::array<double, 4>{g.radius, half - 2.0 * half * r, 1.0, 0.0}; });
          cap(s, g.radius, 0.5 * std::numbers::pi, std::numbers::pi, kRings / 2, -half);
        } else if constexpr (std::is_same_v<T, Cylinder>) {
          const double half = 0.5 * g.length;
          revolve(s, 1, [&](int r) { return std::array<double, 4>{g.radius, half - 2.0 * half * r, 1.0, 0.0}; });
          disc(s, g.radius, half, 1.0);
          disc(s, g.radius, -half, -1.0);
        } else if constexpr (std::is_same_v<T, Plane>) {
          // A square of the scene's size on the plane's surface, with a grid of 20 × 20 cells.
          const Vec3 n = g.normal.normalized();
          const Vec3 t1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
          const Vec3 t2 = n.cross(t1);
          const Vec3 c = g.offset * n + plane_centre - plane_centre.dot(n) * n;
          const double h = plane_half;
          s.quad(c - h * t1 - h * t2, c + h * t1 - h * t2, c + h * t1 + h * t2, c - h * t1 + h * t2, n);
          const Vec3 lift = 1e-3 * h * n;  // the grid just above the quad, so it is not hidden in it
          for (int i = 0; i <= 20; ++i) {
            const double a = -h + 2.0 * h * i / 20;
            for (const Vec3& p : {Vec3(c + a * t1 - h * t2 + lift), Vec3(c + a * t1 + h * t2 + lift),
                                  Vec3(c - h * t1 + a * t2 + lift), Vec3(c + h * t1 + a * t2 + lift)})
              for (int k = 0; k < 3; ++k) s.lines.push_back(static_cast<float>(p[k]));
          }
        } else if constexpr (std::is_same_v<T, MeshShape>) {
          // The mesh as imported (body frame, centred on the centre of mass), one flat normal per triangle.
          if (!g.mesh) return;
          for (const auto& t : g.mesh->triangles) {
            const Vec3 &a = g.mesh->vertices[t[0]], &b = g.mesh->vertices[t[1]], &c = g.mesh->vertices[t[2]];
            const Vec3 n = (b - a).cross(c - a).normalized();
            const Vec3 normal = n.allFinite() ? n : Vec3(Vec3::UnitZ());
            s.triangle(s.vertex(a, normal), s.vertex(b, normal), s.vertex(c, normal));
          }
        }
      },
      shape);
  return s;
}

/// A deterministic colour per body: the hue from a hash of its name; fixed bodies grey.
std::array<double, 4> colour(const RigidBody& body) {
  if (body.fixed) return {0.6, 0.6, 0.6, 1.0};
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : body.name) h = (h ^ c) * 0x100000001b3ull;
  const double hue = static_cast<double>(h % 360) / 60.0, s = 0.55, v = 0.85;
  const double c = v * s, x = c * (1.0 - std::abs(std::fmod(hue, 2.0) - 1.0)), m = v - c;
  const int sector = static_cast<int>(hue);
  const std::array<std::array<double, 3>, 6> rgb{{{c, x, 0}, {x, c, 0}, {0, c, x}, {0, x, c}, {x, 0, c}, {c, 0, x}}};
  return {rgb[sector][0] + m, rgb[sector][1] + m, rgb[sector][2] + m, 1.0};
}

bool moves(const RigidBody& body) { return !body.fixed || body.motion == PrescribedMotion::moving; }

/// Appends `bytes` to the model's one buffer (4-byte aligned) and returns a buffer view on them.
int add_view(tinygltf::Model& model, const void* bytes, std::size_t size, int target) {
  std::vector<unsigned char>& data = model.buffers[0].data;
  while (data.size() % 4 != 0) data.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  if (target != 0) view.target = target;
  const auto* p = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), p, p + size);
  model.bufferViews.push_back(view);
  return static_cast<int>(model.bufferViews.size() - 1);
}

/// A float accessor of `count` elements of `type` (TINYGLTF_TYPE_VEC3 …) over `values`, with min and max
/// when `bounds` (required for positions and animation inputs).
int add_floats(tinygltf::Model& model, const std::vector<float>& values, int type, int components, int target,
               bool bounds) {
  tinygltf::Accessor a;
  a.bufferView = add_view(model, values.data(), values.size() * sizeof(float), target);
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.type = type;
  a.count = values.size() / static_cast<std::size_t>(components);
  if (bounds && a.count > 0) {
    a.minValues.assign(components, std::numeric_limits<double>::infinity());
    a.maxValues.assign(components, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < values.size(); ++i) {
      const std::size_t k = i % static_cast<std::size_t>(components);
      a.minValues[k] = std::min(a.minValues[k], static_cast<double>(values[i]));
      a.maxValues[k] = std::max(a.maxValues[k], static_cast<double>(values[i]));
    }
  }
  model.accessors.push_back(a);
  return static_cast<int>(model.accessors.size() - 1);
}

int add_material(tinygltf::Model& model, const std::array<double, 4>& rgba, const std::string& name) {
  tinygltf::Material m;
  m.name = name;
  m.pbrMetallicRoughness.baseColorFactor = {rgba[0], rgba[1], rgba[2], rgba[3]};
  m.pbrMetallicRoughness.metallicFactor = 0.0;
  m.pbrMetallicRoughness.roughnessFactor = 0.7;
  m.doubleSided = true;  // a plane's quad is seen from below too
  model.materials.push_back(m);
  return static_cast<int>(model.materials.size() - 1);
}

tinygltf::Value text(const std::string& s) { return tinygltf::Value(s); }

}  // namespace

std::string lowercase_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

bool is_animation_path(const std::filesystem::path& file) {
  const std::string ext = lowercase_extension(file);
  return ext == ".glb" || ext == ".gltf" || ext == ".html";
}

namespace {

// Bytes a sample holds: its time and three series, and per moving body a translation, a rotation, a
// velocity and an angular velocity (float32).
constexpr double kSampleBytes = 16.0, kBodySampleBytes = 52.0, kContactBytes = 36.0;

}  // namespace

GltfRecorder::GltfRecorder(const std::filesystem::path& file, bool overwrite, const std::filesystem::path& input,
                           const World& world, std::uint64_t samples, GltfRunInfo info)
    : file_(file), info_(std::move(info)) {
  check_output_path(file, overwrite, input, "--out");
  if (lowercase_extension(file) == ".html") check_viewer_available("--out " + file.string());
  std::uint64_t moving = 0;
  for (const RigidBody& b : world.bodies()) moving += moves(b) ? 1 : 0;
  const double bytes = static_cast<double>(samples) * (kSampleBytes + kBodySampleBytes * static_cast<double>(moving));
  if (bytes > static_cast<double>(kMaxAnimationBytes))
    throw Error("--out " + file.string() + ": the animation would hold " + std::to_string(samples) + " samples of " +
                std::to_string(moving) + " moving bodies (" + format_number(std::round(bytes / 1e6)) +
                " MB), more than the " + std::to_string(kMaxAnimationBytes >> 20) +
                " MiB a glTF export keeps in memory; record fewer steps with --every");
  bytes_ = static_cast<std::uint64_t>(bytes);
  translations_.resize(world.bodies().size());
  rotations_.resize(world.bodies().size());
  velocities_.resize(world.bodies().size());
  angular_velocities_.resize(world.bodies().size());
}

void GltfRecorder::record(const World& world) {
  const auto bodies = world.bodies();
  times_.push_back(static_cast<float>(world.time()));
  kinetic_.push_back(static_cast<float>(total_kinetic_energy(bodies)));
  potential_.push_back(static_cast<float>(load_potential_energy(bodies, world.settings().gravity)));
  double deepest = 0.0;
  for (const Contact& c : world.contacts()) deepest = std::max(deepest, c.depth);
  penetration_.push_back(static_cast<float>(deepest));
  const auto push3 = [](std::vector<float>& to, const Vec3& v) {
    for (int k = 0; k < 3; ++k) to.push_back(static_cast<float>(v[k]));
  };
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!moves(bodies[i])) continue;
    const Quat q = bodies[i].orientation();
    push3(translations_[i], bodies[i].position);
    for (const double c : {q.x(), q.y(), q.z(), q.w()}) rotations_[i].push_back(static_cast<float>(c));
    push3(velocities_[i], bodies[i].velocity);
    push3(angular_velocities_[i], bodies[i].angular_velocity);
  }
  // Contacts are what a run cannot bound in advance: once they would pass the cap, the rest of the run
  // records none, and the file says so (asset extras contacts.complete: false).
  const std::span<const Contact> contacts = world.contacts();
  const std::uint64_t more = static_cast<std::uint64_t>(kContactBytes) * contacts.size();
  if (contacts_complete_ && bytes_ + more > kMaxAnimationBytes) {
    contacts_complete_ = false;
    std::cerr << "impetus: warning: --out " << file_.string() << ": contacts are not recorded after t = "
              << format_number(world.time()) << " s: they would pass the " << (kMaxAnimationBytes >> 20)
              << " MiB a glTF export keeps in memory (record fewer steps with --every)\n";
  }
  if (!contacts_complete_) {
    contact_counts_.push_back(0);
    return;
  }
  bytes_ += more;
  contact_counts_.push_back(static_cast<std::uint32_t>(contacts.size()));
  for (const Contact& c : contacts) {
    push3(contact_points_, c.point);
    push3(normal_impulses_, c.impulse * c.normal);
    push3(tangent_impulses_, c.tangent_impulse);
  }
}

std::string GltfRecorder::serialize(const World& world, bool binary) const {
  const auto bodies = world.bodies();
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "Impetus " + info_.version;
  model.buffers.emplace_back();

  // The planes' quads cover the moving bodies' extent (their start and end positions) with room to spare.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (std::holds_alternative<Plane>(bodies[i].shape)) continue;
    lo = lo.cwiseMin(bodies[i].position);
    hi = hi.cwiseMax(bodies[i].position);
    for (std::size_t k = 0; k + 2 < translations_[i].size(); k += 3) {
      const Vec3 p(translations_[i][k], translations_[i][k + 1], translations_[i][k + 2]);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const bool any = lo.allFinite() && hi.allFinite();
  const Vec3 middle = any ? Vec3(0.5 * (lo + hi)) : Vec3::Zero();
  const double half = any ? std::max(2.0, 0.75 * (hi - lo).maxCoeff() + 1.0) : 5.0;

  tinygltf::Scene scene;
  tinygltf::Value::Array names, masses;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const RigidBody& b = bodies[i];
    const Vec3 centre_in_body = b.rotation.transpose() * (middle - b.position);
    const Surface s = tessellate(b.shape, half, centre_in_body);
    tinygltf::Mesh mesh;
    mesh.name = b.name;
    if (!s.indices.empty()) {
      tinygltf::Primitive p;
      p.attributes["POSITION"] = add_floats(model, s.positions, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
      p.attributes["NORMAL"] = add_floats(model, s.normals, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER, false);
      tinygltf::Accessor idx;
      idx.bufferView = add_view(model, s.indices.data(), s.indices.size() * sizeof(std::uint32_t),
                                TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
      idx.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
      idx.type = TINYGLTF_TYPE_SCALAR;
      idx.count = s.indices.size();
      model.accessors.push_back(idx);
      p.indices = static_cast<int>(model.accessors.size() - 1);
      p.material = add_material(model, colour(b), b.name);
      p.mode = TINYGLTF_MODE_TRIANGLES;
      mesh.primitives.push_back(p);
    }
    if (!s.lines.empty()) {
      tinygltf::Primitive grid;
      grid.attributes["POSITION"] = add_floats(model, s.lines, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
      grid.material = add_material(model, {0.35, 0.35, 0.35, 1.0}, b.name + " grid");
      grid.mode = TINYGLTF_MODE_LINE;
      mesh.primitives.push_back(grid);
    }
    tinygltf::Node node;
    node.name = b.name;
    if (!mesh.primitives.empty()) {
      model.meshes.push_back(mesh);
      node.mesh = static_cast<int>(model.meshes.size() - 1);
    }
    const Quat q = b.orientation();
    node.translation = {b.position.x(), b.position.y(), b.position.z()};
    node.rotation = {q.x(), q.y(), q.z(), q.w()};
    tinygltf::Value::Object extras{{"name", text(b.name)},
                                   {"mass", tinygltf::Value(b.fixed ? 0.0 : b.mass)},
                                   {"fixed", tinygltf::Value(b.fixed)},
                                   {"shape", text(shape_kind_name(b.shape))}};
    if (!velocities_[i].empty()) {
      extras["velocity"] = tinygltf::Value(add_floats(model, velocities_[i], TINYGLTF_TYPE_VEC3, 3, 0, false));
      extras["angular_velocity"] =
          tinygltf::Value(add_floats(model, angular_velocities_[i], TINYGLTF_TYPE_VEC3, 3, 0, false));
    }
    node.extras = tinygltf::Value(extras);
    model.nodes.push_back(node);
    scene.nodes.push_back(static_cast<int>(model.nodes.size() - 1));
    names.push_back(text(b.name));
    masses.push_back(tinygltf::Value(b.fixed ? 0.0 : b.mass));
  }
  scene.name = info_.scene_file;
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  // The sample times: the animation's input, and the time axis of the series in extras.
  // One animation: every recorded time, and per moving body a translation and a rotation sampler.
  const int input = times_.empty() ? -1 : add_floats(model, times_, TINYGLTF_TYPE_SCALAR, 1, 0, true);
  if (!times_.empty()) {
    tinygltf::Animation animation;
    animation.name = "trajectory";
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (!moves(bodies[i])) continue;
      const std::pair<const std::vector<float>*, const char*> paths[] = {{&translations_[i], "translation"},
                                                                          {&rotations_[i], "rotation"}};
      for (const auto& [values, path] : paths) {
        tinygltf::AnimationSampler sampler;
        sampler.input = input;
        sampler.output = add_floats(model, *values, std::strcmp(path, "rotation") == 0 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                                    std::strcmp(path, "rotation") == 0 ? 4 : 3, 0, false);
        sampler.interpolation = "LINEAR";
        animation.samplers.push_back(sampler);
        tinygltf::AnimationChannel channel;
        channel.sampler = static_cast<int>(animation.samplers.size() - 1);
        channel.target_node = static_cast<int>(i);
        channel.target_path = path;
        animation.channels.push_back(channel);
      }
    }
    if (!animation.channels.empty()) model.animations.push_back(animation);
  }

  // What the viewer page plots and draws besides the motion: one value per sample, and the contacts of every
  // sample one after another (`contact_counts` says how many each has).
  const auto scalars = [&](const std::vector<float>& values) {
    return tinygltf::Value(add_floats(model, values, TINYGLTF_TYPE_SCALAR, 1, 0, false));
  };
  tinygltf::Value::Object contacts{{"complete", tinygltf::Value(contacts_complete_)}};
  if (!contact_counts_.empty()) {
    std::vector<float> counts(contact_counts_.begin(), contact_counts_.end());
    contacts["counts"] = scalars(counts);
  }
  if (!contact_points_.empty()) {
    const auto vectors = [&](const std::vector<float>& values) {
      return tinygltf::Value(add_floats(model, values, TINYGLTF_TYPE_VEC3, 3, 0, false));
    };
    contacts["points"] = vectors(contact_points_);
    contacts["normal_impulses"] = vectors(normal_impulses_);
    contacts["tangent_impulses"] = vectors(tangent_impulses_);
  }
  tinygltf::Value::Object series;
  if (!times_.empty())
    series = {{"times", tinygltf::Value(input)},
              {"kinetic_energy", scalars(kinetic_)},
              {"potential_energy", scalars(potential_)},
              {"penetration", scalars(penetration_)}};
  const Vec3& g = world.settings().gravity;
  model.asset.extras = tinygltf::Value(tinygltf::Value::Object{
      {"impetus_scene", text(info_.scene_file)},
      {"modules", tinygltf::Value(tinygltf::Value::Object{{"integrator", text(info_.integrator)},
                                                          {"detector", text(info_.detector)},
                                                          {"resolver", text(info_.resolver)}})},
      {"bodies", tinygltf::Value(names)},
      {"masses", tinygltf::Value(masses)},
      {"dt", tinygltf::Value(world.settings().dt)},
      {"gravity", tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(g.x()), tinygltf::Value(g.y()),
                                                         tinygltf::Value(g.z())})},
      {"series", tinygltf::Value(series)},
      {"contacts", tinygltf::Value(contacts)}});
  model.buffers[0].data.resize((model.buffers[0].data.size() + 3) / 4 * 4, 0);

  std::ostringstream bytes;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, bytes, /*prettyPrint=*/!binary, binary))
    throw Error(file_.string() + ": the glTF document could not be serialized");
  return bytes.str();
}

void GltfRecorder::finish(const World& world) {
  const std::string ext = lowercase_extension(file_);
  const std::string data = ext == ".html" ? viewer_page(serialize(world, true), info_.scene_file)
                                          : serialize(world, ext == ".glb");
  write_file(file_, data);
}

}  // namespace impetus::cli
