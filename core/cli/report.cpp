#include "report.hpp"

#include "impetus/core/error.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdio>
#include <iomanip>
#include <ostream>

namespace impetus::cli {
namespace {

using nlohmann::json;

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

// Shortest round-trip text of a double (std::to_chars), so CSV output is bit-exact.
void append_number(std::string& line, double x) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  line.append(buffer.data(), result.ptr);
}

}  // namespace

RunStats::RunStats(const World& world) : initial_(measure(world)) {
  for (const RigidBody& b : world.bodies())
    if (!b.fixed) total_mass_ += b.mass;
}

void RunStats::before_step(const World& world) {
  const double dt = world.settings().dt;
  const Vec3 g = world.settings().gravity;
  gravity_impulse_ += dt * total_mass_ * g;
  for (const RigidBody& b : world.bodies())
    if (!b.fixed) gravity_moment_ += dt * b.position.cross(b.mass * g);
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
  pulling_ += status.resolver.pulling_impulses;
  energy_gains_ += status.resolver.energy_gain_events;
  sticking_ += status.resolver.sticking;
  sliding_ += status.resolver.sliding;
  friction_work_ += status.resolver.friction_work;
  max_natural_map_ = std::max(max_natural_map_, status.resolver.natural_map_residual);
  max_residual_ = std::max(max_residual_, status.resolver.residual);
  for (const Contact& c : world.contacts()) max_penetration_ = std::max(max_penetration_, c.depth);
}

json RunStats::summary(const World& world, double wall_seconds) const {
  const WorldMetrics now = measure(world);
  const double e0 = total_energy(initial_), e1 = total_energy(now);
  const double steps = static_cast<double>(std::max<std::uint64_t>(steps_, 1));
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
      {"contacts_per_step", {{"mean", static_cast<double>(contacts_) / steps}, {"max", max_contacts_}}},
      {"resolver",
       {{"rounds", rounds_},
        {"max_rounds_per_step", max_rounds_},
        {"non_converged", non_converged_},
        {"singular_systems", singular_},
        {"pulling_impulses", pulling_},
        {"energy_gain_events", energy_gains_},
        {"max_residual_m_per_s", max_residual_},
        {"max_natural_map_residual", max_natural_map_}}},
      {"friction",
       {{"sticking_contacts", sticking_}, {"sliding_contacts", sliding_},
        {"dissipated_j", -friction_work_}}},
      {"energy",
       {{"initial_j", e0}, {"final_j", e1}, {"drift_j", e1 - e0},
        {"kinetic_final_j", now.kinetic_energy}}},
      // Momentum drift: the change not explained by gravity (contacts with fixed bodies also count).
      {"linear_momentum_drift", (now.linear_momentum - initial_.linear_momentum - gravity_impulse_).norm()},
      {"angular_momentum_drift", (now.angular_momentum - initial_.angular_momentum - gravity_moment_).norm()},
      {"max_penetration_m", max_penetration_},
  };
}

void print_summary(const json& s, std::ostream& out) {
  const auto& t = s["module_time_s"];
  const auto& r = s["resolver"];
  const auto& e = s["energy"];
  out << std::setprecision(6);
  out << "steps                 " << s["steps"].get<std::uint64_t>() << " (" << s["bodies"].get<std::size_t>()
      << " bodies)\n"
      << "simulated time        " << s["simulated_time_s"].get<double>() << " s\n"
      << "wall time             " << s["wall_time_s"].get<double>() << " s ("
      << 1e6 * s["time_per_step_s"].get<double>() << " us per step)\n"
      << "time per module       integrate " << t["integrate_velocities"].get<double>() + t["integrate_positions"].get<double>()
      << " s, detect " << t["detect"].get<double>() << " s, resolve " << t["resolve"].get<double>() << " s\n"
      << "contacts per step     mean " << s["contacts_per_step"]["mean"].get<double>() << ", max "
      << s["contacts_per_step"]["max"].get<std::uint64_t>() << "\n"
      << "resolver              " << r["rounds"].get<std::uint64_t>() << " rounds (max "
      << r["max_rounds_per_step"].get<std::uint64_t>() << " per step), " << r["non_converged"].get<std::uint64_t>()
      << " non-converged, " << r["singular_systems"].get<std::uint64_t>() << " singular, "
      << r["energy_gain_events"].get<std::uint64_t>() << " energy gains, max residual "
      << r["max_residual_m_per_s"].get<double>() << " m/s\n"
      << "friction              " << s["friction"]["sticking_contacts"].get<std::uint64_t>() << " sticking and "
      << s["friction"]["sliding_contacts"].get<std::uint64_t>() << " sliding contacts (summed over steps), "
      << s["friction"]["dissipated_j"].get<double>() << " J dissipated, max natural-map residual "
      << r["max_natural_map_residual"].get<double>() << "\n"
      << "energy                " << e["initial_j"].get<double>() << " J -> " << e["final_j"].get<double>()
      << " J (drift " << e["drift_j"].get<double>() << " J)\n"
      << "momentum drift        linear " << s["linear_momentum_drift"].get<double>() << " kg m/s, angular "
      << s["angular_momentum_drift"].get<double>() << " kg m^2/s (beyond gravity; contacts with fixed bodies count too)\n"
      << "max penetration       " << s["max_penetration_m"].get<double>() << " m\n";
}

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& file, bool overwrite) : file_(file) {
  std::error_code ec;
  if (!overwrite && std::filesystem::exists(file, ec))
    throw Error(file.string() + ": file exists; pass --overwrite to replace it");
  out_.open(file, std::ios::out | std::ios::trunc);
  if (!out_) throw Error(file.string() + ": cannot open for writing");
  out_ << "step,time,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n";
}

void TrajectoryWriter::write(const World& world) {
  std::string line;
  for (const RigidBody& b : world.bodies()) {
    line.clear();
    line += std::to_string(world.step_count());
    line += ',';
    append_number(line, world.time());
    line += ',';
    line += b.name;
    const Quat q = b.orientation();
    const double values[] = {b.position.x(), b.position.y(), b.position.z(), q.w(), q.x(), q.y(), q.z(),
                             b.velocity.x(), b.velocity.y(), b.velocity.z(), b.angular_velocity.x(),
                             b.angular_velocity.y(), b.angular_velocity.z()};
    for (double v : values) {
      line += ',';
      append_number(line, v);
    }
    line += '\n';
    out_ << line;
  }
  if (!out_) throw Error(file_.string() + ": write failed");
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
