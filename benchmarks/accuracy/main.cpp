// bench_accuracy: runs every accuracy scenario with every method and setting, and writes one JSON (and
// optionally CSV) file for the whole run. README.md in this folder describes the output.
//
//   bench_accuracy [--quick] [--out FILE.json] [--csv FILE.csv] [--filter TEXT]... [--budget S]
//                  [--scenes DIR] [--no-isolate] [--list]
#include "accuracy.hpp"
#include "report.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace {

using namespace impetus::accuracy;

struct Options {
  bool quick = false;
  bool isolate = true;
  bool list = false;
  double budget = 0.0;  // 0: 10 s, or 3 s with --quick
  std::string out = "accuracy.json";
  std::string csv;
  std::vector<std::string> filters;
  std::filesystem::path scenes = std::filesystem::path(IMPETUS_SOURCE_DIR) / "assets" / "scenes";
};

[[noreturn]] void usage(int status) {
  std::fprintf(status ? stderr : stdout,
               "usage: bench_accuracy [--quick] [--out FILE.json] [--csv FILE.csv] [--filter TEXT]... [--budget S]\n"
               "                      [--scenes DIR] [--no-isolate] [--list]\n"
               "  --quick       short simulations, reference settings only (about a minute)\n"
               "  --out         the suite's JSON (default accuracy.json)\n"
               "  --csv         also one CSV row per run\n"
               "  --filter      run only scenarios whose id contains TEXT (repeatable)\n"
               "  --budget      wall-time budget per run in seconds (default 10, quick 3; a step still running\n"
               "                5 s past it is killed)\n"
               "  --scenes      scene directory (default: the source tree's assets/scenes)\n"
               "  --no-isolate  run in this process (no child process per run, no kill on a hung step)\n"
               "  --list        list scenarios and their number of runs, run nothing\n");
  std::exit(status);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bench_accuracy: %s needs a value\n", arg.c_str());
        usage(2);
      }
      return argv[++i];
    };
    if (arg == "--quick") o.quick = true;
    else if (arg == "--no-isolate") o.isolate = false;
    else if (arg == "--list") o.list = true;
    else if (arg == "--out") o.out = value();
    else if (arg == "--csv") o.csv = value();
    else if (arg == "--filter") o.filters.push_back(value());
    else if (arg == "--scenes") o.scenes = value();
    else if (arg == "--budget") o.budget = std::atof(value().c_str());
    else if (arg == "--help" || arg == "-h") usage(0);
    else {
      std::fprintf(stderr, "bench_accuracy: unknown argument '%s'\n", arg.c_str());
      usage(2);
    }
  }
  if (o.budget <= 0) o.budget = o.quick ? 3.0 : 10.0;
  return o;
}

bool selected(const Options& o, const Scenario& s) {
  if (o.filters.empty()) return true;
  for (const std::string& f : o.filters)
    if (s.id.find(f) != std::string::npos) return true;
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const auto start = std::chrono::steady_clock::now();
  char host[256] = "unknown";
  gethostname(host, sizeof host - 1);
  nlohmann::json suite{{"suite", "impetus accuracy"},
                       {"format", 1},
                       {"quick", o.quick},
                       {"generated_utc", utc_now()},
                       {"host", host},
                       {"cores", sysconf(_SC_NPROCESSORS_ONLN)},
                       {"build_type", IMPETUS_BUILD_TYPE},
                       {"budget_s", o.budget},
                       {"scenarios", nlohmann::json::array()}};
  std::ofstream csv;
  if (!o.csv.empty()) {
    csv.open(o.csv);
    if (!csv) {
      std::fprintf(stderr, "bench_accuracy: cannot write %s\n", o.csv.c_str());
      return 1;
    }
    csv << csv_header() << "\n";
  }
  std::size_t runs = 0, passed = 0;
  for (const Scenario& s : scenarios(o.quick)) {
    if (!selected(o, s)) continue;
    const std::vector<Method> methods = methods_for(s, o.quick);
    if (o.list) {
      std::printf("%-22s %3zu runs  %s\n", s.id.c_str(), methods.size(), s.title.c_str());
      continue;
    }
    nlohmann::json entry = scenario_to_json(s);
    entry["runs"] = nlohmann::json::array();
    for (const Method& m : methods) {
      const RunResult r = o.isolate ? run_isolated(s, m, o.scenes, o.budget, 5.0)
                                    : run(s, m, o.scenes, o.budget);
      const auto primary = r.errors.find(s.primary);
      std::fprintf(stderr, "%-20s %-44s %-11s %9.3g s/step  %s %-10.3g %s\n", s.id.c_str(), m.label().c_str(),
                   r.status.c_str(), r.time_per_step, s.primary.c_str(),
                   primary != r.errors.end() ? primary->second : 0.0, r.pass ? "pass" : "FAIL");
      if (r.status == "error") std::fprintf(stderr, "    %s\n", r.message.c_str());
      nlohmann::json row = method_to_json(m);
      row.update(result_to_json(r));
      entry["runs"].push_back(row);
      if (csv) csv << csv_row(s, m, r) << "\n";
      ++runs;
      passed += r.pass ? 1 : 0;
    }
    suite["scenarios"].push_back(entry);
  }
  if (o.list) return 0;
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  suite["total_wall_s"] = total;
  std::ofstream out(o.out);
  if (!out) {
    std::fprintf(stderr, "bench_accuracy: cannot write %s\n", o.out.c_str());
    return 1;
  }
  out << suite.dump(1) << "\n";
  std::fprintf(stderr, "bench_accuracy: %zu runs (%zu pass the criterion) in %.0f s -> %s\n", runs, passed, total,
               o.out.c_str());
  return 0;
}
