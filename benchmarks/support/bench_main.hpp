#pragma once
/// \file
/// The `main` of every Google Benchmark family, with a console reporter that prints counters as plain
/// numbers. Google Benchmark's own console output writes counters with SI prefixes, which misleads for
/// the values these families report: a residual of 5.55e-17 m/s prints as `55.5112a`, an energy change
/// of −3e-4 as `-300u`. Here a counter holding a whole number prints in full (`bodies=5050`) and any
/// other value with three significant digits (`residual=5.55e-17`). Only the console changes: with
/// `--benchmark_format=json|csv`, and for the file of `--benchmark_out`, Google Benchmark's own reporters
/// run untouched, so scripts reading the JSON see the same numbers as before.

#include <benchmark/benchmark.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>

namespace impetus::bench {

/// A counter's value as text: whole numbers in full, anything else in `%.3g`; "nan" and "0" unsigned
/// (an aggregate of equal values has a coefficient of variation of −0 or −nan).
inline std::string plain_number(double value) {
  if (std::isnan(value)) return "nan";
  if (value == 0.0) return "0";
  char text[32];
  if (std::isfinite(value) && value == std::round(value) && std::abs(value) < 1e15)
    std::snprintf(text, sizeof text, "%.0f", value);
  else
    std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

/// Google Benchmark's console reporter with counters printed by plain_number(). The library offers no
/// hook for the counters alone, so each line is printed by the base class without counters and label,
/// and the counters (then the label) are put back in front of its line end.
class PlainConsoleReporter : public benchmark::ConsoleReporter {
 public:
  using benchmark::ConsoleReporter::ConsoleReporter;

 protected:
  void PrintRunData(const Run& run) override {
    if (run.error_occurred) return ConsoleReporter::PrintRunData(run);  // no counters on an error line
    Run bare = run;
    bare.counters.clear();
    bare.report_label.clear();
    std::ostream& out = GetOutputStream();
    std::ostringstream line;
    SetOutputStream(&line);
    ConsoleReporter::PrintRunData(bare);
    SetOutputStream(&out);
    // The line ends with "\n", followed by a colour reset when colours are on.
    const std::string text = line.str();
    const std::size_t end = text.rfind('\n');
    out << text.substr(0, end);
    const bool percent = run.run_type == Run::RT_Aggregate && run.aggregate_unit == benchmark::kPercentage;
    for (const auto& [name, counter] : run.counters) {
      // As the base class: a coefficient-of-variation aggregate is a percentage; rates carry /s.
      std::string value = percent ? plain_number(100.0 * counter.value) + "%" : plain_number(counter.value);
      if (!percent && (counter.flags & benchmark::Counter::kIsRate))
        value += (counter.flags & benchmark::Counter::kInvert) ? "s" : "/s";
      // Tabular columns are as wide as the base class's header (at least 10, or the name).
      if (output_options_ & OO_Tabular)
        out << ' ' << std::string(std::max<std::size_t>({10, name.size(), value.size()}) - value.size(), ' ') << value;
      else
        out << ' ' << name << '=' << value;
    }
    if (!run.report_label.empty()) out << ' ' << run.report_label;
    out << (end == std::string::npos ? "\n" : text.substr(end));
  }
};

/// The value Google Benchmark will give flag `name` (`--name=value` in argv, the last one winning, else
/// the environment variable NAME in capitals, else `fallback`). Read before benchmark::Initialize(),
/// which removes the flags it knows from argv and keeps their values private.
inline std::string flag_value(int argc, char** argv, const std::string& name, const std::string& fallback) {
  std::string value = fallback;
  std::string variable = name;
  std::transform(variable.begin(), variable.end(), variable.begin(), [](unsigned char c) { return std::toupper(c); });
  if (const char* from_environment = std::getenv(variable.c_str())) value = from_environment;
  const std::string prefix = "--" + name;
  for (int i = 1; i < argc; ++i) {
    if (argv[i] == prefix) value = "true";  // a bare boolean flag
    else if (std::strncmp(argv[i], (prefix + "=").c_str(), prefix.size() + 1) == 0) value = argv[i] + prefix.size() + 1;
  }
  return value;
}

/// Google Benchmark's reading of a boolean flag's value.
inline bool flag_true(std::string value) {
  std::transform(value.begin(), value.end(), value.begin(), [](unsigned char c) { return std::tolower(c); });
  return !(value == "0" || value == "f" || value == "n" || value == "false" || value == "no" || value == "off");
}

/// benchmark::Initialize(), and the reporter for the console: a PlainConsoleReporter with the colour and
/// tabular options the flags ask for, or nullptr when the console format is json or csv (Google
/// Benchmark then makes its own reporter, as without this file).
inline std::unique_ptr<benchmark::BenchmarkReporter> initialize(int* argc, char** argv) {
  const std::string format = flag_value(*argc, argv, "benchmark_format", "console");
  const std::string colour = flag_value(*argc, argv, "benchmark_color", "auto");
  const bool tabular = flag_true(flag_value(*argc, argv, "benchmark_counters_tabular", "false"));
  // "auto": colours on a terminal, as Google Benchmark decides it.
  const char* term = std::getenv("TERM");
  const bool coloured = colour == "auto" ? ::isatty(STDOUT_FILENO) && term && std::strcmp(term, "dumb") != 0
                                         : flag_true(colour);
  benchmark::Initialize(argc, argv);
  if (format != "console") return nullptr;
  int options = benchmark::ConsoleReporter::OO_None;
  if (coloured) options |= benchmark::ConsoleReporter::OO_Color;
  if (tabular) options |= benchmark::ConsoleReporter::OO_Tabular;
  return std::make_unique<PlainConsoleReporter>(static_cast<benchmark::ConsoleReporter::OutputOptions>(options));
}

}  // namespace impetus::bench

/// BENCHMARK_MAIN() with the plain console reporter above.
#define IMPETUS_BENCHMARK_MAIN()                                                            \
  int main(int argc, char** argv) {                                                       \
    const auto reporter = ::impetus::bench::initialize(&argc, argv);                      \
    if (::benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;                   \
    ::benchmark::RunSpecifiedBenchmarks(reporter.get());                                  \
    ::benchmark::Shutdown();                                                              \
    return 0;                                                                             \
  }                                                                                       \
  int main(int, char**)
