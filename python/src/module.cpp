// impetus._impetus: the engine for Python (README.md, "Python"). The public API is python/impetus/
// __init__.py, which wraps this module; documents the tool prints as JSON (run summary, resolve, plugins,
// mass) cross as JSON text and are parsed there, so Python sees exactly what `--json` prints.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "mass_report.hpp"
#include "report.hpp"

#include "impetus/core/error.hpp"
#include "impetus/engine/metrics.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/engine/world.hpp"
#include "impetus/plugins/host.hpp"

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace py = pybind11;
using namespace impetus;

namespace {

using Array = py::array_t<double, py::array::c_style>;

std::vector<SceneOverride> to_overrides(const std::vector<std::pair<std::string, std::string>>& pairs) {
  std::vector<SceneOverride> out;
  for (const auto& [key, value] : pairs) out.push_back({key, value});
  return out;
}

void warn(const Scene& scene) {
  if (scene.warnings.empty()) return;
  const py::object warnings = py::module_::import("warnings");
  for (const std::string& w : scene.warnings) warnings.attr("warn")(w, py::module_::import("builtins").attr("UserWarning"), 3);
}

// An (n, width) array of doubles, row after row from `fill(i, row)`.
template <typename Fill>
Array rows(std::size_t n, std::size_t width, Fill fill) {
  Array a(width == 1 ? std::vector<py::ssize_t>{static_cast<py::ssize_t>(n)}
                     : std::vector<py::ssize_t>{static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(width)});
  double* p = a.mutable_data();
  for (std::size_t i = 0; i < n; ++i) fill(i, p + i * width);
  return a;
}

void put(double* row, const Vec3& v) {
  row[0] = v.x();
  row[1] = v.y();
  row[2] = v.z();
}

py::tuple tuple3(const Vec3& v) { return py::make_tuple(v.x(), v.y(), v.z()); }

// The state arrays of set_state, checked: float64, (n, width), finite. Names the key and the defect.
Array state_array(const py::dict& state, const char* key, std::size_t n, std::size_t width) {
  if (!state.contains(key)) throw Error(std::string("set_state: no '") + key + "' array");
  const py::object value = state[key];
  if (!py::isinstance<py::array>(value))
    throw Error(std::string("set_state: '") + key + "' is a " + std::string(py::str(value.get_type().attr("__name__"))) +
                ", not a numpy array");
  const auto array = value.cast<py::array>();
  if (!array.dtype().is(py::dtype::of<double>()))
    throw Error(std::string("set_state: '") + key + "' has dtype " + std::string(py::str(array.dtype())) +
                "; it must be float64");
  std::vector<py::ssize_t> shape(array.shape(), array.shape() + array.ndim());
  const std::vector<py::ssize_t> expected = width == 9 ? std::vector<py::ssize_t>{static_cast<py::ssize_t>(n), 3, 3}
                                                       : std::vector<py::ssize_t>{static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(width)};
  if (shape != expected) {
    const auto text = [](const std::vector<py::ssize_t>& s) {
      std::string t = "(";
      for (std::size_t i = 0; i < s.size(); ++i) t += (i ? ", " : "") + std::to_string(s[i]);
      return t + (s.size() == 1 ? ",)" : ")");
    };
    throw Error(std::string("set_state: '") + key + "' has shape " + text(shape) + "; this world needs " + text(expected));
  }
  Array a = Array::ensure(array);
  const double* p = a.data();
  for (std::size_t i = 0; i < n * width; ++i)
    if (!std::isfinite(p[i]))
      throw Error(std::string("set_state: '") + key + "' of body " + std::to_string(i / width) + " is not finite");
  return a;
}

/// A world with the plugin host that loaded its modules (declared first: it outlives them) and the run's
/// statistics since it was built, for the same summary `impetus run --json` prints.
class PyWorld {
 public:
  explicit PyWorld(const Scene& scene) : scene_(scene), world_(build_world(scene_, host_)), stats_(*world_) {}

  // Steps n times without the GIL; throws Error as `impetus run` does (the scene file and the failure).
  py::dict step(std::uint64_t n) {
    {
      py::gil_scoped_release release;
      const auto start = std::chrono::steady_clock::now();
      const std::string label = scene_.file.empty() ? std::string("world") : scene_.file.string();
      try {
        for (std::uint64_t i = 0; i < n; ++i) cli::checked_step(*world_, stats_, label);
      } catch (...) {
        wall_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        throw;
      }
      wall_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    return status();
  }

  py::dict status() const {
    const StepStatus& s = world_->last_status();
    py::dict profile, integrator, detector, resolver;
    profile["velocities"] = s.profile.velocities;
    profile["detect"] = s.profile.detect;
    profile["resolve"] = s.profile.resolve;
    profile["positions"] = s.profile.positions;
    profile["total"] = s.profile.total;
    integrator["bodies"] = s.integrator.bodies;
    integrator["orthonormalized"] = s.integrator.orthonormalized;
    detector["pairs_tested"] = s.detector.pairs_tested;
    detector["narrowphase_calls"] = s.detector.narrowphase_calls;
    detector["contacts"] = s.detector.contacts;
    detector["contacts_dropped"] = s.detector.contacts_dropped;
    detector["speculative_pairs"] = s.detector.speculative_pairs;
    const ResolverCounters& r = s.resolver;
    resolver["islands"] = r.islands;
    resolver["contacts"] = r.contacts;
    resolver["rounds"] = r.rounds;
    resolver["pulling_impulses"] = r.pulling_impulses;
    resolver["non_converged"] = r.non_converged;
    resolver["singular_systems"] = r.singular_systems;
    resolver["redundant_systems"] = r.redundant_systems;
    resolver["residual"] = r.residual;
    resolver["complementarity_error"] = r.complementarity_error;
    resolver["sticking"] = r.sticking;
    resolver["sliding"] = r.sliding;
    resolver["natural_map_residual"] = r.natural_map_residual;
    resolver["friction_work"] = r.friction_work;
    py::dict out;
    out["ok"] = s.ok;
    out["message"] = s.message;
    out["time"] = world_->time();
    out["step"] = world_->step_count();
    out["contacts"] = world_->contacts().size();
    out["profile"] = profile;
    out["integrator"] = integrator;
    out["detector"] = detector;
    out["resolver"] = resolver;
    out["awake_bodies"] = s.awake_bodies;
    out["sleeping_bodies"] = s.sleeping_bodies;
    return out;
  }

  py::dict state() const {
    const auto bodies = world_->bodies();
    py::dict out;
    out["position"] = rows(bodies.size(), 3, [&](std::size_t i, double* r) { put(r, bodies[i].position); });
    out["orientation"] = rows(bodies.size(), 4, [&](std::size_t i, double* r) {
      const Quat q = bodies[i].orientation();
      r[0] = q.w();
      r[1] = q.x();
      r[2] = q.y();
      r[3] = q.z();
    });
    out["rotation"] = rows(bodies.size(), 9, [&](std::size_t i, double* r) {
      for (int k = 0; k < 9; ++k) r[k] = bodies[i].rotation(k / 3, k % 3);
    });
    out["rotation"] = out["rotation"].attr("reshape")(bodies.size(), 3, 3);
    out["velocity"] = rows(bodies.size(), 3, [&](std::size_t i, double* r) { put(r, bodies[i].velocity); });
    out["angular_velocity"] =
        rows(bodies.size(), 3, [&](std::size_t i, double* r) { put(r, bodies[i].angular_velocity); });
    return out;
  }

  // The state() layout back. `rotation` (exact) wins over `orientation` when both are given, and they must
  // then agree; each is checked (a unit quaternion, a proper rotation). Fixed bodies keep velocities they
  // may not have. Nothing changes unless everything is sound.
  void set_state(const py::dict& s) {
    const auto bodies = world_->bodies();
    const std::size_t n = bodies.size();
    const Array position = state_array(s, "position", n, 3), velocity = state_array(s, "velocity", n, 3),
                omega = state_array(s, "angular_velocity", n, 3);
    std::optional<Array> orientation, rotation;
    if (s.contains("orientation")) orientation = state_array(s, "orientation", n, 4);
    if (s.contains("rotation")) rotation = state_array(s, "rotation", n, 9);
    if (!orientation && !rotation) throw Error("set_state: no 'orientation' (or 'rotation') array");
    std::vector<Mat3> turns(n);
    for (std::size_t i = 0; i < n; ++i) {
      const std::string who = "set_state: body " + std::to_string(i) + " ('" + bodies[i].name + "')";
      std::optional<Quat> q;
      if (orientation) {
        const double* o = orientation->data() + 4 * i;
        const Quat given(o[0], o[1], o[2], o[3]);
        if (std::abs(given.norm() - 1.0) > 1e-6)
          throw Error(who + ": its orientation quaternion has norm " + std::to_string(given.norm()) +
                      "; it must be a unit quaternion (w, x, y, z)");
        q = given.normalized();
      }
      if (rotation) {
        const double* m = rotation->data() + 9 * i;
        for (int k = 0; k < 9; ++k) turns[i](k / 3, k % 3) = m[k];
        if ((turns[i].transpose() * turns[i] - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-9 || turns[i].determinant() < 0)
          throw Error(who + ": its rotation is not a proper rotation matrix (orthonormal, determinant 1)");
        if (q && q->angularDistance(Quat(turns[i])) > 1e-6)
          throw Error(who + ": 'orientation' and 'rotation' disagree; change one and drop the other");
      } else {
        turns[i] = q->toRotationMatrix();
      }
      const Vec3 v(velocity.data() + 3 * i), w(omega.data() + 3 * i);
      if (bodies[i].fixed && bodies[i].motion == PrescribedMotion::none && (!v.isZero(0.0) || !w.isZero(0.0)))
        throw Error(who + " is fixed and does not move: its velocities must stay 0 (a moving fixed body is "
                    "`motion: moving` in the scene)");
    }
    for (std::size_t i = 0; i < n; ++i) {
      RigidBody& b = bodies[i];
      const Vec3 x(position.data() + 3 * i), v(velocity.data() + 3 * i), w(omega.data() + 3 * i);
      const bool changed = x != b.position || turns[i] != b.rotation || v != b.velocity || w != b.angular_velocity;
      b.position = x;
      b.rotation = turns[i];
      b.velocity = v;
      b.angular_velocity = w;
      if (changed && b.asleep) world_->wake(static_cast<BodyIndex>(i));
    }
  }

  py::dict contacts() const {
    const std::vector<Contact>& c = world_->contacts();
    py::array_t<std::uint32_t> a(static_cast<py::ssize_t>(c.size())), b(static_cast<py::ssize_t>(c.size()));
    py::list modes;
    for (std::size_t i = 0; i < c.size(); ++i) {
      a.mutable_data()[i] = c[i].a;
      b.mutable_data()[i] = c[i].b;
      modes.append(contact_mode_name(c[i].mode));
    }
    py::dict out;
    out["a"] = a;
    out["b"] = b;
    out["point"] = rows(c.size(), 3, [&](std::size_t i, double* r) { put(r, c[i].point); });
    out["normal"] = rows(c.size(), 3, [&](std::size_t i, double* r) { put(r, c[i].normal); });
    out["depth"] = rows(c.size(), 1, [&](std::size_t i, double* r) { r[0] = c[i].depth; });
    out["impulse"] = rows(c.size(), 1, [&](std::size_t i, double* r) { r[0] = c[i].impulse; });
    out["tangent_impulse"] = rows(c.size(), 3, [&](std::size_t i, double* r) { put(r, c[i].tangent_impulse); });
    out["mode"] = modes;
    return out;
  }

  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const RigidBody& b : world_->bodies()) out.push_back(b.name);
    return out;
  }

  std::string summary() const { return cli::run_summary(scene_, *world_, stats_, wall_).dump(); }

  // Applied loads (world frame, through the centre of mass; persistent until changed), by body name.
  void set_load(const std::string& name, const std::optional<std::vector<double>>& force,
                const std::optional<std::vector<double>>& torque) {
    RigidBody& b = body(name);
    const auto vec = [&](const std::vector<double>& v, const char* what) {
      if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
        throw Error("set_load: the " + std::string(what) + " on '" + name + "' must be three finite numbers");
      return Vec3(v[0], v[1], v[2]);
    };
    if (b.fixed) throw Error("set_load: '" + name + "' is fixed; loads act on movable bodies");
    if (force) b.force = vec(*force, "force");
    if (torque) b.torque = vec(*torque, "torque");
    if (b.asleep) world_->wake(*world_->find_body(name));
  }

  World& world() { return *world_; }
  const Scene& scene() const { return scene_; }

 private:
  RigidBody& body(const std::string& name) {
    const std::optional<BodyIndex> i = world_->find_body(name);
    if (!i) throw Error("no body named '" + name + "' in this world");
    return world_->bodies()[*i];
  }

  Scene scene_;
  PluginHost host_;
  std::unique_ptr<World> world_;
  cli::RunStats stats_;
  double wall_ = 0.0;
};

py::dict measure_world(PyWorld& w) {
  const WorldMetrics m = impetus::measure(w.world());
  py::dict out;
  out["kinetic_energy"] = m.kinetic_energy;
  out["potential_energy"] = m.potential_energy;
  out["linear_momentum"] = tuple3(m.linear_momentum);
  out["angular_momentum"] = tuple3(m.angular_momentum);
  out["max_penetration"] = m.max_penetration;
  out["contacts"] = m.contacts;
  return out;
}

}  // namespace

PYBIND11_MODULE(_impetus, m) {
  m.doc() = "The Impetus engine (use the impetus package, which wraps this module)";
  m.attr("__version__") = IMPETUS_VERSION;
  py::register_exception<Error>(m, "Error", PyExc_ValueError);

  py::class_<Scene>(m, "Scene", "A scene as loaded and checked (load_scene); build a World from it")
      .def_property_readonly("file", [](const Scene& s) { return s.file.string(); })
      .def_property_readonly("dt", [](const Scene& s) { return s.settings.dt; })
      .def_property_readonly("gravity", [](const Scene& s) { return tuple3(s.settings.gravity); })
      .def_property_readonly("names", [](const Scene& s) {
        std::vector<std::string> out;
        for (const RigidBody& b : s.bodies) out.push_back(b.name);
        return out;
      })
      .def_property_readonly("modules", [](const Scene& s) {
        py::dict out;
        out["integrator"] = s.integrator.plugin;
        out["detector"] = s.detector.plugin;
        out["resolver"] = s.resolver.plugin;
        return out;
      })
      .def_property_readonly("module_options", [](const Scene& s) {
        return py::make_tuple(cli::options_json(s.integrator.options).dump(), cli::options_json(s.detector.options).dump(),
                              cli::options_json(s.resolver.options).dump());
      })
      .def_property_readonly("warnings", [](const Scene& s) { return s.warnings; })
      .def("__repr__", [](const Scene& s) {
        return "<impetus.Scene " + (s.file.empty() ? std::string("(in code)") : s.file.string()) + ": " +
               std::to_string(s.bodies.size()) + " bodies, " + s.integrator.plugin + " / " + s.detector.plugin + " / " +
               s.resolver.plugin + ">";
      });

  m.def("_load_scene", [](const std::string& file, const std::vector<std::pair<std::string, std::string>>& overrides) {
    Scene scene = load_scene(file, to_overrides(overrides));
    warn(scene);
    return scene;
  });
  m.def("_load_scene_text", [](const std::string& text, const std::string& name, const std::string& base_dir,
                               const std::vector<std::pair<std::string, std::string>>& overrides) {
    Scene scene = load_scene_text(text, name, base_dir, to_overrides(overrides));
    warn(scene);
    return scene;
  });

  py::class_<PyWorld>(m, "World", "A simulation world built from a scene, its modules loaded by name")
      .def(py::init<const Scene&>(), py::arg("scene"))
      .def("step", &PyWorld::step, py::arg("n") = 1,
           "Takes n steps (without the GIL) and returns the last step's status; raises impetus.Error as "
           "`impetus run` fails (the world is left at its state before the failing step)")
      .def_property_readonly("status", &PyWorld::status)
      .def_property_readonly("time", [](PyWorld& w) { return w.world().time(); })
      .def_property_readonly("step_count", [](PyWorld& w) { return w.world().step_count(); })
      .def_property_readonly("dt", [](PyWorld& w) { return w.world().settings().dt; })
      .def_property(
          "threads", [](PyWorld& w) { return w.world().threads(); },
          [](PyWorld& w, std::int64_t n) {
            if (n < 0 || n > static_cast<std::int64_t>(World::kMaxThreads))
              throw Error("World.threads: must be 0 (every core) to " + std::to_string(World::kMaxThreads) +
                          ", got " + std::to_string(n));
            w.world().set_threads(static_cast<std::uint32_t>(n));
          },
          "Threads a step may use (the scene's `threads`; 0: every core). Trajectories are bit-identical "
          "for every value; set it between steps")
      .def_property_readonly("names", &PyWorld::names)
      .def_property_readonly("scene", &PyWorld::scene)
      .def("state", &PyWorld::state)
      .def("set_state", &PyWorld::set_state, py::arg("state"))
      .def("contacts", &PyWorld::contacts)
      .def("_summary", &PyWorld::summary)
      .def("set_load", &PyWorld::set_load, py::arg("body"), py::arg("force") = py::none(), py::arg("torque") = py::none())
      .def("__len__", [](PyWorld& w) { return w.world().bodies().size(); });

  m.def("measure", &measure_world, py::arg("world"),
        "Kinetic and potential energy (J), linear and angular momentum about the origin, the deepest "
        "penetration and the number of contacts of the last detection");
  m.def("_resolve", [](const Scene& scene) { return cli::resolve_scene(scene).dump(); });
  m.def("_plugins", [] {
    PluginHost host;
    return cli::plugins_report(host.discover()).dump();
  });
  m.def("_mass", [](const std::string& file, std::optional<double> density, std::optional<double> mass, double scale,
                    const std::string& part) {
    cli::MassArgs args;
    args.mesh = file;
    args.density = density;
    args.mass = mass;
    args.scale = scale;
    args.part = part;
    return cli::mass_json(args, cli::compute_mass(args)).dump();
  });
}
