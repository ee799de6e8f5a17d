// JSON and CSV for the suite's output (report.hpp).
#include "report.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

namespace impetus::accuracy {
namespace {

nlohmann::json number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

double number_from(const nlohmann::json& j) {
  return j.is_number() ? j.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

std::string csv_number(double x) {
  if (!std::isfinite(x)) return "";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", x);
  return buffer;
}

}  // namespace

nlohmann::json result_to_json(const RunResult& r) {
  nlohmann::json errors = nlohmann::json::object();
  for (const auto& [name, value] : r.errors) errors[name] = number(value);
  const RunCounters& c = r.counters;
  return {{"status", r.status},
          {"message", r.message},
          {"steps", r.steps},
          {"simulated_s", number(r.simulated)},
          {"time_per_step_s", number(r.time_per_step)},
          {"wall_s", number(r.wall)},
          {"errors", errors},
          {"pass", r.pass},
          {"counters",
           {{"rounds", c.rounds},
            {"max_rounds_per_step", c.max_rounds_step},
            {"non_converged", c.non_converged},
            {"singular_systems", c.singular_systems},
            {"redundant_systems", c.redundant_systems},
            {"pulling_impulses", c.pulling_impulses},
            {"nan_caught", c.nan_caught},
            {"energy_gain_events", c.energy_gain_events},
            {"max_contacts", c.max_contacts}}}};
}

RunResult result_from_json(const nlohmann::json& j) {
  RunResult r;
  r.status = j.at("status").get<std::string>();
  r.message = j.at("message").get<std::string>();
  r.steps = j.at("steps").get<std::size_t>();
  r.simulated = number_from(j.at("simulated_s"));
  r.time_per_step = number_from(j.at("time_per_step_s"));
  r.wall = number_from(j.at("wall_s"));
  for (const auto& [name, value] : j.at("errors").items()) r.errors[name] = number_from(value);
  r.pass = j.at("pass").get<bool>();
  const nlohmann::json& c = j.at("counters");
  r.counters.rounds = c.at("rounds").get<unsigned long long>();
  r.counters.max_rounds_step = c.at("max_rounds_per_step").get<unsigned long long>();
  r.counters.non_converged = c.at("non_converged").get<unsigned long long>();
  r.counters.singular_systems = c.at("singular_systems").get<unsigned long long>();
  r.counters.redundant_systems = c.value("redundant_systems", 0ull);  // absent from files before ABI 5
  r.counters.pulling_impulses = c.at("pulling_impulses").get<unsigned long long>();
  r.counters.nan_caught = c.at("nan_caught").get<unsigned long long>();
  r.counters.energy_gain_events = c.at("energy_gain_events").get<unsigned long long>();
  r.counters.max_contacts = c.at("max_contacts").get<unsigned long long>();
  return r;
}

nlohmann::json method_to_json(const Method& m) {
  return {{"method", m.resolver_label()},
          {"resolver", m.resolver},
          {"mode", m.mode},
          {"integrator", m.integrator},
          {"dt", m.dt > 0 ? nlohmann::json(m.dt) : nlohmann::json(nullptr)},
          {"dt_label", m.dt > 0 ? format_dt(m.dt) : ""},
          {"cap_option", m.cap_option()},
          {"cap", m.cap > 0 ? nlohmann::json(m.cap) : nlohmann::json(nullptr)},
          {"label", m.label()}};
}

nlohmann::json scenario_to_json(const Scenario& s) {
  nlohmann::json overrides = nlohmann::json::array();
  for (const SceneOverride& o : s.overrides) overrides.push_back(o.key + "=" + o.value);
  nlohmann::json dts = nlohmann::json::array();
  for (const double dt : s.dts) dts.push_back(dt);
  nlohmann::json bounds = nlohmann::json::object();
  for (const auto& [name, bound] : s.bounds) bounds[name] = bound;
  return {{"id", s.id},
          {"group", s.group},
          {"title", s.title},
          {"scene", "assets/scenes/" + s.scene},
          {"overrides", overrides},
          {"kind", s.kind == Kind::impact ? "impact" : "simulation"},
          {"duration_s", s.kind == Kind::impact ? nlohmann::json(nullptr) : nlohmann::json(s.duration)},
          {"reference_dt", s.kind == Kind::impact ? nlohmann::json(nullptr) : nlohmann::json(s.reference_dt)},
          {"reference_dt_label", s.kind == Kind::impact ? "" : format_dt(s.reference_dt)},
          {"dts", dts},
          {"resolvers", s.resolvers},
          {"measures", s.measures},
          {"errors", s.error_doc},
          {"primary", s.primary},
          {"criterion", s.criterion},
          {"bounds", bounds}};
}

std::string csv_header() {
  return "scenario,method,integrator,dt,cap_option,cap,status,steps,simulated_s,time_per_step_s,pass,primary,"
         "primary_error,errors";
}

std::string csv_row(const Scenario& s, const Method& m, const RunResult& r) {
  std::string errors;
  for (const auto& [name, value] : r.errors) errors += (errors.empty() ? "" : ";") + name + "=" + csv_number(value);
  const auto primary = r.errors.find(s.primary);
  return s.id + "," + m.resolver_label() + "," + m.integrator + "," + (m.dt > 0 ? csv_number(m.dt) : "") + "," +
         m.cap_option() + "," + (m.cap > 0 ? std::to_string(m.cap) : "") + "," + r.status + "," +
         std::to_string(r.steps) + "," + csv_number(r.simulated) + "," + csv_number(r.time_per_step) + "," +
         (r.pass ? "1" : "0") + "," + s.primary + "," +
         (primary != r.errors.end() ? csv_number(primary->second) : "") + "," + errors;
}

}  // namespace impetus::accuracy
