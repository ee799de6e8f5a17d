// The `impetus` tool as a user runs it: exit status, messages naming file/line, module swapping by flag,
// the JSON and CSV contracts, and bit-identical reruns.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <Eigen/Core>

#include "impetus_test/process.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

using Result = impetus::test::CommandResult;

Result run(const std::string& args) { return impetus::test::run_shell(std::string(IMPETUS_EXE) + " " + args); }

std::string scene(const char* name) { return std::string(IMPETUS_CLI_SCENES) + "/" + name; }

fs::path temp_file(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("impetus_cli_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::string read(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Cli, HelpListsTheCommands) {
  const Result r = run("--help");
  EXPECT_EQ(r.status, 0);
  for (const char* word : {"run", "resolve", "plugins"}) EXPECT_NE(r.out.find(word), std::string::npos) << word;
}

TEST(Cli, PluginsJsonListsTheIntegratorsWithTheirPaths) {
  const Result r = run("plugins --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  int found = 0;
  for (const auto& p : j["plugins"]) {
    if (p["kind"] != "integrator") continue;
    const std::string name = p["name"];
    if (name != "euler" && name != "momentum" && name != "splitting") continue;
    ++found;
    EXPECT_TRUE(fs::exists(p["path"].get<std::string>())) << p.dump();
    EXPECT_NE(p["path"].get<std::string>().find("impetus_integrator_" + name), std::string::npos);
  }
  EXPECT_EQ(found, 3) << r.out;
}

TEST(Cli, DemoRunsWithoutAScene) {
  const Result r = run("run --steps 200 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["steps"], 200);
  EXPECT_NEAR(j["simulated_time_s"].get<double>(), 0.2, 1e-12);
}

/// |L0| (kg m²/s) of the box in spin.yaml: 0.1 x 0.4 x 0.8 m, 1000 kg/m³, ω = (1, 6, 0.5) rad/s.
double spin_box_angular_momentum() {
  const double mass = 1000 * 0.1 * 0.4 * 0.8;
  const Eigen::Vector3d J(mass * (0.4 * 0.4 + 0.8 * 0.8) / 12, mass * (0.1 * 0.1 + 0.8 * 0.8) / 12,
                          mass * (0.1 * 0.1 + 0.4 * 0.4) / 12);
  return J.cwiseProduct(Eigen::Vector3d(1.0, 6.0, 0.5)).norm();  // body frame = world at t=0
}

// Swapping the integrator is one flag, no rebuild: the torque-free box conserves angular momentum with
// `momentum` (to 1e-9 relative) and visibly does not with the paper's `euler` scheme (eq. 2 ignores the
// gyroscopic term, so its ω stays fixed while the body turns and J_world ω wanders).
TEST(Cli, IntegratorFlagSwapsThePluginAndChangesTheDrift) {
  const Result momentum = run("run " + scene("spin.yaml") + " --duration 2 --json");
  const Result euler = run("run " + scene("spin.yaml") + " --duration 2 --json --integrator euler");
  ASSERT_EQ(momentum.status, 0) << momentum.out;
  ASSERT_EQ(euler.status, 0) << euler.out;
  const auto jm = nlohmann::json::parse(momentum.out), je = nlohmann::json::parse(euler.out);
  EXPECT_EQ(jm["modules"]["integrator"], "momentum");
  EXPECT_EQ(je["modules"]["integrator"], "euler");
  const double L0 = spin_box_angular_momentum();
  EXPECT_LT(jm["angular_momentum_drift"].get<double>() / L0, 1e-9);
  EXPECT_GT(je["angular_momentum_drift"].get<double>() / L0, 1e-3);
}

// `--integrator splitting` on the same box: L conserved as with `momentum` (1e-9 relative), and the
// kinetic energy, which `momentum` lets grow at first order in dt, stays within 1e-5 of its start
// (second-order, bounded error; integrators/splitting/README.md) — at least 100 times closer. Measured
// over 2 s at dt = 1e-3, |ω| ≈ 6 rad/s: splitting 2.3e-6, momentum 1.1e-2.
TEST(Cli, SplittingIntegratorBoundsTheEnergyDrift) {
  const Result momentum = run("run " + scene("spin.yaml") + " --duration 2 --json");
  const Result splitting = run("run " + scene("spin.yaml") + " --duration 2 --json --integrator splitting");
  ASSERT_EQ(momentum.status, 0) << momentum.out;
  ASSERT_EQ(splitting.status, 0) << splitting.out;
  const auto jm = nlohmann::json::parse(momentum.out), js = nlohmann::json::parse(splitting.out);
  EXPECT_EQ(js["modules"]["integrator"], "splitting");
  const double e0 = js["energy"]["initial_j"].get<double>();
  const double drift_splitting = std::abs(js["energy"]["drift_j"].get<double>()) / e0;
  const double drift_momentum = std::abs(jm["energy"]["drift_j"].get<double>()) / e0;
  std::printf("energy drift over 2 s: splitting %.3e, momentum %.3e (relative)\n", drift_splitting,
              drift_momentum);
  EXPECT_LT(drift_splitting, 1e-5);
  EXPECT_GT(drift_momentum, 100.0 * drift_splitting);
  EXPECT_LT(js["angular_momentum_drift"].get<double>() / spin_box_angular_momentum(), 1e-9);
}

TEST(Cli, UnknownKeyIsRefusedWithFileLineAndKey) {
  const Result r = run("run " + scene("typo.yaml"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("typo.yaml:6:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("positon"), std::string::npos) << r.out;
}

TEST(Cli, NegativeMassIsRefusedWithFileLineAndReason) {
  const Result r = run("run " + scene("negative_mass.yaml"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("negative_mass.yaml:6:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mass"), std::string::npos) << r.out;
}

TEST(Cli, NanIsRefusedWithFileAndLine) {
  const Result r = run("run " + scene("nan.yaml"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("nan.yaml:7:"), std::string::npos) << r.out;
}

TEST(Cli, UnknownPluginNamesTheAvailableOnes) {
  const Result r = run("run " + scene("spin.yaml") + " --integrator eulr");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("eulr"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("momentum"), std::string::npos) << r.out;
}

TEST(Cli, SetOverridesASceneValue) {
  const Result r = run("run " + scene("spin.yaml") + " --steps 10 --json --set dt=0.01");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["simulated_time_s"].get<double>(), 0.1, 1e-12);
}

// The CSV contract, and determinism: the same scene and build give bit-identical trajectories.
TEST(Cli, TrajectoryCsvIsWellFormedAndBitIdenticalAcrossRuns) {
  const fs::path a = temp_file("a.csv"), b = temp_file("b.csv");
  fs::remove(a);
  fs::remove(b);
  ASSERT_EQ(run("run --steps 300 --out " + a.string()).status, 0);
  ASSERT_EQ(run("run --steps 300 --out " + b.string()).status, 0);
  const std::string text = read(a);
  EXPECT_EQ(text, read(b));
  std::istringstream lines(text);
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header, "step,time,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz");
  std::string line;
  int rows = 0;
  while (std::getline(lines, line)) {
    ++rows;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 15) << line;
  }
  const auto summary = nlohmann::json::parse(run("run --steps 1 --json").out);
  EXPECT_EQ(rows, summary["bodies"].get<int>() * 301);  // every body, initial state + 300 steps
}

TEST(Cli, OutRefusesToOverwriteAnExistingFile) {
  const fs::path f = temp_file("keep.csv");
  { std::ofstream(f) << "precious\n"; }
  const Result r = run("run --steps 5 --out " + f.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("exists"), std::string::npos) << r.out;
  EXPECT_EQ(read(f), "precious\n");
  EXPECT_EQ(run("run --steps 5 --overwrite --out " + f.string()).status, 0);
}

// Outputs that would lose data (README.md, "The `impetus` tool"): every write is checked to the end, an
// input is never an output, a dangling link is not followed.
TEST(Cli, OutputsThatWouldLoseDataAreRefused) {
  const Result full = run("run --steps 5 --overwrite --out /dev/full");
  EXPECT_NE(full.status, 0);
  EXPECT_NE(full.out.find("/dev/full: writing failed"), std::string::npos) << full.out;

  const fs::path copy = temp_file("input.yaml");
  fs::copy_file(scene("spin.yaml"), copy, fs::copy_options::overwrite_existing);
  const std::string before = read(copy);
  const Result same = run("run " + copy.string() + " --steps 5 --overwrite --out " + copy.string());
  EXPECT_NE(same.status, 0);
  EXPECT_NE(same.out.find("is the scene being read"), std::string::npos) << same.out;
  EXPECT_EQ(read(copy), before);
  const Result same_fclib = run("fclib export " + copy.string() + " --overwrite --out " + copy.string());
  EXPECT_NE(same_fclib.out.find("is the scene being read"), std::string::npos) << same_fclib.out;
  EXPECT_EQ(read(copy), before);

  const fs::path link = temp_file("dangling.csv"), target = temp_file("not_there") / "x.csv";
  fs::remove(link);
  fs::create_symlink(target, link);
  const Result dangling = run("run --steps 5 --out " + link.string());
  EXPECT_NE(dangling.status, 0);
  EXPECT_NE(dangling.out.find("dangling"), std::string::npos) << dangling.out;
  EXPECT_FALSE(fs::exists(target));
}

// The contact log and the body table (README.md, "The `impetus` tool"): bullet_wall.yaml's 10 g ball at
// 200 m/s stops on the wall (restitution 0), so the normal impulses of the log add up to its momentum,
// 2 N s, to rounding; every row has 16 fields, names the wall and the bullet, and has a unit normal. The
// body table gives each body's mass and sizes as the scene wrote them.
TEST(Cli, ContactLogAndBodyTable) {
  const fs::path out = temp_file("wall.csv"), contacts = temp_file("wall_contacts.csv");
  const fs::path bodies = temp_file("wall.bodies.csv");
  const std::string wall = std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/bullet_wall.yaml";
  const Result r = run("run " + wall + " --duration 0.02 --overwrite --out " + out.string() + " --contacts " +
                       contacts.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("contact log"), std::string::npos) << r.out;
  std::istringstream log(read(contacts));
  std::string line;
  std::getline(log, line);
  EXPECT_EQ(line, "step,time,a,b,x,y,z,nx,ny,nz,depth,impulse,tx,ty,tz,mode");
  double total = 0.0;
  int rows = 0;
  while (std::getline(log, line)) {
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
    ASSERT_EQ(f.size(), 16u) << line;
    EXPECT_EQ(f[2], "wall");
    EXPECT_EQ(f[3], "bullet");
    EXPECT_NEAR(std::hypot(std::stod(f[7]), std::stod(f[8]), std::stod(f[9])), 1.0, 1e-12) << line;
    total += std::stod(f[11]);
    ++rows;
  }
  EXPECT_GT(rows, 0);
  EXPECT_NEAR(total, 0.01 * 200.0, 1e-12);
  EXPECT_EQ(read(bodies), "name,mass,fixed,shape,radius,length,size_x,size_y,size_z,normal_x,normal_y,normal_z,"
                          "offset,mesh,scale,collision\n"
                          "wall,0,true,box,,,0.05,2,2,,,,,,,\n"
                          "bullet,0.01,false,sphere,0.01,,,,,,,,,,,\n");

  // Existing files are kept without --overwrite (the body table too), and two outputs cannot share a
  // file; nothing is written when a path is refused.
  const std::string kept = read(contacts);
  const Result again = run("run " + wall + " --duration 0.02 --contacts " + contacts.string());
  EXPECT_NE(again.status, 0);
  EXPECT_NE(again.out.find("--contacts " + contacts.string() + ": file exists"), std::string::npos) << again.out;
  EXPECT_EQ(read(contacts), kept);
  const fs::path fresh = temp_file("fresh.csv");
  fs::remove(fresh);
  { std::ofstream(temp_file("fresh.bodies.csv")) << "mine\n"; }
  const Result table = run("run " + wall + " --duration 0.02 --out " + fresh.string());
  EXPECT_NE(table.out.find("its body table"), std::string::npos) << table.out;
  EXPECT_FALSE(fs::exists(fresh));
  EXPECT_EQ(read(temp_file("fresh.bodies.csv")), "mine\n");
  const Result shared = run("run " + wall + " --duration 0.02 --overwrite --out " + out.string() + " --contacts " +
                            out.string());
  EXPECT_NE(shared.status, 0);
  EXPECT_NE(shared.out.find("each output needs its own file"), std::string::npos) << shared.out;
  const Result full = run("run " + wall + " --duration 0.02 --overwrite --contacts /dev/full");
  EXPECT_NE(full.status, 0);
  EXPECT_NE(full.out.find("/dev/full: writing failed"), std::string::npos) << full.out;
}

// Output names the tool would have to guess at are refused before the run, naming the option and what
// it accepts; a new file in a folder that does not exist names the folder; a device takes CSV whatever
// its name (/dev/stdout prints the trajectory).
TEST(Cli, OutputNamesAreCheckedBeforeTheRun) {
  const Result txt = run("run --steps 5 --out " + temp_file("run.txt").string());
  EXPECT_NE(txt.status, 0);
  EXPECT_NE(txt.out.find("unknown extension '.txt'; use .csv"), std::string::npos) << txt.out;
  EXPECT_FALSE(fs::exists(temp_file("run.txt")));
  const Result log = run("run --steps 5 --contacts " + temp_file("log.json").string());
  EXPECT_NE(log.out.find("--contacts " + temp_file("log.json").string() + ": unknown extension"), std::string::npos)
      << log.out;
  const fs::path nowhere = temp_file("no_such_folder") / "run.csv";
  const Result missing = run("run --steps 5 --out " + nowhere.string());
  EXPECT_NE(missing.status, 0);
  EXPECT_NE(missing.out.find("does not exist"), std::string::npos) << missing.out;
  EXPECT_NE(missing.out.find("no_such_folder"), std::string::npos) << missing.out;
  const Result out = run("run --steps 2 --out /dev/stdout --overwrite");
  EXPECT_EQ(out.status, 0) << out.out;
  EXPECT_NE(out.out.find("step,time,body,x,y,z"), std::string::npos) << out.out;
}

// A body name with a comma or a quote is one CSV field (RFC 4180 quoting); the row keeps 16 fields.
TEST(Cli, NamesWithCommasAreQuotedInTheTrajectory) {
  const fs::path f = temp_file("quoted.csv");
  const Result r = run("run " + scene("spin.yaml") + " --steps 1 --overwrite --out " + f.string() +
                       " --set 'bodies.0.name=\"a,b\\\"c\"'");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string csv = read(f);
  EXPECT_NE(csv.find("\n0,0,\"a,b\"\"c\","), std::string::npos) << csv;
}

// Counts and numbers through flags: a duration or step count beyond 2^53 steps is refused, not run
// "forever" after an overflow; --dt keeps every digit (it was formatted with six decimals).
TEST(Cli, FlagsKeepTheirValueOrAreRefused) {
  const Result huge = run("run --duration 1e30");
  EXPECT_NE(huge.status, 0);
  EXPECT_NE(huge.out.find("--duration 1e+30: at dt"), std::string::npos) << huge.out;
  const Result steps = run("run --steps 18446744073709551615");
  EXPECT_NE(steps.status, 0);
  EXPECT_NE(steps.out.find("a run can count exactly (2^53)"), std::string::npos) << steps.out;
  for (const char* dt : {"1e-07", "0.0001234567"}) {
    const Result r = run(std::string("run --steps 3 --json --dt ") + dt);
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_EQ(nlohmann::json::parse(r.out)["simulated_time_s"].get<double>(), 3 * std::stod(dt)) << dt;
  }
}

// A step whose state stays finite but whose energy overflows fails the run (it printed inf and nan).
TEST(Cli, RunsWhoseAccountingOverflowsFail) {
  const Result r = run("run --steps 3 --dt 1e300");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("finite"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("inf"), std::string::npos) << r.out;
}

TEST(Cli, ResolveWithoutADetectorIsAClearError) {
  const Result r = run("resolve " + scene("spin.yaml"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("detector"), std::string::npos) << r.out;
}

// `impetus fclib export` then `impetus fclib solve --json`: the contract's fields, the problem's size as
// exported, and a solution that meets fclib's merit at the asked tolerance; impulses in the cones.
TEST(Cli, FclibExportThenSolveMeetsTheToleranceOnFclibsMerit) {
  const fs::path f = temp_file("pyramid.hdf5");
  fs::remove(f);
  const std::string pyramid = std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/pyramid_drop_10.yaml";
  const Result exported = run("fclib export " + pyramid +
                              " --set generators.0.pyramid.rows=4 --set generators.0.pyramid.friction=0.5 --out " + f.string());
  ASSERT_EQ(exported.status, 0) << exported.out;
  EXPECT_NE(exported.out.find("local problem of"), std::string::npos) << exported.out;
  const Result solved = run("fclib solve " + f.string() + " --tol 1e-9 --json");
  ASSERT_EQ(solved.status, 0) << solved.out;
  const auto j = nlohmann::json::parse(solved.out);
  for (const char* key : {"file", "contacts", "error", "iterations", "time_s", "converged", "reaction", "velocity"})
    EXPECT_TRUE(j.contains(key)) << key;
  const std::size_t contacts = j["contacts"];
  EXPECT_NE(exported.out.find("problem of " + std::to_string(contacts) + " contacts"), std::string::npos) << exported.out;
  EXPECT_TRUE(j["converged"].get<bool>());
  EXPECT_LE(j["error"].get<double>(), 1e-9);
  ASSERT_EQ(j["reaction"].size(), 3 * contacts);
  ASSERT_EQ(j["velocity"].size(), 3 * contacts);
  for (std::size_t c = 0; c < contacts; ++c) {  // r in the cone ‖r_t‖ ≤ 0.5 r_n, u_n ≥ 0 (to the tolerance)
    const double rn = j["reaction"][3 * c], rt = std::hypot(j["reaction"][3 * c + 1].get<double>(), j["reaction"][3 * c + 2].get<double>());
    EXPECT_GE(rn, -1e-12);
    EXPECT_LE(rt, 0.5 * rn + 1e-9);
    EXPECT_GE(j["velocity"][3 * c].get<double>(), -1e-8);
  }
}

TEST(Cli, FclibRefusesWhatItCannotUse) {
  const fs::path f = temp_file("keep.hdf5");
  { std::ofstream(f) << "precious\n"; }
  const std::string pyramid = std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/pyramid_drop_10.yaml";
  Result r = run("fclib export " + pyramid + " --out " + f.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("file exists; pass --overwrite"), std::string::npos) << r.out;
  EXPECT_EQ(read(f), "precious\n");

  r = run("fclib solve " + f.string());  // not HDF5
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find(f.string() + ": not an HDF5 file"), std::string::npos) << r.out;

  const std::string chain = std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/pendulum_chain.yaml";
  r = run("fclib export " + chain + " --out " + temp_file("chain.hdf5").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("constraints"), std::string::npos) << r.out;
}

}  // namespace

namespace {

// ---- The run summary (README.md, "The run summary") ----

// One body's rows of a trajectory CSV: position z and velocity (vx, vy, vz) per recorded step.
struct Track {
  std::vector<double> z;
  std::vector<Eigen::Vector3d> v;
};

Track read_track(const fs::path& file, const std::string& body) {
  std::istringstream lines(read(file));
  std::string line;
  std::getline(lines, line);  // header
  Track t;
  while (std::getline(lines, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (cells.size() != 16 || cells[2] != body) continue;
    t.z.push_back(std::stod(cells[5]));
    t.v.emplace_back(std::stod(cells[10]), std::stod(cells[11]), std::stod(cells[12]));
  }
  return t;
}

Eigen::Vector3d vec3(const nlohmann::json& j) {
  return Eigen::Vector3d(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
}

// A 2 kg ball falls 1 m onto a fixed plane with e = 0. Through the step that stops it, the contacts
// dissipate exactly ½ m v² of its speed at impact (v = its velocity after that step's gravity), and
// gravity's work is m g Δh; the balance closes and nothing is flagged. 1e-9 relative.
TEST(CliSummary, BallDropDissipatesItsImpactEnergyAndGravityDoesMgDh) {
  const double m = 2.0, g = 9.81, dt = 1e-3;
  const fs::path csv = temp_file("drop.csv");
  const Result full = run("run " + scene("drop.yaml") + " --steps 600 --json --overwrite --out " + csv.string());
  ASSERT_EQ(full.status, 0) << full.out;
  const Track ball = read_track(csv, "ball");
  ASSERT_EQ(ball.v.size(), 601u);
  // The impact step: the first whose velocity is not the free-fall prediction v + g dt.
  std::size_t impact = 0;
  for (std::size_t k = 1; k < ball.v.size() && impact == 0; ++k)
    if (ball.v[k].z() != ball.v[k - 1].z() + dt * -g) impact = k;
  ASSERT_GT(impact, 400u);
  const double v_impact = ball.v[impact - 1].z() + dt * -g;
  EXPECT_LT(std::abs(ball.v[impact].z()), 1e-9 * std::abs(v_impact));  // e = 0: stopped in that step

  const Result upto = run("run " + scene("drop.yaml") + " --steps " + std::to_string(impact) + " --json");
  ASSERT_EQ(upto.status, 0) << upto.out;
  const auto e = nlohmann::json::parse(upto.out)["energy"];
  const double impact_energy = 0.5 * m * v_impact * v_impact;
  std::printf("drop: impact at step %zu, v = %.9g m/s, 1/2 m v^2 = %.12g J, dissipated %.12g J\n", impact, v_impact,
              impact_energy, e["dissipated_by_contacts_j"].get<double>());
  EXPECT_NEAR(e["dissipated_by_contacts_j"].get<double>(), impact_energy, 1e-9 * impact_energy);
  EXPECT_NEAR(e["gravity_work_j"].get<double>(), m * g * (ball.z[0] - ball.z[impact]), 1e-9 * impact_energy);
  // The balance closes on the trajectory's kinetic energy; what integration gained (gravity's kick in
  // the impact step, which the contact took back) is not flagged.
  const double kinetic_change = 0.5 * m * (ball.v[impact].squaredNorm() - ball.v[0].squaredNorm());
  EXPECT_NEAR(kinetic_change,
              -e["dissipated_by_contacts_j"].get<double>() + e["position_correction_j"].get<double>() +
                  e["gravity_work_j"].get<double>() + e["integration_j"].get<double>(),
              1e-9 * impact_energy);
  EXPECT_LT(e["integration_gain_j"].get<double>(), 1e-9 * impact_energy);
  EXPECT_TRUE(e["unexpected"].empty()) << e.dump();

  // Over the whole run, resting steps included: contacts absorb each step's gravity, and the balance
  // matches the trajectory step by step.
  const auto ef = nlohmann::json::parse(full.out)["energy"];
  double resolve_change = 0.0;
  for (std::size_t k = 1; k < ball.v.size(); ++k) {
    const double predicted = ball.v[k - 1].z() + dt * -g;
    resolve_change += 0.5 * m * (ball.v[k].squaredNorm() - predicted * predicted);
  }
  EXPECT_NEAR(ef["dissipated_by_contacts_j"].get<double>(), -resolve_change, 1e-9 * impact_energy);
  EXPECT_NEAR(ef["gravity_work_j"].get<double>(), m * g * (ball.z.front() - ball.z.back()), 1e-9 * impact_energy);
  EXPECT_TRUE(ef["unexpected"].empty()) << ef.dump();
}

// A box sliding down a 30° slope with friction: the impulses it receives from the fixed ground
// (normal and friction) and gravity explain its momentum change; the drift left is rounding.
TEST(CliSummary, SlidingBoxMomentumIsExplainedByTheFixedGround) {
  const Result r = run("run " + scene("slope.yaml") + " --duration 1 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  const auto& p = j["momentum"];
  const Eigen::Vector3d change = vec3(p["linear_change_kg_m_per_s"]);
  const Eigen::Vector3d from_ground = vec3(p["fixed_body_impulse_n_s"]);
  const Eigen::Vector3d from_gravity = vec3(p["gravity_impulse_n_s"]);
  std::printf("slope: dp = (%.6g, %.6g, %.6g), ground (%.6g, %.6g, %.6g), drift %.3g kg m/s, angular %.3g\n",
              change.x(), change.y(), change.z(), from_ground.x(), from_ground.y(), from_ground.z(),
              j["linear_momentum_drift"].get<double>(), j["angular_momentum_drift"].get<double>());
  EXPECT_GT(change.x(), 0.5);        // it slides: a ≈ 0.657 m/s² for 1 s
  EXPECT_GT(from_ground.z(), 8.0);   // the normal impulse carries the weight's normal part, 8.5 N s
  EXPECT_LT(from_ground.x(), -4.0);  // friction μ N ≈ 4.25 N s up the slope
  EXPECT_LT((change - from_gravity - from_ground).norm(), 1e-9);
  EXPECT_LT(j["linear_momentum_drift"].get<double>(), 1e-9);
  const Result text = run("run " + scene("slope.yaml") + " --duration 1");
  EXPECT_NE(text.out.find("from fixed bodies: linear"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("drift (unexplained)"), std::string::npos) << text.out;
}

// Applied loads do work the balance accounts for (tests/cli/scenes/loads.yaml): F·Δx for the world-frame
// force (Δx from the closed form of the step, 1e-9 relative) and dt τ·ω per step for the body-frame
// torque; the integration remainder is then exactly the symplectic step's deficit −F² dt² N/(2m)
// − τ² dt² N/(2J) (1e-9 relative), a loss, not flagged; the momentum the force adds is N dt F.
TEST(CliSummary, AppliedLoadsDoTheWorkTheClosedFormsGive) {
  const Result r = run("run " + scene("loads.yaml") + " --steps 1000 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  const double dt = 1e-3, n = 1000, force = 3.0, m = 2.0, torque = 0.25, inertia = 0.4 * 1.0 * 0.25;
  const double force_work = force * force * dt * dt * n * (n + 1) / (2.0 * m);
  const double torque_work = torque * torque * dt * dt * n * (n + 1) / (2.0 * inertia);
  const double deficit = -(force * force / m + torque * torque / inertia) * dt * dt * n / 2.0;
  const auto& e = j["energy"];
  EXPECT_NEAR(e["applied_load_work_j"].get<double>(), force_work + torque_work, 1e-9 * (force_work + torque_work));
  EXPECT_NEAR(e["integration_j"].get<double>(), deficit, 1e-9 * std::abs(deficit));
  EXPECT_TRUE(e["unexpected"].empty()) << e.dump();
  const Eigen::Vector3d impulse = vec3(j["momentum"]["applied_load_impulse_n_s"]);
  EXPECT_NEAR(impulse.x(), n * dt * force, 1e-12);
  EXPECT_LT(j["linear_momentum_drift"].get<double>(), 1e-12);
  const Result text = run("run " + scene("loads.yaml") + " --steps 1000");
  EXPECT_NE(text.out.find("J work of applied loads"), std::string::npos) << text.out;
}

// Fixed bodies that move (assets/scenes/conveyor.yaml: a belt, a platform, a turntable and a pusher) put
// energy in through their contacts: the summary reports that work apart, so what contacts dissipate stays
// ≥ 0 and nothing is flagged.
TEST(CliSummary, WorkOfMovingFixedBodiesIsReportedNotFlagged) {
  const std::string args = "run " + std::string(IMPETUS_BUNDLED_SCENES) + "/conveyor.yaml --duration 1.5";
  const auto j = nlohmann::json::parse(run(args + " --json").out);
  const auto& e = j["energy"];
  EXPECT_GT(e["prescribed_motion_work_j"].get<double>(), 0.08) << e.dump();  // the pusher's m U² alone
  EXPECT_GT(e["dissipated_by_contacts_j"].get<double>(), 0.0) << e.dump();
  EXPECT_TRUE(e["unexpected"].empty()) << e.dump();
  const Result text = run(args);
  EXPECT_NE(text.out.find("J work of moving fixed bodies"), std::string::npos) << text.out;
}

// A body pinned deep in the ground: the summary reports the bounded corrections ("resolver limits") and
// the ball stays within the bound of where it was (0.4 m a step, README "Reliability"; it does not move
// at all here, the correction being refused).
TEST(CliSummary, BoundedCorrectionsAreReported) {
  const std::string args = "run " + scene("pinned_in_ground.yaml") + " --steps 50";
  const auto j = nlohmann::json::parse(run(args + " --json").out);
  EXPECT_GT(j["resolver"]["corrections_clamped"].get<std::uint64_t>(), 0u) << j["resolver"].dump();
  EXPECT_LE(j["resolver"]["largest_correction_m"].get<double>(), 0.4) << j["resolver"].dump();
  EXPECT_LE(j["max_penetration_m"].get<double>(), 1.0 + 1e-9);
  const Result text = run(args);
  EXPECT_NE(text.out.find("position corrections clamped"), std::string::npos) << text.out;
}

// assets/scenes/bullet_wall.yaml (a 2 cm ball at 200 m/s against a 5 cm wall): the summary counts the
// pair tests the detector looked ahead for, in text and JSON, and none without the look-ahead; the ball
// loses its 200 J to the wall (restitution 0) only with it.
TEST(CliSummary, SpeculativeContactsAreCounted) {
  const std::string args = "run " + std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/bullet_wall.yaml --duration 0.02";
  const auto j = nlohmann::json::parse(run(args + " --json").out);
  EXPECT_GT(j["contacts_per_step"]["speculative_pairs"].get<std::uint64_t>(), 0u) << j["contacts_per_step"].dump();
  EXPECT_NEAR(j["energy"]["final_j"].get<double>(), 0.0, 1e-9) << j["energy"].dump();
  EXPECT_NE(run(args).out.find("looked ahead for fast bodies"), std::string::npos);
  const auto off = nlohmann::json::parse(run(args + " --set modules.detector.speculative=false --json").out);
  EXPECT_EQ(off["contacts_per_step"]["speculative_pairs"].get<std::uint64_t>(), 0u);
  EXPECT_NEAR(off["energy"]["final_j"].get<double>(), 200.0, 1e-9) << off["energy"].dump();
}

// The friction line says "none" where no body has friction (drop.yaml): its stick/slide counts would
// only tell which frictionless contacts had no tangential velocity. With friction (slope.yaml) it counts
// sliding contacts and the energy friction dissipated (> 0 for a box sliding 1 s).
TEST(CliSummary, FrictionLineSaysNoneWithoutFriction) {
  const Result frictionless = run("run " + scene("drop.yaml") + " --steps 600");
  EXPECT_NE(frictionless.out.find("friction              none"), std::string::npos) << frictionless.out;
  const auto j = nlohmann::json::parse(run("run " + scene("drop.yaml") + " --steps 600 --json").out);
  EXPECT_FALSE(j["friction"]["modelled"].get<bool>());
  const auto js = nlohmann::json::parse(run("run " + scene("slope.yaml") + " --duration 1 --json").out);
  EXPECT_TRUE(js["friction"]["modelled"].get<bool>());
  EXPECT_GT(js["friction"]["sliding_contacts"].get<std::uint64_t>(), 0u);
  EXPECT_GT(js["friction"]["dissipated_j"].get<double>(), 0.0);
}

// A box resting flat on four corners: redundant contact sets solved by minimum norm, none singular,
// and the summary says so in those words.
TEST(CliSummary, RestingBoxReportsRedundantContactSetsNotSingular) {
  const Result r = run("run " + scene("resting_box.yaml") + " --steps 120 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["resolver"]["redundant_systems"].get<std::uint64_t>(), 0u) << r.out;
  EXPECT_EQ(j["resolver"]["singular_systems"].get<std::uint64_t>(), 0u) << r.out;
  EXPECT_TRUE(j["energy"]["unexpected"].empty()) << r.out;
  const Result text = run("run " + scene("resting_box.yaml") + " --steps 120");
  EXPECT_NE(text.out.find("redundant contact sets (minimum-norm)"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find(" 0 singular (failed)"), std::string::npos) << text.out;
}

// The summary names the resolver with the options the scene or --set gave it.
TEST(CliSummary, ShowsTheResolverAndItsOptions) {
  const std::string args = "run " + scene("resting_box.yaml") + " --steps 5 --set modules.resolver.mode=paper";
  const Result text = run(args);
  ASSERT_EQ(text.status, 0) << text.out;
  EXPECT_NE(text.out.find("resolver ledas (mode: paper)"), std::string::npos) << text.out;
  const auto j = nlohmann::json::parse(run(args + " --json").out);
  EXPECT_EQ(j["modules"]["resolver"], "ledas");
  EXPECT_EQ(j["module_options"]["resolver"]["mode"], "paper");
  const Result plain = run("run " + scene("resting_box.yaml") + " --steps 5");
  EXPECT_NE(plain.out.find("resolver ledas\n"), std::string::npos) << plain.out;
}

// `resolver: none` still detects (README.md): the summary says the contacts were not resolved.
TEST(CliSummary, ResolverNoneSaysContactsWereDetectedNotResolved) {
  const std::string args = "run " + scene("drop.yaml") + " --steps 600 --resolver none";
  const Result text = run(args);
  ASSERT_EQ(text.status, 0) << text.out;
  EXPECT_NE(text.out.find("detected, not resolved"), std::string::npos) << text.out;
  const auto j = nlohmann::json::parse(run(args + " --json").out);
  EXPECT_FALSE(j["contacts_per_step"]["resolved"].get<bool>());
  EXPECT_GT(j["contacts_per_step"]["max"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(j["energy"]["dissipated_by_contacts_j"].get<double>(), 0.0);
}

// Integration that gains energy on a free body is flagged: the `momentum` integrator lets a tumbling
// box's kinetic energy grow at first order in dt (README.md); `splitting` bounds it and is not flagged.
TEST(CliSummary, IntegrationGainIsFlaggedOnlyWhenItIsOne) {
  const Result momentum = run("run " + scene("spin.yaml") + " --duration 2");
  EXPECT_NE(momentum.out.find("unexpected:         integration gained"), std::string::npos) << momentum.out;
  const auto jm = nlohmann::json::parse(run("run " + scene("spin.yaml") + " --duration 2 --json").out);
  EXPECT_GT(jm["energy"]["integration_gain_j"].get<double>(), 0.1);
  EXPECT_EQ(jm["energy"]["unexpected"].size(), 1u);
  const auto js =
      nlohmann::json::parse(run("run " + scene("spin.yaml") + " --duration 2 --json --integrator splitting").out);
  EXPECT_TRUE(js["energy"]["unexpected"].empty()) << js["energy"].dump();
  // Without contacts or gravity the whole change is integration's: drift_j keeps its old value.
  EXPECT_DOUBLE_EQ(jm["energy"]["drift_j"].get<double>(), jm["energy"]["change_j"].get<double>());
}

TEST(CliSummary, RunHelpExplainsTheTerms) {
  const Result r = run("run --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("redundant contact sets (minimum-norm)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("singular (failed)"), std::string::npos) << r.out;
}

}  // namespace
