// Scene files: the top level of the format (README.md, "Scene files"), and building a World.
// The parts live in scene_bodies.cpp, scene_modules.cpp, scene_entries.cpp and scene_override.cpp.

#include "impetus/engine/scene.hpp"

#include "impetus/core/format.hpp"
#include "impetus/plugins/host.hpp"
#include "scene_internal.hpp"
#include "scene_yaml.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace impetus {
namespace {

using scene_detail::Fields;
using scene_detail::ReadBody;
using scene_detail::SceneReader;

// A generated fixed plane identical to a body the scene already has (the pyramid's "ground" in a scene
// that has its own ground, as in the README's example) is the same body: it is kept once.
bool same_fixed_plane(const RigidBody& a, const RigidBody& b) {
  const auto* pa = std::get_if<Plane>(&a.shape);
  const auto* pb = std::get_if<Plane>(&b.shape);
  return a.fixed && b.fixed && pa && pb && pa->normal == pb->normal && pa->offset == pb->offset &&
         a.position == b.position && a.rotation == b.rotation;
}

// Adds `read` to the scene, refusing a name already taken (names are how constraints, `--set` and
// the CLI's output refer to bodies).
void add_bodies(const SceneReader& r, std::vector<ReadBody> read, bool generated, Scene& scene,
                std::map<std::string, BodyIndex>& index_by_name, std::map<std::string, std::string>& where_by_name) {
  for (ReadBody& b : read) {
    const auto [it, inserted] = index_by_name.emplace(b.body.name, static_cast<BodyIndex>(scene.bodies.size()));
    if (!inserted && generated && same_fixed_plane(scene.bodies[it->second], b.body)) continue;
    if (!inserted)
      r.fail(b.where, "duplicate body name '" + b.body.name + "' (first at " + where_by_name[b.body.name] + ")");
    const std::string& where = where_by_name[b.body.name] = r.where(b.where);
    scene.body_where.push_back(where);
    scene.bodies.push_back(std::move(b.body));
  }
}

Scene read_scene(const SceneReader& r, const YAML::Node& root, const SceneLimits& limits) {
  if (!root.IsMap()) r.fail(root, "a scene is a mapping of keys (dt, gravity, modules, bodies, ...), got " +
                                      SceneReader::describe(root));
  const Fields f(r, root, "scene",
                 {"dt", "gravity", "step_order", "sleep", "threads", "plugin_path", "modules", "bodies",
                  "generators", "constraints"});
  Scene scene;
  if (const YAML::Node* n = f.find("dt")) scene.settings.dt = r.positive(*n, "dt");
  if (const YAML::Node* n = f.find("gravity")) scene.settings.gravity = r.vec3(*n, "gravity");
  if (const YAML::Node* n = f.find("step_order"))
    scene.settings.order = r.choice(*n, "step_order", {"split", "paper"}) == "paper" ? StepOrder::paper
                                                                                     : StepOrder::split;
  if (const YAML::Node* n = f.find("sleep")) {
    // Sleeping islands (docs/conventions.md, "Sleeping"): `sleep: {enabled, linear_velocity,
    // angular_velocity, time}`; any key given turns it on unless `enabled: false`.
    const Fields s(r, *n, "sleep", {"enabled", "linear_velocity", "angular_velocity", "time"});
    SleepSettings& sleep = scene.settings.sleep;
    sleep.enabled = s.find("enabled") ? r.boolean(*s.find("enabled"), "enabled") : true;
    if (const YAML::Node* v = s.find("linear_velocity")) sleep.linear_velocity = r.non_negative(*v, "linear_velocity");
    if (const YAML::Node* v = s.find("angular_velocity")) sleep.angular_velocity = r.non_negative(*v, "angular_velocity");
    if (const YAML::Node* v = s.find("time")) sleep.time = r.positive(*v, "time");
  }
  // Threads the modules may use (docs/conventions.md, "Threads"): 0 for every core; results do not depend on it.
  if (const YAML::Node* n = f.find("threads"))
    scene.settings.threads = static_cast<std::uint32_t>(r.integer(*n, "threads", 0, World::kMaxThreads));
  if (const YAML::Node* n = f.find("plugin_path")) {
    // One directory or a list of them, relative to the scene file.
    const std::vector<YAML::Node> dirs = n->IsSequence() ? r.list(*n, "plugin_path") : std::vector{*n};
    for (const YAML::Node& dir : dirs) {
      const std::string text = r.string(dir, "plugin_path");
      if (text.empty()) r.fail(dir, "'plugin_path' entries must not be empty");
      scene.plugin_path.push_back(r.resolve_path(text));
    }
  }

  const YAML::Node* modules = f.find("modules");
  std::optional<Fields> m;
  if (modules && !modules->IsNull()) m.emplace(r, *modules, "modules", std::initializer_list<std::string_view>{
                                                                        "integrator", "detector", "resolver"});
  const auto module_node = [&](const char* kind) { return m ? m->find(kind) : nullptr; };
  scene.integrator = scene_detail::read_module(r, module_node("integrator"), ModuleKind::integrator);
  scene.detector = scene_detail::read_module(r, module_node("detector"), ModuleKind::detector);
  scene.resolver = scene_detail::read_module(r, module_node("resolver"), ModuleKind::resolver);

  std::map<std::string, BodyIndex> index_by_name;
  std::map<std::string, std::string> where_by_name;
  if (const YAML::Node* n = f.find("bodies")) {
    const std::vector<YAML::Node> list = r.list(*n, "bodies");
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (scene.bodies.size() >= limits.bodies)
        r.fail(list[i], "the scene holds more than " + std::to_string(limits.bodies) + " bodies (the limit)");
      add_bodies(r, {scene_detail::read_body(r, list[i], i)}, false, scene, index_by_name, where_by_name);
    }
  }
  if (const YAML::Node* n = f.find("generators"))
    for (const YAML::Node& entry : r.list(*n, "generators")) {
      const scene_detail::BodyRoom room{scene.bodies.size(), limits.bodies};
      add_bodies(r, scene_detail::read_generator(r, entry, room), true, scene, index_by_name, where_by_name);
    }
  // Constraints last: they name bodies, including generated ones, and use their initial poses.
  if (const YAML::Node* n = f.find("constraints"))
    for (const YAML::Node& entry : r.list(*n, "constraints")) {
      scene.constraints.push_back(scene_detail::read_constraint(r, entry, scene.bodies, index_by_name));
      scene.constraint_where.push_back(r.where(entry));
    }
  return scene;
}

// What a path that is not a regular file is, for messages.
std::string file_kind(const std::filesystem::file_status& status) {
  switch (status.type()) {
    case std::filesystem::file_type::character: return "a character device";
    case std::filesystem::file_type::block: return "a block device";
    case std::filesystem::file_type::fifo: return "a FIFO";
    case std::filesystem::file_type::socket: return "a socket";
    default: return "not a file";
  }
}

// Prefix of errors about a scene once loaded: its file, or "scene" for one built in code.
std::string scene_label(const Scene& scene) { return scene.file.empty() ? "scene" : scene.file.string(); }

// A programmatic Scene may leave a module empty: it gets the scene file's default.
PluginRequest plugin_request(const ModuleRequest& module, ModuleKind kind, const char* fallback,
                             ModuleOptions& options) {
  PluginRequest request;
  request.kind = kind;
  request.name = module.plugin.empty() ? fallback : module.plugin;
  request.file = module.path;
  request.options = &options;
  request.where = module.where;
  return request;
}

}  // namespace

Scene load_scene_text(const std::string& yaml, const std::string& name, const std::filesystem::path& base_dir,
                      const std::vector<SceneOverride>& overrides, const SceneLimits& limits) {
  SceneReader reader(name, base_dir);
  try {
    YAML::Node root = scene_detail::load_bounded_yaml(yaml, name);
    scene_detail::apply_overrides(root, overrides, reader);
    Scene scene = read_scene(reader, root, limits);
    scene.warnings = reader.warnings();
    return scene;
  } catch (const YAML::Exception& e) {
    // Malformed YAML (or a yaml-cpp failure while reading the tree): never crash, point at it.
    throw Error(reader.where(e.mark) + ": invalid YAML: " + e.msg);
  }
}

Scene load_scene(const std::filesystem::path& file, const std::vector<SceneOverride>& overrides,
                 const SceneLimits& limits) {
  // A directory opens as a stream on Linux and reads as nothing, a device (/dev/zero) reads without end
  // and a FIFO blocks until someone writes: only a regular file (or a link to one) is read.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file, ec);
  if (std::filesystem::is_directory(status)) throw Error(file.string() + ": is a directory, not a scene file");
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw Error(file.string() + ": is not a regular file (" + file_kind(status) + "); a scene is read from a file");
  // Refuse enormous files before reading them into memory (a scene is a few kilobytes; generators make
  // big scenes from a few lines).
  constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t{64} << 20;
  if (const std::uintmax_t size = std::filesystem::file_size(file, ec); !ec && size > kMaxSceneBytes)
    throw Error(file.string() + ": the scene file is " + std::to_string(size) +
                " bytes, larger than the limit of " + std::to_string(kMaxSceneBytes) + " bytes (64 MiB)");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file.string() + ": cannot open the scene file: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(file.string() + ": cannot read the scene file");
  if (text.str().empty()) throw Error(file.string() + ": the scene file is empty");
  Scene scene = load_scene_text(text.str(), file.string(), file.parent_path(), overrides, limits);
  scene.file = file;
  return scene;
}

namespace {

// The first body with friction a resolver that does not model it refuses, and the first constraint
// `resolver` refuses, each located where the scene wrote it (the world would say only "body 'x'" or
// "constraint #i").
void check_resolver_accepts(const Scene& scene, CollisionResolver& resolver, const std::string& name) {
  if (const ModuleStatus friction = resolver.accept_friction(); !friction)
    for (std::size_t i = 0; i < scene.bodies.size() && i < scene.body_where.size(); ++i)
      if (scene.bodies[i].material.friction > 0.0)
        throw Error(scene.body_where[i] + ": body '" + scene.bodies[i].name + "' has friction " +
                    format_number(scene.bodies[i].material.friction) + ", but resolver '" + name + "': " +
                    friction.message + "; set its friction to 0 or choose a resolver (or mode) that models "
                    "friction, such as ledas or mirtich");
  const ModuleStatus all = resolver.accept_constraints(scene.constraints);
  if (all) return;
  for (std::size_t i = 0; i < scene.constraints.size() && i < scene.constraint_where.size(); ++i)
    if (!resolver.accept_constraints(std::span(scene.constraints).subspan(i, 1)))
      throw Error(scene.constraint_where[i] + ": resolver '" + name + "' refuses this constraint: " + all.message);
  throw Error(scene_label(scene) + ": resolver '" + name + "': " + all.message);
}

}  // namespace

std::unique_ptr<World> build_world(const Scene& scene, PluginHost& host) {
  host.prepend_directories(scene.plugin_path);
  auto world = std::make_unique<World>(scene.settings);
  try {
    world->add_bodies(scene.bodies);  // a fresh world: scene index = world index
    for (const Constraint& constraint : scene.constraints) world->add_constraint(constraint);
  } catch (const Error& e) {
    throw Error(scene_label(scene) + ": " + e.what());
  }
  // The host reads (and marks as read) the options, so each module gets its own copy.
  ModuleOptions integrator_options = scene.integrator.options;
  world->set_integrator(host.create_integrator(
      plugin_request(scene.integrator, ModuleKind::integrator, "momentum", integrator_options)));
  if (scene.detector.plugin != "none") {
    ModuleOptions options = scene.detector.options;
    world->set_detector(host.create_detector(plugin_request(scene.detector, ModuleKind::detector, "fcl", options)));
  }
  if (scene.resolver.plugin != "none") {
    ModuleOptions options = scene.resolver.options;
    const PluginRequest request = plugin_request(scene.resolver, ModuleKind::resolver, "ledas", options);
    std::shared_ptr<CollisionResolver> resolver = host.create_resolver(request);
    check_resolver_accepts(scene, *resolver, request.name);
    try {
      world->set_resolver(std::move(resolver));
    } catch (const Error& e) {
      throw Error(scene_label(scene) + ": " + e.what());  // a body's friction the resolver does not model
    }
  }
  return world;
}

}  // namespace impetus
