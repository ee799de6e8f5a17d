// `impetus fclib solve` and `impetus fclib export` (fclib_command.hpp).
#include "fclib_command.hpp"
#include "report.hpp"

#include "impetus/core/error.hpp"
#include "impetus/core/format.hpp"
#include "impetus/fclib/fclib.hpp"
#include "impetus/plugins/host.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>

namespace impetus::cli {

namespace fs = std::filesystem;

namespace {

// The absolute natural-map residual that guarantees fclib's merit ≤ `tolerance`: the merit divides the
// contacts' residual by 1 + √‖q‖ and the equality rows' by 1 + ‖s‖, and adds them.
double absolute_tolerance(const fclib::LocalProblem& problem, double tolerance) {
  const auto c = static_cast<Eigen::Index>(3 * problem.contacts());
  double scale = 1.0 + std::sqrt(problem.q.head(c).norm());
  if (problem.equalities > 0) scale = 0.5 * std::min(scale, 1.0 + problem.q.tail(problem.q.size() - c).norm());
  return tolerance * scale;
}

nlohmann::json numbers(const fclib::Vector& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

}  // namespace

int run_fclib_solve(const FclibSolveArgs& args) {
  if (!(args.tolerance > 0.0) || !std::isfinite(args.tolerance)) throw Error("--tol: must be a positive number");
  const fclib::FileProblem file = fclib::read_problem(args.file);
  const fclib::LocalProblem& problem = file.local;

  PluginHost host;
  PluginRequest request;
  request.kind = ModuleKind::resolver;
  request.name = args.resolver;
  request.where = "--resolver";
  const std::shared_ptr<CollisionResolver> resolver = host.create_resolver(request);

  const std::size_t m = problem.rows();
  fclib::Vector r = fclib::Vector::Zero(static_cast<Eigen::Index>(m)), u = r;
  LocalContactSolution solution;
  solution.r = r.data();
  solution.u = u.data();
  const auto start = std::chrono::steady_clock::now();
  const ModuleStatus status = resolver->solve_contact_problem(problem.view(absolute_tolerance(problem, args.tolerance)), solution);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!status) throw Error(args.file + ": resolver " + args.resolver + ": " + status.message);
  const double error = fclib::merit(problem, r);
  const bool converged = error <= args.tolerance;

  if (args.json) {
    const auto c = static_cast<Eigen::Index>(3 * problem.contacts());
    nlohmann::json j{{"file", args.file},
                     {"form", file.form == fclib::Form::local ? "local" : "global"},
                     {"contacts", problem.contacts()},
                     {"equalities", problem.equalities},
                     {"resolver", args.resolver},
                     {"tolerance", args.tolerance},
                     {"error", error},
                     {"residual", solution.residual},
                     {"iterations", solution.iterations},
                     {"time_s", seconds},
                     {"converged", converged},
                     {"reaction", numbers(r.head(c))},
                     {"velocity", numbers(u.head(c))}};
    if (problem.equalities > 0) j["multipliers"] = numbers(r.tail(r.size() - c));
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << args.file << ": " << (file.form == fclib::Form::local ? "local" : "global") << " problem, "
              << problem.contacts() << " contacts";
    if (problem.equalities > 0) std::cout << ", " << problem.equalities << " equality rows";
    if (!problem.info.title.empty()) std::cout << " (" << problem.info.title << ")";
    std::cout << "\nresolver " << args.resolver << ": error " << error << " (fclib's merit; tolerance "
              << args.tolerance << "), " << solution.iterations << " iterations, " << seconds * 1e3 << " ms, "
              << (converged ? "converged" : "NOT converged") << "\n";
  }
  return 0;
}

int run_fclib_export(const Scene& scene, World& world, const FclibExportArgs& args) {
  const fs::path out(args.out);
  check_output_path(out, args.overwrite, scene.file, "--out");
  if (!world.constraints().empty())
    throw Error(scene.file.string() + ": has " + std::to_string(world.constraints().size()) +
                " constraints; fclib export writes contact problems only (assembly constraints are not exported)");
  if (!world.has_detector()) throw Error(scene.file.string() + ": export needs a detector (modules.detector is 'none')");
  std::error_code ec;
  const StepStatus& status = world.detect_contacts();
  if (!status.ok) throw Error(scene.file.string() + ": " + status.message);
  fclib::SceneProblem problem = fclib::scene_problem(world.bodies(), world.contacts(), world.settings().dt);
  if (problem.contacts.empty()) throw Error(scene.file.string() + ": no contact between a movable body and another body after one detection");
  const fclib::Info info{"Impetus: " + scene.file.filename().string(),
                         "the contact problem of " + scene.file.filename().string() +
                             " after one detection at its initial state, dt " + format_number(world.settings().dt) +
                             " s; the inelastic impact (restitution not included)",
                         ""};
  problem.global.info = problem.local.info = info;
  // Written beside the target first, so a failed write never leaves half a file under the user's name.
  const fs::path partial = out.string() + ".impetus-partial";
  if (fs::exists(partial, ec)) throw Error(partial.string() + ": exists (left by an interrupted export?); remove it first");
  if (args.global)
    fclib::write_problem(partial, problem.global);
  else
    fclib::write_problem(partial, problem.local);
  fs::rename(partial, out, ec);
  if (ec) {
    fs::remove(partial, ec);
    throw Error(args.out + ": cannot be written (" + ec.message() + ")");
  }
  std::cout << "wrote " << args.out << ": " << (args.global ? "global" : "local") << " problem of "
            << problem.contacts.size() << " contacts on " << problem.bodies.size() << " movable bodies\n";
  return 0;
}

}  // namespace impetus::cli
