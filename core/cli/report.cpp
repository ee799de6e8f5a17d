#include "report.hpp"

#include "impetus/core/error.hpp"
#include "impetus/core/format.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <type_traits>
#include <variant>
#include <ostream>

namespace impetus::cli {
namespace {

using nlohmann::json;

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

// Shortest round-trip text of a double, so CSV output is bit-exact.
void append_number(std::string& line, double x) { line += format_number(x); }

// A name as a CSV field (RFC 4180): quoted, with quotes doubled, when it holds a comma or a quote.
// (Names with line breaks or other control characters are refused when a body is added.)
void append_csv_text(std::string& line, const std::string& text) {
  if (text.find_first_of(",\"") == std::string::npos) {
    line += text;
    return;
  }
  line += '"';
  for (char c : text) {
    if (c == '"') line += '"';
    line += c;
  }
  line += '"';
}

}  // namespace

RunStats::RunStats(const World& world) : initial_(measure(world)) {
  for (const RigidBody& b : world.bodies()) {
    initial_positions_.push_back(b.position);
    if (!b.fixed) total_mass_ += b.mass;
    frictional_ = frictional_ || b.material.friction > 0.0;
  }
}

void RunStats::before_step(const World& world) {
  const double dt = world.settings().dt;
  const Vec3 g = world.settings().gravity;
  gravity_impulse_ += dt * total_mass_ * g;
  for (const RigidBody& b : world.bodies()) {
    if (b.fixed) continue;
    gravity_moment_ += dt * b.position.cross(b.mass * g);
    const Vec3 force = b.applied_force();
    load_impulse_ += dt * force;
    load_moment_ += dt * (b.position.cross(force) + b.applied_torque());
  }
  step_kinetic_ = total_kinetic_energy(world.bodies());
  step_potential_ = load_potential_energy(world.bodies(), g);
}

// The step's integration remainder is the change of kinetic + load potential energy outside the resolve
// stage, less the work of torques and body-frame forces. Where the step's contacts dissipated energy, a gain up to that much
// is the split step's exchange (velocities before contacts), set apart so that it is not flagged.
void RunStats::add_integration_step(const World& world, const StepStatus& status, double step_load_work) {
  const double kinetic = total_kinetic_energy(world.bodies());
  const double potential = load_potential_energy(world.bodies(), world.settings().gravity);
  kinetic_after_ = kinetic;
  potential_after_ = potential;
  const double remainder = (kinetic - step_kinetic_) + (potential - step_potential_) -
                           status.resolve_kinetic_energy_change - status.resolve_potential_energy_change -
                           step_load_work;
  // What the step's contacts dissipated: their kinetic energy change less the work moving fixed bodies
  // did through them (a belt's push and the gravity kick its contact takes back happen in one step).
  const double taken_back = std::max(0.0, status.prescribed_work - status.resolve_kinetic_energy_change);
  contact_exchange_ += std::clamp(remainder, 0.0, taken_back);
}

const char* RunStats::non_finite() const {
  if (!std::isfinite(kinetic_after_)) return "kinetic energy";
  if (!std::isfinite(potential_after_)) return "potential energy of gravity and loads";
  if (!std::isfinite(contact_energy_change_) || !std::isfinite(correction_energy_) ||
      !std::isfinite(prescribed_work_) || !std::isfinite(contact_exchange_))
    return "energy exchanged by contacts";
  if (!std::isfinite(step_load_work_)) return "work of applied loads";
  if (!all_finite(gravity_impulse_) || !all_finite(gravity_moment_) || !all_finite(load_impulse_) ||
      !all_finite(load_moment_) || !all_finite(fixed_impulse_) || !all_finite(fixed_moment_))
    return "momentum balance";
  return nullptr;
}

// Contact convention (modules/contact.hpp): the impulse P = p n + p_t acts +P on b and −P on a. Only a
// movable body's share counts: what it receives from a fixed body enters the system from outside.
void RunStats::add_fixed_body_impulses(const World& world) {
  const auto bodies = world.bodies();
  for (const Contact& c : world.contacts()) {
    const bool a_fixed = bodies[c.a].fixed, b_fixed = bodies[c.b].fixed;
    if (a_fixed == b_fixed) continue;  // internal (cancels) or between two fixed bodies (acts on nothing)
    const Vec3 impulse = c.impulse * c.normal + c.tangent_impulse;
    const Vec3 received = a_fixed ? impulse : Vec3(-impulse);
    fixed_impulse_ += received;
    fixed_moment_ += c.point.cross(received);
  }
}

void RunStats::add_step(const World& world, const StepStatus& status) {
  time_.velocities += status.profile.velocities;
  time_.detect += status.profile.detect;
  time_.resolve += status.profile.resolve;
  time_.positions += status.profile.positions;
  time_.total += status.profile.total;
  const std::uint64_t contacts = world.contacts().size();
  ++steps_;
  contacts_ += contacts;
  max_contacts_ = std::max(max_contacts_, contacts);
  rounds_ += status.resolver.rounds;
  max_rounds_ = std::max(max_rounds_, status.resolver.rounds);
  non_converged_ += status.resolver.non_converged;
  singular_ += status.resolver.singular_systems;
  redundant_ += status.resolver.redundant_systems;
  work_limited_ += status.resolver.work_limited;
  speculative_ += status.detector.speculative_pairs;
  clamped_ += status.resolver.corrections_clamped;
  largest_correction_ = std::max(largest_correction_, status.resolver.largest_correction);
  pulling_ += status.resolver.pulling_impulses;
  energy_gains_ += status.resolver.energy_gain_events;
  sticking_ += status.resolver.sticking;
  sliding_ += status.resolver.sliding;
  friction_work_ += status.resolver.friction_work;
  max_natural_map_ = std::max(max_natural_map_, status.resolver.natural_map_residual);
  max_residual_ = std::max(max_residual_, status.resolver.residual);
  for (const Contact& c : world.contacts()) max_penetration_ = std::max(max_penetration_, c.depth);
  contact_energy_change_ += status.resolve_kinetic_energy_change;
  contact_energy_scale_ += std::abs(status.resolve_kinetic_energy_change);
  correction_energy_ += status.resolve_potential_energy_change;
  prescribed_work_ += status.prescribed_work;
  sleeping_now_ = status.sleeping_bodies;
  max_sleeping_ = std::max(max_sleeping_, status.sleeping_bodies);
  woken_ += status.woken_bodies;
  add_fixed_body_impulses(world);
  // Loads without a potential: torques and body-frame forces, dt (F·v + τ·ω) per step.
  double step_load_work = 0.0;
  for (const RigidBody& b : world.bodies())
    if (!b.fixed)
      step_load_work += world.settings().dt * ((b.rotation * b.force_body).dot(b.velocity) +
                                               b.applied_torque().dot(b.angular_velocity));
  step_load_work_ += step_load_work;
  add_integration_step(world, status, step_load_work);
}

// The energy balance ΔKE = contacts + position correction + gravity + loads + integration. Gravity and
// constant world-frame forces do work m g·Δx and F·Δx over the run; torques and body-frame forces
// dt (F·v + τ·ω) per step. Contacts with fixed bodies that move do work Σ P·u (the prescribed motion's
// work), set apart from what contacts dissipate. Integration is what none of them explains, and the only
// part called drift.
json RunStats::energy_summary(const World& world) const {
  const WorldMetrics now = measure(world);
  const auto bodies = world.bodies();
  const Vec3 g = world.settings().gravity;
  double gravity_work = 0.0, force_work = 0.0, scale = std::max(initial_.kinetic_energy, now.kinetic_energy);
  for (std::size_t i = 0; i < bodies.size() && i < initial_positions_.size(); ++i) {
    if (bodies[i].fixed) continue;
    const Vec3 moved = bodies[i].position - initial_positions_[i];
    gravity_work += bodies[i].mass * g.dot(moved);
    force_work += bodies[i].force.dot(moved);
  }
  const double load_work = force_work + step_load_work_;
  const double dissipated = prescribed_work_ - contact_energy_change_;
  const double integration = now.kinetic_energy - initial_.kinetic_energy - contact_energy_change_ -
                             correction_energy_ - gravity_work - load_work;
  // Rounding: each step's sums round at ~1e-16 of the energies involved; 1e-9 leaves a wide margin.
  scale = std::max({scale, contact_energy_scale_, std::abs(gravity_work), std::abs(load_work),
                    std::abs(correction_energy_), std::abs(prescribed_work_)});
  const double rounding = std::max(1e-9, 1e-15 * static_cast<double>(steps_)) * scale;
  json unexpected = json::array();
  if (-dissipated > rounding)
    unexpected.push_back("contacts gained " + format_number(-dissipated) + " J beyond the work of moving fixed bodies");
  // Net: a bounded, oscillating integration error (splitting) is not a gain unless it ends as one.
  const double integration_gain = integration - contact_exchange_;
  if (integration_gain > rounding)
    unexpected.push_back("integration gained " + format_number(integration_gain) +
                         " J beyond what contacts took back in the same steps");
  const double e0 = total_energy(initial_), e1 = total_energy(now);
  return json{{"initial_j", e0},
              {"final_j", e1},
              {"change_j", e1 - e0},
              {"kinetic_final_j", now.kinetic_energy},
              {"dissipated_by_contacts_j", dissipated},
              {"prescribed_motion_work_j", prescribed_work_},
              {"position_correction_j", correction_energy_},
              {"gravity_work_j", gravity_work},
              {"applied_load_work_j", load_work},
              {"integration_j", integration},
              {"drift_j", integration},
              {"integration_gain_j", integration_gain},
              {"contact_exchange_j", contact_exchange_},
              {"unexpected", unexpected}};
}

// Δp = gravity + applied loads + impulses from fixed bodies + drift; the same for L about the origin.
json RunStats::momentum_summary(const World& world) const {
  const WorldMetrics now = measure(world);
  const Vec3 dp = now.linear_momentum - initial_.linear_momentum;
  const Vec3 dl = now.angular_momentum - initial_.angular_momentum;
  const Vec3 linear_drift = dp - gravity_impulse_ - load_impulse_ - fixed_impulse_;
  const Vec3 angular_drift = dl - gravity_moment_ - load_moment_ - fixed_moment_;
  return json{{"linear_change_kg_m_per_s", vec(dp)},
              {"angular_change_kg_m2_per_s", vec(dl)},
              {"gravity_impulse_n_s", vec(gravity_impulse_)},
              {"gravity_moment_n_m_s", vec(gravity_moment_)},
              {"applied_load_impulse_n_s", vec(load_impulse_)},
              {"applied_load_moment_n_m_s", vec(load_moment_)},
              {"fixed_body_impulse_n_s", vec(fixed_impulse_)},
              {"fixed_body_moment_n_m_s", vec(fixed_moment_)},
              {"linear_drift_kg_m_per_s", vec(linear_drift)},
              {"angular_drift_kg_m2_per_s", vec(angular_drift)}};
}

json RunStats::summary(const World& world, double wall_seconds) const {
  const double steps = static_cast<double>(std::max<std::uint64_t>(steps_, 1));
  const json momentum = momentum_summary(world);
  const auto norm = [&momentum](const char* key) {
    const auto& v = momentum[key];
    return Vec3(v[0].get<double>(), v[1].get<double>(), v[2].get<double>()).norm();
  };
  return json{
      {"steps", steps_},
      {"bodies", world.bodies().size()},
      {"simulated_time_s", world.time()},
      {"wall_time_s", wall_seconds},
      {"time_per_step_s", time_.total / steps},
      {"module_time_s",
       {{"integrate_velocities", time_.velocities},
        {"detect", time_.detect},
        {"resolve", time_.resolve},
        {"integrate_positions", time_.positions}}},
      {"contacts_per_step",
       {{"mean", static_cast<double>(contacts_) / steps}, {"max", max_contacts_}, {"speculative_pairs", speculative_}}},
      {"resolver",
       {{"rounds", rounds_},
        {"max_rounds_per_step", max_rounds_},
        {"non_converged", non_converged_},
        {"singular_systems", singular_},
        {"redundant_systems", redundant_},
        {"pulling_impulses", pulling_},
        {"energy_gain_events", energy_gains_},
        {"max_residual_m_per_s", max_residual_},
        {"max_natural_map_residual", max_natural_map_},
        {"work_limited", work_limited_},
        {"corrections_clamped", clamped_},
        {"largest_correction_m", largest_correction_}}},
      {"friction",
       {{"modelled", frictional_},
        {"sticking_contacts", sticking_}, {"sliding_contacts", sliding_},
        {"dissipated_j", 0.0 - friction_work_}}},
      {"sleep",
       {{"enabled", world.settings().sleep.enabled},
        {"sleeping_final", sleeping_now_},
        {"max_sleeping", max_sleeping_},
        {"woken", woken_}}},
      {"energy", energy_summary(world)},
      {"momentum", momentum},
      // The change gravity, applied loads and fixed bodies' impulses do not explain (README.md).
      {"linear_momentum_drift", norm("linear_drift_kg_m_per_s")},
      {"angular_momentum_drift", norm("angular_drift_kg_m2_per_s")},
      {"max_penetration_m", max_penetration_},
  };
}

namespace {

// "ledas (mode: paper)": the plugin and the options the scene or command line gave it.
std::string module_label(const json& summary, const char* kind) {
  std::string label = summary["modules"][kind].get<std::string>();
  const json options = summary.value("module_options", json::object()).value(kind, json::object());
  if (options.empty()) return label;
  label += " (";
  bool first = true;
  for (const auto& [key, value] : options.items()) {
    label += (first ? "" : ", ") + key + ": " + (value.is_string() ? value.get<std::string>() : value.dump());
    first = false;
  }
  return label + ")";
}

void print_energy(const json& e, std::ostream& out) {
  out << "energy                " << e["initial_j"].get<double>() << " J -> " << e["final_j"].get<double>()
      << " J: " << 0.0 + e["dissipated_by_contacts_j"].get<double>() << " J dissipated by contacts, "
      << e["gravity_work_j"].get<double>() << " J work of gravity";
  if (e["applied_load_work_j"].get<double>() != 0.0)
    out << ", " << e["applied_load_work_j"].get<double>() << " J work of applied loads";
  if (e["prescribed_motion_work_j"].get<double>() != 0.0)
    out << ", " << e["prescribed_motion_work_j"].get<double>() << " J work of moving fixed bodies";
  if (e["position_correction_j"].get<double>() != 0.0)
    out << ", " << e["position_correction_j"].get<double>() << " J from position correction";
  const double integration = e["integration_j"].get<double>();
  out << ", " << std::abs(integration) << " J " << (integration > 0.0 ? "gained" : "lost") << " by integration";
  // A gain the contacts took back within the same steps is the split step's exchange (README.md).
  if (integration > 0.0 && e["contact_exchange_j"].get<double>() > 0.0 && e["unexpected"].empty())
    out << " (taken back by contacts in the same steps)";
  out << "\n";
  for (const auto& what : e["unexpected"]) out << "  unexpected:         " << what.get<std::string>() << "\n";
}

}  // namespace

void print_summary(const json& s, std::ostream& out) {
  const auto& t = s["module_time_s"];
  const auto& r = s["resolver"];
  const auto& m = s["momentum"];
  const auto norm = [&m](const char* key) {
    const auto& v = m[key];
    return Vec3(v[0].get<double>(), v[1].get<double>(), v[2].get<double>()).norm();
  };
  out << std::setprecision(6);
  if (s.contains("scene")) out << "scene                 " << s["scene"].get<std::string>() << "\n";
  if (s.contains("modules")) {
    out << "modules               integrator " << module_label(s, "integrator") << ", detector "
        << module_label(s, "detector") << ", resolver " << module_label(s, "resolver") << "\n";
  }
  out << "steps                 " << s["steps"].get<std::uint64_t>() << " (" << s["bodies"].get<std::size_t>()
      << " bodies)\n"
      << "simulated time        " << s["simulated_time_s"].get<double>() << " s\n"
      << "wall time             " << s["wall_time_s"].get<double>() << " s ("
      << 1e6 * s["time_per_step_s"].get<double>() << " us per step)\n"
      << "time per module       integrate " << t["integrate_velocities"].get<double>() + t["integrate_positions"].get<double>()
      << " s, detect " << t["detect"].get<double>() << " s, resolve " << t["resolve"].get<double>() << " s\n"
      << "contacts per step     mean " << s["contacts_per_step"]["mean"].get<double>() << ", max "
      << s["contacts_per_step"]["max"].get<std::uint64_t>();
  if (!s["contacts_per_step"].value("resolved", true)) out << " (detected, not resolved: resolver none)";
  if (const std::uint64_t n = s["contacts_per_step"].value("speculative_pairs", std::uint64_t{0}); n > 0)
    out << "; " << n << " pair tests looked ahead for fast bodies (speculative contacts)";
  out << "\n"
      << "resolver              " << r["rounds"].get<std::uint64_t>() << " rounds (max "
      << r["max_rounds_per_step"].get<std::uint64_t>() << " per step), " << r["non_converged"].get<std::uint64_t>()
      << " non-converged, " << r["singular_systems"].get<std::uint64_t>() << " singular (failed), "
      << r["redundant_systems"].get<std::uint64_t>() << " redundant contact sets (minimum-norm), "
      << r["energy_gain_events"].get<std::uint64_t>() << " energy gains, max residual "
      << r["max_residual_m_per_s"].get<double>() << " m/s\n";
  // Pathological scenes (README.md, "Reliability"): a solve stopped by its work budget, a position
  // correction bounded. Shown only when it happened.
  if (r["work_limited"].get<std::uint64_t>() > 0 || r["corrections_clamped"].get<std::uint64_t>() > 0)
    out << "resolver limits       " << r["work_limited"].get<std::uint64_t>() << " solves stopped by the work budget, "
        << r["corrections_clamped"].get<std::uint64_t>() << " position corrections clamped (largest "
        << r["largest_correction_m"].get<double>() << " m)\n";
  // Without friction the stick/slide counts only say whether a contact's tangential velocity was zero.
  if (s["friction"].value("modelled", true))
    out << "friction              " << s["friction"]["sticking_contacts"].get<std::uint64_t>() << " sticking and "
        << s["friction"]["sliding_contacts"].get<std::uint64_t>() << " sliding contacts (summed over steps), "
        << s["friction"]["dissipated_j"].get<double>() << " J dissipated, max natural-map residual "
        << r["max_natural_map_residual"].get<double>() << "\n";
  else
    out << "friction              none: every body has friction 0, so contacts slide freely\n";
  if (s.contains("sleep") && s["sleep"]["enabled"].get<bool>())
    out << "sleeping              " << s["sleep"]["sleeping_final"].get<std::uint64_t>() << " bodies asleep at the end (at most "
        << s["sleep"]["max_sleeping"].get<std::uint64_t>() << "), " << s["sleep"]["woken"].get<std::uint64_t>()
        << " woken up\n";
  print_energy(s["energy"], out);
  out << "momentum              from fixed bodies: linear " << norm("fixed_body_impulse_n_s") << " N s, angular "
      << norm("fixed_body_moment_n_m_s") << " N m s; drift (unexplained): linear "
      << s["linear_momentum_drift"].get<double>() << " kg m/s, angular " << s["angular_momentum_drift"].get<double>()
      << " kg m^2/s\n"
      << "max penetration       " << s["max_penetration_m"].get<double>() << " m\n";
}

void check_output_path(const std::filesystem::path& out, bool overwrite, const std::filesystem::path& input,
                       const std::string& option) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const std::string name = option + " " + out.string();
  if (fs::is_symlink(fs::symlink_status(out, ec)) && !fs::exists(out, ec))
    throw Error(name + ": is a symbolic link to '" + fs::read_symlink(out, ec).string() +
                "', which does not exist; Impetus does not create files through a dangling link");
  if (!fs::exists(out, ec)) {
    const fs::path folder = out.parent_path();
    if (!folder.empty() && !fs::is_directory(folder, ec))
      throw Error(name + ": the folder '" + folder.string() + "' does not exist (Impetus creates files, not folders)");
    return;
  }
  if (fs::is_directory(out, ec)) throw Error(name + ": is a directory");
  if (!input.empty() && fs::equivalent(out, input, ec))
    throw Error(name + ": is the scene being read; an input is never overwritten by an output");
  if (!overwrite) throw Error(name + ": file exists; pass --overwrite to replace it");
}

void checked_step(World& world, RunStats& stats, const std::string& scene_file) {
  stats.before_step(world);
  const StepStatus& status = world.step();
  if (!status.ok) throw Error(scene_file + ": " + status.message);
  stats.add_step(world, status);
  if (const char* what = stats.non_finite())
    throw Error(scene_file + ": step " + std::to_string(world.step_count()) + " (t = " + format_number(world.time()) +
                " s): the run's " + what +
                " is no longer finite (velocities, masses or the time step too large to square)");
}

nlohmann::json options_json(const ModuleOptions& options) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [key, value] : options.values())
    out[key] = value.is_list ? nlohmann::json(value.items) : nlohmann::json(value.text);
  return out;
}

nlohmann::json run_summary(const Scene& scene, const World& world, const RunStats& stats, double wall_seconds) {
  nlohmann::json summary = stats.summary(world, wall_seconds);
  summary["scene"] = scene.file.string();
  summary["modules"] = {{"integrator", scene.integrator.plugin},
                        {"detector", scene.detector.plugin},
                        {"resolver", scene.resolver.plugin}};
  summary["module_options"] = {{"integrator", options_json(scene.integrator.options)},
                               {"detector", options_json(scene.detector.options)},
                               {"resolver", options_json(scene.resolver.options)}};
  // Without a resolver the detector still runs (World::contacts() shows what it found): say so.
  summary["contacts_per_step"]["resolved"] = world.has_resolver() || !world.has_detector();
  return summary;
}

nlohmann::json resolve_scene(const Scene& scene) {
  PluginHost host;
  std::unique_ptr<World> world = build_world(scene, host);
  if (!world->has_detector() || !world->has_resolver())
    throw Error(scene.file.string() + ": resolve needs a detector and a resolver (modules.detector and "
                "modules.resolver are 'none')");
  const StepStatus& status = world->detect_and_resolve();
  if (!status.ok) throw Error(scene.file.string() + ": " + status.message);
  return resolve_report(*world, scene.resolver.plugin, status.profile.resolve);
}

void write_file(const std::filesystem::path& file, std::string_view data) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(file.string() + ": cannot open for writing");
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  out.flush();
  out.close();
  if (!out) throw Error(file.string() + ": writing failed (the device is full or the file cannot be written)");
}

CsvFile::CsvFile(const std::filesystem::path& file, bool overwrite, const std::filesystem::path& input,
                 const std::string& option, const std::string& header)
    : file_(file) {
  check_output_path(file, overwrite, input, option);
  out_.open(file, std::ios::out | std::ios::trunc);
  if (!out_) throw Error(file.string() + ": cannot open for writing");
  put(header);
}

void CsvFile::put(const std::string& text) {
  out_ << text;
  if (!out_) throw Error(file_.string() + ": writing failed (the device is full or the file cannot be written)");
}

void CsvFile::finish() {
  out_.flush();
  out_.close();
  if (!out_) throw Error(file_.string() + ": writing failed (the device is full or the file cannot be written)");
}

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& file, bool overwrite,
                                   const std::filesystem::path& input)
    : csv_(file, overwrite, input, "--out", "step,time,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n") {}

void TrajectoryWriter::write(const World& world) {
  std::string lines, step_time;
  step_time += std::to_string(world.step_count());
  step_time += ',';
  append_number(step_time, world.time());
  step_time += ',';
  for (const RigidBody& b : world.bodies()) {
    lines += step_time;
    append_csv_text(lines, b.name);
    const Quat q = b.orientation();
    const double values[] = {b.position.x(), b.position.y(), b.position.z(), q.w(), q.x(), q.y(), q.z(),
                             b.velocity.x(), b.velocity.y(), b.velocity.z(), b.angular_velocity.x(),
                             b.angular_velocity.y(), b.angular_velocity.z()};
    for (double v : values) {
      lines += ',';
      append_number(lines, v);
    }
    lines += '\n';
  }
  csv_.put(lines);
}

ContactWriter::ContactWriter(const std::filesystem::path& file, bool overwrite, const std::filesystem::path& input)
    : csv_(file, overwrite, input, "--contacts", "step,time,a,b,x,y,z,nx,ny,nz,depth,impulse,tx,ty,tz,mode\n") {}

void ContactWriter::write(const World& world) {
  const auto bodies = world.bodies();
  std::string lines, step_time;
  step_time += std::to_string(world.step_count());
  step_time += ',';
  append_number(step_time, world.time());
  step_time += ',';
  for (const Contact& c : world.contacts()) {
    lines += step_time;
    append_csv_text(lines, bodies[c.a].name);
    lines += ',';
    append_csv_text(lines, bodies[c.b].name);
    const double values[] = {c.point.x(),  c.point.y(), c.point.z(), c.normal.x(),          c.normal.y(),
                             c.normal.z(), c.depth,     c.impulse,   c.tangent_impulse.x(), c.tangent_impulse.y(),
                             c.tangent_impulse.z()};
    for (double v : values) {
      lines += ',';
      append_number(lines, v);
    }
    lines += ',';
    lines += contact_mode_name(c.mode);
    lines += '\n';
  }
  csv_.put(lines);
}

std::filesystem::path body_table_path(const std::filesystem::path& trajectory) {
  std::filesystem::path out = trajectory;
  if (out.extension() == ".csv") out.replace_extension();
  out += ".bodies.csv";
  return out;
}

void write_body_table(const std::filesystem::path& file, bool overwrite, const std::filesystem::path& input,
                      const World& world) {
  CsvFile csv(file, overwrite, input, "--out (its body table)",
              "name,mass,fixed,shape,radius,length,size_x,size_y,size_z,normal_x,normal_y,normal_z,offset,"
              "mesh,scale,collision\n");
  std::string lines;
  for (const RigidBody& b : world.bodies()) {
    append_csv_text(lines, b.name);
    lines += ',';
    append_number(lines, b.fixed ? 0.0 : b.mass);
    lines += b.fixed ? ",true," : ",false,";
    lines += shape_kind_name(b.shape);
    // radius,length | size_x,size_y,size_z | normal_x,normal_y,normal_z,offset | mesh,scale,collision
    std::string fields[12];
    const auto number = [](double x) { return format_number(x); };
    std::visit(
        [&](const auto& shape) {
          using T = std::decay_t<decltype(shape)>;
          if constexpr (std::is_same_v<T, Sphere>) {
            fields[0] = number(shape.radius);
          } else if constexpr (std::is_same_v<T, Capsule> || std::is_same_v<T, Cylinder>) {
            fields[0] = number(shape.radius);
            fields[1] = number(shape.length);
          } else if constexpr (std::is_same_v<T, Box>) {
            for (int i = 0; i < 3; ++i) fields[2 + i] = number(shape.size[i]);
          } else if constexpr (std::is_same_v<T, Plane>) {
            for (int i = 0; i < 3; ++i) fields[5 + i] = number(shape.normal[i]);
            fields[8] = number(shape.offset);
          } else if constexpr (std::is_same_v<T, MeshShape>) {
            std::string file_field;
            append_csv_text(file_field, shape.file.string());
            fields[9] = file_field;
            fields[10] = number(shape.scale);
            fields[11] = shape.collision == MeshCollision::convex ? "convex" : "triangles";
          }
        },
        b.shape);
    for (const std::string& f : fields) {
      lines += ',';
      lines += f;
    }
    lines += '\n';
  }
  csv.put(lines);
  csv.finish();
}

json resolve_report(const World& world, const std::string& resolver, double seconds) {
  const auto bodies = world.bodies();
  json contacts = json::array();
  for (const Contact& c : world.contacts())
    contacts.push_back({{"a", bodies[c.a].name}, {"b", bodies[c.b].name}, {"point", vec(c.point)},
                        {"normal", vec(c.normal)}, {"depth", c.depth}, {"impulse", c.impulse},
                        {"tangent_impulse", vec(c.tangent_impulse)}, {"mode", contact_mode_name(c.mode)}});
  json out_bodies = json::array();
  for (const RigidBody& b : bodies)
    out_bodies.push_back({{"name", b.name}, {"velocity", vec(b.velocity)},
                          {"angular_velocity", vec(b.angular_velocity)}});
  const StepStatus& s = world.last_status();
  return json{{"resolver", resolver},
              {"iterations", s.resolver.rounds},
              {"time_s", seconds},
              {"residual", s.resolver.residual},
              {"pulling_impulses", s.resolver.pulling_impulses},
              {"singular_systems", s.resolver.singular_systems},
              {"redundant_systems", s.resolver.redundant_systems},
              {"energy_gain_events", s.resolver.energy_gain_events},
              {"natural_map_residual", s.resolver.natural_map_residual},
              {"sticking", s.resolver.sticking},
              {"sliding", s.resolver.sliding},
              {"friction_work_j", s.resolver.friction_work},
              {"contacts", contacts},
              {"bodies", out_bodies}};
}

json plugins_report(const PluginListing& listing) {
  json plugins = json::array(), failures = json::array(), searched = json::array();
  for (const auto& dir : listing.searched) searched.push_back(dir.string());
  for (const PluginInfo& p : listing.plugins)
    plugins.push_back({{"kind", module_kind_name(p.kind)}, {"name", p.name}, {"version", p.version},
                       {"summary", p.summary}, {"path", p.path.string()}, {"shadowed", p.shadowed}});
  for (const PluginFailure& f : listing.failures)
    failures.push_back({{"path", f.path.string()}, {"reason", f.reason}});
  return json{{"searched", searched}, {"plugins", plugins}, {"failures", failures}};
}

void print_plugins(const PluginListing& listing, std::ostream& out) {
  out << "searched:\n";
  for (const auto& dir : listing.searched) out << "  " << dir.string() << "\n";
  out << "plugins:\n";
  std::size_t name_width = 4, version_width = 7;
  for (const PluginInfo& p : listing.plugins) {
    name_width = std::max(name_width, p.name.size());
    version_width = std::max(version_width, p.version.size());
  }
  for (const PluginInfo& p : listing.plugins) {
    out << "  " << std::left << std::setw(11) << module_kind_name(p.kind) << std::setw(static_cast<int>(name_width + 2))
        << p.name << std::setw(static_cast<int>(version_width + 2)) << p.version << p.path.string()
        << (p.shadowed ? "  (shadowed)" : "") << "\n"
        << "  " << std::string(11 + name_width + 2 + version_width + 2, ' ') << p.summary << "\n";
  }
  if (listing.plugins.empty()) out << "  (none)\n";
  if (!listing.failures.empty()) {
    out << "failed to load:\n";
    for (const PluginFailure& f : listing.failures) out << "  " << f.path.string() << ": " << f.reason << "\n";
  }
}

}  // namespace impetus::cli
