// The `impetus` command-line tool: run a scene, resolve one impact, list plugins, mass properties of a mesh.
// Contract: README.md, "The `impetus` tool", documents every option.

#include "fclib_command.hpp"
#include "gltf_export.hpp"
#include "mass_command.hpp"
#include "report.hpp"
#include "viewer_page.hpp"

#include "impetus/core/error.hpp"
#include "impetus/core/format.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/plugins/host.hpp"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using namespace impetus;

namespace {

using Clock = std::chrono::steady_clock;

// Step counts and the time t = n dt stay exact integers in a double up to 2^53.
constexpr double kMaxSteps = 9007199254740992.0;

// How to read the run summary (README.md, "The run summary", says the same at length).
constexpr const char* kRunSummaryHelp = R"help(The summary:
  energy     accounted, not just compared: dissipated by contacts (kinetic energy lost across the
             resolve stage of each step), work of gravity (m g dh) and of applied loads, potential
             energy added by position correction, and the remainder gained or lost by integration
             (the only part called drift). Only what is unexpected is flagged: contacts gaining
             energy, or integration gaining more than rounding beyond what the same steps' contacts
             took back (gravity's kick on a resting body, which its contact removes each step).
  momentum   impulses the movable bodies received from fixed bodies (and their moment about the
             origin) are physics; drift is what gravity, applied loads and those impulses do not
             explain.
  resolver   "redundant contact sets (minimum-norm)": more contact rows than the bodies have degrees
             of freedom (a box resting on four corners); the impulses are not unique and the
             smallest ones are used. Normal. "singular (failed)": a system the resolver could not
             satisfy (conflicting targets). With resolver none the detector still runs and the
             summary says the contacts were detected and not resolved (detector none skips it).)help";

struct SceneArgs {
  std::string scene;
  std::vector<std::string> sets;
  std::string integrator, detector, resolver;
  std::optional<double> dt;
};

// The bundled demo: installed copy first (relative to this executable), then the source tree.
fs::path demo_scene() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path() / IMPETUS_DEMO_SCENE_INSTALLED;
    if (fs::exists(installed, ec)) return installed.lexically_normal();
  }
  return IMPETUS_DEMO_SCENE_BUILD;
}

// Command-line module and dt flags are overrides like any --set, applied before validation.
Scene load(const SceneArgs& args) {
  std::vector<SceneOverride> overrides;
  if (args.dt) overrides.push_back({"dt", format_number(*args.dt)});
  if (!args.integrator.empty()) overrides.push_back({"modules.integrator", args.integrator});
  if (!args.detector.empty()) overrides.push_back({"modules.detector", args.detector});
  if (!args.resolver.empty()) overrides.push_back({"modules.resolver", args.resolver});
  for (const std::string& s : args.sets) overrides.push_back(parse_override(s));
  Scene scene = load_scene(args.scene.empty() ? demo_scene() : fs::path(args.scene), overrides);
  for (const std::string& warning : scene.warnings) std::cerr << "impetus: warning: " << warning << "\n";
  return scene;
}

void add_scene_options(CLI::App* cmd, SceneArgs& args, bool scene_required) {
  auto* scene = cmd->add_option("scene", args.scene, "scene file (YAML)")->check(CLI::ExistingFile);
  if (scene_required) scene->required();
  cmd->add_option("--set", args.sets, "override a scene value by its dotted path: KEY=VALUE (repeatable)")
      ->type_name("KEY=VALUE");
  cmd->add_option("--resolver", args.resolver, "resolver plugin (overrides modules.resolver)")->type_name("NAME");
}

// Progress on stderr, only for a person watching a terminal, at most ten updates a second.
class Progress {
 public:
  explicit Progress(std::uint64_t total) : total_(total), enabled_(isatty(STDERR_FILENO) != 0) {}
  void update(const World& world) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (now - last_ < std::chrono::milliseconds(100)) return;
    if (!shown_ && now - start_ < std::chrono::milliseconds(500)) return;  // short runs stay quiet
    last_ = now;
    shown_ = true;
    std::fprintf(stderr, "\r  step %llu/%llu (%.0f%%), t = %.4g s ", static_cast<unsigned long long>(world.step_count()),
                 static_cast<unsigned long long>(total_), 100.0 * world.step_count() / total_, world.time());
    std::fflush(stderr);
  }
  void done() {
    if (shown_) std::fprintf(stderr, "\r%60s\r", "");
  }

 private:
  std::uint64_t total_;
  bool enabled_;
  bool shown_ = false;
  Clock::time_point start_ = Clock::now(), last_{};
};

// What `run` writes besides its summary.
struct RunOutputs {
  std::string trajectory;  // --out (and its body table beside it)
  std::string contacts;    // --contacts
  bool overwrite = false;
  std::uint64_t every = 1;

  bool animation() const { return !trajectory.empty() && cli::is_animation_path(trajectory); }
  // The body table goes beside a CSV trajectory written to a file, not beside a device or a pipe
  // (/dev/stdout, /dev/full).
  bool body_table() const {
    std::error_code ec;
    return !trajectory.empty() && !animation() &&
           (!std::filesystem::exists(trajectory, ec) || std::filesystem::is_regular_file(trajectory, ec));
  }
};

// What a run's output file may be called: --out FILE.csv (trajectory), FILE.glb or FILE.gltf (glTF 2.0),
// FILE.html (the viewer page); --contacts FILE.csv. A device or a pipe (/dev/stdout, even redirected to a
// file) takes CSV whatever its name. Anything else is refused rather than guessed (README.md, "The
// `impetus` tool").
void check_extension(const std::string& option, const std::filesystem::path& file) {
  std::error_code ec;
  if (file.string().starts_with("/dev/") ||
      (std::filesystem::exists(file, ec) && !std::filesystem::is_regular_file(file, ec)))
    return;
  const std::string ext = cli::lowercase_extension(file);
  if (option == "--out" && ext != ".csv" && !cli::is_animation_path(file))
    throw Error("--out " + file.string() + ": unknown extension '" + ext +
                "'; use .csv (the trajectory as a table), .glb or .gltf (a glTF 2.0 animation) or .html (the "
                "viewer page)");
  if (option == "--contacts" && ext != ".csv")
    throw Error("--contacts " + file.string() + ": unknown extension '" + ext + "'; the contact log is written as .csv");
}

// Checks every output path before any file is created, so a bad --contacts leaves no empty --out behind,
// and refuses two outputs naming one file.
void check_outputs(const RunOutputs& outputs, const std::filesystem::path& scene) {
  std::vector<std::pair<std::string, std::filesystem::path>> files;
  if (!outputs.trajectory.empty()) {
    files.emplace_back("--out", outputs.trajectory);
    if (outputs.body_table()) files.emplace_back("--out (its body table)", cli::body_table_path(outputs.trajectory));
  }
  if (!outputs.contacts.empty()) files.emplace_back("--contacts", outputs.contacts);
  for (std::size_t i = 0; i < files.size(); ++i) {
    cli::check_output_path(files[i].second, outputs.overwrite, scene, files[i].first);
    check_extension(files[i].first, files[i].second);
    for (std::size_t j = 0; j < i; ++j)
      if (std::filesystem::weakly_canonical(files[i].second) == std::filesystem::weakly_canonical(files[j].second))
        throw Error(files[i].first + " " + files[i].second.string() + ": is also the file of " + files[j].first +
                    "; each output needs its own file");
  }
}

int run_command(const SceneArgs& args, std::optional<std::uint64_t> steps, std::optional<double> duration,
                const RunOutputs& outputs, bool json) {
  const Scene scene = load(args);
  PluginHost host;
  std::unique_ptr<World> world = build_world(scene, host);
  const double dt = world->settings().dt;
  std::uint64_t total = 1000;
  if (steps) total = *steps;
  if (duration) {
    if (!(*duration >= 0.0) || !std::isfinite(*duration))
      throw Error("--duration: must be a non-negative number of seconds");
    const double count = std::round(*duration / dt);
    if (!(count <= kMaxSteps))
      throw Error("--duration " + format_number(*duration) + ": at dt " + format_number(dt) + " s that is " +
                  format_number(count) + " steps, more than the " + format_number(kMaxSteps) +
                  " a run can count exactly (2^53)");
    total = static_cast<std::uint64_t>(count);
  }
  if (steps && static_cast<double>(*steps) > kMaxSteps)
    throw Error("--steps " + std::to_string(*steps) + ": more than the " + format_number(kMaxSteps) +
                " a run can count exactly (2^53)");

  check_outputs(outputs, scene.file);
  std::optional<cli::TrajectoryWriter> writer;
  std::optional<cli::GltfRecorder> animation;
  if (outputs.animation()) {
    animation.emplace(outputs.trajectory, outputs.overwrite, scene.file, *world, total / outputs.every + 2,
                      cli::GltfRunInfo{scene.file.string(), scene.integrator.plugin, scene.detector.plugin,
                                       scene.resolver.plugin, IMPETUS_VERSION});
    animation->record(*world);
  } else if (!outputs.trajectory.empty()) {
    if (outputs.body_table())
      cli::write_body_table(cli::body_table_path(outputs.trajectory), outputs.overwrite, scene.file, *world);
    writer.emplace(outputs.trajectory, outputs.overwrite, scene.file);
    writer->write(*world);
  }
  std::optional<cli::ContactWriter> contact_log;
  if (!outputs.contacts.empty()) contact_log.emplace(outputs.contacts, outputs.overwrite, scene.file);
  cli::RunStats stats(*world);
  Progress progress(total);
  const auto start = Clock::now();
  for (std::uint64_t i = 0; i < total; ++i) {
    try {
      cli::checked_step(*world, stats, scene.file.string());
    } catch (const Error&) {
      progress.done();
      throw;
    }
    if (world->step_count() % outputs.every == 0 || i + 1 == total) {
      if (writer) writer->write(*world);
      if (animation) animation->record(*world);
      if (contact_log) contact_log->write(*world);
    }
    progress.update(*world);
  }
  progress.done();
  if (writer) writer->finish();
  if (animation) animation->finish(*world);
  if (contact_log) contact_log->finish();
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  const nlohmann::json summary = cli::run_summary(scene, *world, stats, wall);
  if (json) {
    std::cout << summary.dump(2) << "\n";
  } else {
    cli::print_summary(summary, std::cout);
    if (!outputs.trajectory.empty()) {
      std::cout << "trajectory            " << outputs.trajectory;
      if (outputs.body_table()) std::cout << " (bodies: " << cli::body_table_path(outputs.trajectory).string() << ")";
      if (cli::lowercase_extension(outputs.trajectory) == ".html")
        std::cout << "  (open it in a browser: file://"
                  << fs::absolute(outputs.trajectory).lexically_normal().string() << ")";
      std::cout << "\n";
    }
    if (!outputs.contacts.empty()) std::cout << "contact log           " << outputs.contacts << "\n";
  }
  return 0;
}

int resolve_command(const SceneArgs& args, bool json) {
  const Scene scene = load(args);
  const nlohmann::json report = cli::resolve_scene(scene);
  if (json) {
    std::cout << report.dump(2) << "\n";
    return 0;
  }
  std::cout << "resolver " << scene.resolver.plugin << ": " << report["contacts"].size() << " contacts, "
            << report["iterations"] << " rounds, " << report["time_s"].get<double>() << " s, residual "
            << report["residual"].get<double>() << " m/s\n";
  for (const auto& c : report["contacts"])
    std::cout << "  " << c["a"].get<std::string>() << " - " << c["b"].get<std::string>() << "  depth "
              << c["depth"] << "  impulse " << c["impulse"] << "\n";
  return 0;
}

int fclib_export_command(const SceneArgs& args, const cli::FclibExportArgs& export_args) {
  const Scene scene = load(args);
  PluginHost host;
  std::unique_ptr<World> world = build_world(scene, host);
  return cli::run_fclib_export(scene, *world, export_args);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"impetus: rigid-body simulation with replaceable integrator, detector and resolver plugins"};
  app.set_version_flag("--version", std::string("impetus ") + IMPETUS_VERSION);
  app.require_subcommand(1);

  SceneArgs run_args;
  std::optional<std::uint64_t> steps;
  std::optional<double> duration;
  RunOutputs outputs;
  bool run_json = false;
  auto* run = app.add_subcommand("run", "simulate a scene (no SCENE: the bundled demo) and print a summary");
  add_scene_options(run, run_args, false);
  run->footer(kRunSummaryHelp);
  auto* steps_opt = run->add_option("--steps", steps, "number of steps (default 1000)")->check(CLI::NonNegativeNumber);
  run->add_option("--duration", duration, "simulated time in seconds")->excludes(steps_opt);
  run->add_option("--dt", run_args.dt, "time step in seconds (overrides dt)")->check(CLI::PositiveNumber);
  run->add_option("--integrator", run_args.integrator, "integrator plugin (overrides modules.integrator)")->type_name("NAME");
  run->add_option("--detector", run_args.detector, "detector plugin (overrides modules.detector)")->type_name("NAME");
  run->add_option("--out", outputs.trajectory,
                  "write the trajectory as CSV: step,time,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz, and the bodies "
                  "(name, mass, shape, sizes) beside it as FILE.bodies.csv; or, for FILE.glb / FILE.gltf, as a glTF "
                  "2.0 animation of the bodies' shapes; or, for FILE.html, as a page that plays it in a browser");
  run->add_option("--contacts", outputs.contacts,
                  "write the contact log as CSV: step,time,a,b,x,y,z,nx,ny,nz,depth,impulse,tx,ty,tz,mode");
  run->add_flag("--overwrite", outputs.overwrite, "allow --out and --contacts to replace existing files");
  run->add_option("--every", outputs.every, "with --out or --contacts: record every N-th step (default 1)")
      ->check(CLI::PositiveNumber);
  run->add_flag("--json", run_json, "print the summary as JSON");

  SceneArgs resolve_args;
  bool resolve_json = false;
  auto* resolve = app.add_subcommand("resolve", "one detection and one resolution on the scene's initial state");
  add_scene_options(resolve, resolve_args, true);
  resolve->add_flag("--json", resolve_json, "print contacts, impulses and velocities as JSON");

  bool plugins_json = false;
  auto* plugins = app.add_subcommand("plugins", "list every plugin found and every library that failed to load");
  plugins->add_flag("--json", plugins_json, "print the listing as JSON");

  auto* fclib = app.add_subcommand("fclib", "frictional contact problems in fclib's HDF5 form (Frictional Contact Library)");
  fclib->require_subcommand(1);
  cli::FclibSolveArgs fclib_solve_args;
  auto* fclib_solve = fclib->add_subcommand("solve", "solve an fclib problem (local, or global reduced to local form)");
  fclib_solve->add_option("file", fclib_solve_args.file, "fclib problem (HDF5)")->required()->check(CLI::ExistingFile);
  fclib_solve->add_option("--tol", fclib_solve_args.tolerance, "tolerance on fclib's merit (default 1e-10)")
      ->check(CLI::PositiveNumber);
  fclib_solve->add_option("--resolver", fclib_solve_args.resolver, "resolver plugin that solves it (default ledas)")
      ->type_name("NAME");
  fclib_solve->add_flag("--json", fclib_solve_args.json, "print the result, impulses and velocities as JSON");
  SceneArgs fclib_export_scene;
  cli::FclibExportArgs fclib_export_args;
  auto* fclib_export = fclib->add_subcommand("export", "write a scene's contact problem after one detection as an fclib problem");
  add_scene_options(fclib_export, fclib_export_scene, true);
  fclib_export->add_option("--out", fclib_export_args.out, "the HDF5 file to write")->required();
  fclib_export->add_flag("--global", fclib_export_args.global, "write the global form (M, H, f, w) instead of the local one (W, q)");
  fclib_export->add_flag("--overwrite", fclib_export_args.overwrite, "allow --out to replace an existing file");

  cli::ViewArgs view_args;
  auto* view = app.add_subcommand("view", "write a page that plays a run exported as glTF in a browser, offline");
  view->add_option("file", view_args.file, "a run exported by impetus run --out FILE.glb (or .gltf)")
      ->required()
      ->check(CLI::ExistingFile);
  view->add_option("--out", view_args.out, "the HTML page to write")->required();
  view->add_flag("--overwrite", view_args.overwrite, "allow --out to replace an existing file");

  cli::MassArgs mass_args;
  auto* mass = cli::add_mass_command(app, mass_args);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    if (run->parsed()) return run_command(run_args, steps, duration, outputs, run_json);
    if (resolve->parsed()) return resolve_command(resolve_args, resolve_json);
    if (mass->parsed()) return cli::run_mass_command(mass_args);
    if (view->parsed()) return cli::run_view_command(view_args);
    if (fclib_solve->parsed()) return cli::run_fclib_solve(fclib_solve_args);
    if (fclib_export->parsed()) return fclib_export_command(fclib_export_scene, fclib_export_args);
    if (plugins->parsed()) {
      PluginHost host;
      const PluginListing listing = host.discover();
      if (plugins_json)
        std::cout << cli::plugins_report(listing).dump(2) << "\n";
      else
        cli::print_plugins(listing, std::cout);
      return 0;
    }
  } catch (const std::exception& e) {
    std::cerr << "impetus: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
