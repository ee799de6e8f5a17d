#pragma once
// Summaries and output files of the `impetus` tool: run statistics, the trajectory CSV, and the JSON
// documents of `run --json`, `resolve --json` and `plugins --json`. Part of the tool's support library
// (impetus_tool_support), which the Python package links too, so both report a run the same way.

#include "impetus/engine/metrics.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/engine/world.hpp"
#include "impetus/plugins/host.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace impetus::cli {

/// Statistics gathered over a run, step by step, for the run summary (README.md, "The run summary").
///
/// Energy is accounted, not just compared: ΔKE = (work of contacts) + (work of gravity) + (work of applied
/// loads) + (what integration gained or lost). Contacts are measured around the resolve stage of each
/// step (StepStatus::resolve_energy_change); gravity and loads from the positions; integration is the
/// remainder. Momentum likewise: Δp = gravity + loads + impulses received from fixed bodies + drift.
class RunStats {
 public:
  explicit RunStats(const World& world);
  /// Call before world.step(): adds the momentum gravity and the applied loads will add over the step.
  /// With velocities updated before positions, a free body's angular momentum about the origin changes
  /// by exactly dt · x_before × (m g + F) + dt τ, so the pre-step position is the one to use.
  void before_step(const World& world);
  /// Adds the step just taken (after world.step()).
  void add_step(const World& world, const StepStatus& status);
  /// What in the run's accounting is no longer finite ("kinetic energy", …), or null: a step whose
  /// state stays finite can still overflow an energy or a momentum (1e200 m/s squared), and a summary
  /// of inf and nan would be garbage.
  const char* non_finite() const;
  /// The summary as JSON (units in key names: _s, _j, _m …).
  nlohmann::json summary(const World& world, double wall_seconds) const;

 private:
  void add_fixed_body_impulses(const World& world);
  void add_integration_step(const World& world, const StepStatus& status, double step_load_work);
  nlohmann::json energy_summary(const World& world) const;
  nlohmann::json momentum_summary(const World& world) const;

  WorldMetrics initial_;
  std::vector<Vec3> initial_positions_;  // of every body, for the work of gravity and constant forces
  double total_mass_ = 0.0;
  bool frictional_ = false;
  std::uint64_t sleeping_now_ = 0, max_sleeping_ = 0, woken_ = 0;  // sleeping islands              // some body has friction > 0 (else every contact is frictionless)
  Vec3 gravity_impulse_ = Vec3::Zero();  // ∫ Σ m g dt: the linear momentum gravity adds
  Vec3 gravity_moment_ = Vec3::Zero();   // ∫ Σ x × m g dt: the angular momentum gravity adds about 0
  Vec3 load_impulse_ = Vec3::Zero();     // ∫ Σ F dt: the linear momentum applied forces add
  Vec3 load_moment_ = Vec3::Zero();      // ∫ Σ (x × F + τ) dt
  Vec3 fixed_impulse_ = Vec3::Zero();    // Σ impulses movable bodies received from fixed ones (N s)
  Vec3 fixed_moment_ = Vec3::Zero();     // Σ point × impulse of the same, about the origin (N m s)
  double contact_energy_change_ = 0.0;   // Σ kinetic energy change across the resolve stage (J)
  double contact_energy_scale_ = 0.0;    // Σ |that change|: the scale rounding is measured against
  double correction_energy_ = 0.0;       // Σ potential energy the resolver's position correction added (J)
  double step_load_work_ = 0.0;          // Σ dt (F_body·v + τ·ω) over loads without a potential (J)
  double prescribed_work_ = 0.0;         // Σ work of moving fixed bodies through contacts (J)
  // Σ over steps of the integration gain the same step's contacts took back: the split step gives a
  // resting (or landing) body gravity's kick before the contact removes it, an exchange, not a gain.
  double contact_exchange_ = 0.0;
  double step_kinetic_ = 0.0, step_potential_ = 0.0;  // KE and −Σ (m g + F)·x before the current step
  double kinetic_after_ = 0.0, potential_after_ = 0.0;  // the same after the last step
  StepProfile time_;                     // summed over steps
  std::uint64_t steps_ = 0, contacts_ = 0, max_contacts_ = 0, rounds_ = 0, max_rounds_ = 0;
  std::uint64_t non_converged_ = 0, singular_ = 0, redundant_ = 0, pulling_ = 0, energy_gains_ = 0;
  std::uint64_t sticking_ = 0, sliding_ = 0;
  std::uint64_t work_limited_ = 0, clamped_ = 0;  // solves stopped by a work budget, corrections bounded
  std::uint64_t speculative_ = 0;  // pairs the detector looked ahead for (fast bodies)
  double largest_correction_ = 0.0;               // m
  double friction_work_ = 0.0, max_natural_map_ = 0.0;
  double max_penetration_ = 0.0, max_residual_ = 0.0;
};

/// One step of a run with its statistics: throws Error("<scene file>: …") when the step failed (the world
/// is back at its state before it) or the run's accounting is no longer finite.
void checked_step(World& world, RunStats& stats, const std::string& scene_file);

/// The options a scene or an override gave a module (plugin defaults are not known here): a string per
/// scalar, an array of strings per list.
nlohmann::json options_json(const ModuleOptions& options);

/// The `run --json` document: the statistics' summary with the scene, its modules and their options.
nlohmann::json run_summary(const Scene& scene, const World& world, const RunStats& stats, double wall_seconds);

/// Prints a run summary for people.
void print_summary(const nlohmann::json& summary, std::ostream& out);

/// Refuses an output path that would lose data or hurt an input, naming `option` (e.g. "--out"): an
/// existing file without `overwrite`, a directory, a symbolic link to nothing (it would create a file
/// elsewhere), the same file as `input` (the scene being read), even with `overwrite`, or a new file in a
/// folder that does not exist.
void check_output_path(const std::filesystem::path& out, bool overwrite, const std::filesystem::path& input,
                       const std::string& option);

/// Writes `data` to `file` (replacing it; the path was checked before), throwing Error if it could not be
/// written whole (a full disk, /dev/full).
void write_file(const std::filesystem::path& file, std::string_view data);

/// A CSV file the tool writes: its path is checked first (check_output_path, naming `option`), every
/// write is checked, and finish() checks the final flush, so a full disk is an error, never a short file.
class CsvFile {
 public:
  CsvFile(const std::filesystem::path& file, bool overwrite, const std::filesystem::path& input,
          const std::string& option, const std::string& header);
  /// Writes `text` (whole lines); throws Error if the write failed.
  void put(const std::string& text);
  /// Flushes and closes the file; throws Error if any write failed (a full disk, /dev/full).
  void finish();

 private:
  std::filesystem::path file_;
  std::ofstream out_;
};

/// Writes one CSV row per body per recorded step: step,time,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz.
/// Numbers use the shortest text that reads back to the same double, so the file is bit-exact.
class TrajectoryWriter {
 public:
  /// Opens `file` for writing after check_output_path (`input`: the scene being run).
  TrajectoryWriter(const std::filesystem::path& file, bool overwrite, const std::filesystem::path& input);
  void write(const World& world);
  void finish() { csv_.finish(); }

 private:
  CsvFile csv_;
};

/// Writes the contact log (`--contacts`): one row per contact of the step just taken, with the impulses
/// the resolver applied: step,time,a,b,x,y,z,nx,ny,nz,depth,impulse,tx,ty,tz,mode (README.md, "The
/// `impetus` tool"). Same number format as the trajectory.
class ContactWriter {
 public:
  ContactWriter(const std::filesystem::path& file, bool overwrite, const std::filesystem::path& input);
  void write(const World& world);
  void finish() { csv_.finish(); }

 private:
  CsvFile csv_;
};

/// The body table beside a trajectory: `run.csv` → `run.bodies.csv` (any other name gains `.bodies.csv`).
std::filesystem::path body_table_path(const std::filesystem::path& trajectory);

/// Writes the body table (name, mass, fixed, shape and its sizes, mesh file, scale and collision), one
/// row per body, so an analysis of the trajectory needs nothing but the files.
void write_body_table(const std::filesystem::path& file, bool overwrite, const std::filesystem::path& input,
                      const World& world);

/// The `resolve --json` document (README.md, "The `impetus` tool").
nlohmann::json resolve_report(const World& world, const std::string& resolver, double seconds);

/// The `impetus resolve` experiment: one detection and one resolution on the scene's initial state, with
/// its `--json` document. Throws Error naming the scene without a detector or resolver, or when it fails.
nlohmann::json resolve_scene(const Scene& scene);

/// The `plugins --json` document.
nlohmann::json plugins_report(const PluginListing& listing);
/// Prints the plugin listing for people.
void print_plugins(const PluginListing& listing, std::ostream& out);

}  // namespace impetus::cli
