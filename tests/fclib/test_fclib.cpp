// Contact problems in fclib's form (core/fclib): a scene's problem written and read back unchanged in
// both forms, solved from the file by the ledas plugin to the velocities `impetus resolve` applies,
// fclib's merit agreeing with the natural-map residual, and malformed files refused with their defect.
#include "impetus/core/error.hpp"
#include "impetus/engine/scene.hpp"
#include "impetus/engine/world.hpp"
#include "impetus/fclib/fclib.hpp"
#include "impetus/plugins/host.hpp"
#include "impetus/resolution/ledas/frictional_solver.hpp"

#include <gtest/gtest.h>

#include <hdf5.h>
#include <hdf5_hl.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

namespace {

using namespace impetus;
namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("impetus_fclib_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / name;
  fs::remove(file);
  return file;
}

std::string scene_path(const char* name) { return std::string(IMPETUS_SOURCE_DIR) + "/assets/scenes/" + name; }

// A world from a bundled scene with overrides, and `prepare` applied to its bodies (velocities,
// restitution) before anything is detected.
struct Case {
  const char* scene;
  std::vector<std::string> overrides;
  std::function<void(std::span<RigidBody>)> prepare;
  bool unique = false;  ///< Coulomb's problem has one solution (sticking, resting): velocities compare
};

std::unique_ptr<World> make_world(const Case& c, PluginHost& host) {
  std::vector<SceneOverride> overrides;
  for (const std::string& o : c.overrides) overrides.push_back(parse_override(o));
  const Scene scene = load_scene(scene_path(c.scene), overrides);
  std::unique_ptr<World> world = build_world(scene, host);
  for (RigidBody& b : world->bodies()) b.material.restitution = 0.0;  // the exported problem is the inelastic impact
  if (c.prepare) c.prepare(world->bodies());
  return world;
}

// The velocity a step's gravity gives every movable body: the problem a resting scene solves each step.
std::function<void(std::span<RigidBody>)> gravity_kick(double dt, Vec3 extra = Vec3::Zero()) {
  return [dt, extra](std::span<RigidBody> bodies) {
    for (RigidBody& b : bodies)
      if (!b.fixed) b.velocity += Vec3(0, 0, -9.81) * dt + extra;
  };
}

// Deterministic pseudo-random velocities of up to 1 m/s and 2 rad/s: a cluster hit from all sides.
void random_velocities(std::span<RigidBody> bodies) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (RigidBody& b : bodies)
    if (!b.fixed) {
      b.velocity = Vec3(unit(random), unit(random), unit(random) - 1.0);
      b.angular_velocity = 2.0 * Vec3(unit(random), unit(random), unit(random));
    }
}

std::vector<Case> cases() {
  return {
      {"pyramid_drop_10.yaml", {"generators.0.pyramid.rows=6", "generators.0.pyramid.friction=0.5"}, nullptr},
      {"pyramid_drop_10.yaml", {"generators.0.pyramid.rows=5", "generators.0.pyramid.friction=0.2"}, nullptr},
      {"pyramid4.yaml", {"modules.resolver=ledas"}, [](std::span<RigidBody> b) {
         for (RigidBody& body : b) body.material.friction = 0.3;
         random_velocities(b);
       }},
      {"friction_stack_10.yaml", {}, gravity_kick(1.0 / 60.0, Vec3(0.05, 0.02, 0.0)), true},
      {"friction_card_house.yaml", {}, gravity_kick(1.0 / 240.0), true},
      {"figure2.yaml", {"bodies.beam.friction=0.5", "bodies.plank.friction=0.5", "bodies.plank.velocity=[0.4,0.1,-1]"},
       nullptr, true},
      // Fixed bodies with prescribed motion (a belt, a platform, a turntable): their velocity at each
      // contact is in w. Boxes slipping on four corners: impulses not unique.
      {"conveyor.yaml", {}, gravity_kick(1.0 / 240.0)},
  };
}

std::string label(const Case& c) {
  std::string out = c.scene;
  for (const std::string& o : c.overrides) out += " " + o;
  return out;
}

// The case's contact problem after one detection.
fclib::SceneProblem detected_problem(const Case& c, PluginHost& host) {
  std::unique_ptr<World> world = make_world(c, host);
  world->detect_contacts();
  return fclib::scene_problem(world->bodies(), world->contacts(), world->settings().dt);
}

// The dropped sphere pyramid K = 10 (pyramid_drop_10.yaml, 145 contacts) with friction μ = `mu`, its
// contact problem after one detection.
fclib::LocalProblem dropped_pyramid_10(PluginHost& host, const std::string& mu) {
  const Case c{"pyramid_drop_10.yaml", {"generators.0.pyramid.friction=" + mu}, nullptr};
  fclib::LocalProblem problem = detected_problem(c, host).local;
  EXPECT_EQ(problem.contacts(), 145u);
  return problem;
}

double largest(const fclib::SparseMatrix& a) { return a.nonZeros() > 0 ? a.coeffs().cwiseAbs().maxCoeff() : 0.0; }

TEST(Fclib, ASceneProblemSurvivesTheFileBitForBitInBothForms) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(label(c));
    PluginHost host;
    const fclib::SceneProblem problem = detected_problem(c, host);
    ASSERT_GT(problem.contacts.size(), 0u);

    const fs::path local_file = temp_file("local.hdf5"), global_file = temp_file("global.hdf5");
    fclib::write_problem(local_file, problem.local);
    fclib::write_problem(global_file, problem.global);
    const fclib::FileProblem local = fclib::read_problem(local_file);
    ASSERT_EQ(local.form, fclib::Form::local);
    EXPECT_EQ(largest(local.local.w - problem.local.w), 0.0);  // HDF5 keeps doubles exactly
    EXPECT_EQ((local.local.q - problem.local.q).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(local.local.mu, problem.local.mu);

    // The global form reduced by a factorization of M agrees with W from the bodies' own inverses to
    // rounding (M's blocks are well conditioned: relative 1e-12 of W's largest entry).
    const fclib::FileProblem global = fclib::read_problem(global_file);
    ASSERT_EQ(global.form, fclib::Form::global);
    EXPECT_EQ(largest(global.global.h - problem.global.h), 0.0);
    EXPECT_LE(largest(global.local.w - problem.local.w), 1e-12 * largest(problem.local.w));
    EXPECT_LE((global.local.q - problem.local.q).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + problem.local.q.norm()));
  }
}

// Export → solve from the file with the ledas plugin → the velocities `impetus resolve` applies. Two checks:
//  1. the impulses World::detect_and_resolve applied (Contact::impulse, tangent_impulse) solve the exported
//     problem (natural-map residual ≤ 1e-10 (1 + ‖q‖)), and W r + q is the velocity they produced (u = Hᵀ v⁺
//     + w with the bodies' velocities after it) to 1e-12 m/s: the file holds exactly the problem resolved;
//  2. the problem solved from the file converges, and where Coulomb's problem has one solution its velocities
//     are the applied ones to 1e-9 m/s. Where it has several (the dropped pyramids and the random cluster,
//     slipping contacts on redundant sets), both answers are exact solutions that may differ (by up to
//     2e-4 m/s on the dropped pyramid of 6 rows), and only check 1 and convergence apply.
TEST(Fclib, TheExportedProblemIsTheProblemResolveSolves) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(label(c));
    PluginHost host;
    const fclib::SceneProblem problem = detected_problem(c, host);
    const fs::path file = temp_file("roundtrip.hdf5");
    fclib::write_problem(file, problem.local);
    const fclib::LocalProblem read = fclib::read_problem(file).local;

    // 1. What the world applied, in the problem's rows.
    std::unique_ptr<World> resolved = make_world(c, host);
    ASSERT_TRUE(resolved->detect_and_resolve().ok);
    fclib::Vector v(static_cast<Eigen::Index>(6 * problem.bodies.size()));
    for (std::size_t s = 0; s < problem.bodies.size(); ++s) {
      v.segment<3>(static_cast<Eigen::Index>(6 * s)) = resolved->bodies()[problem.bodies[s]].velocity;
      v.segment<3>(static_cast<Eigen::Index>(6 * s + 3)) = resolved->bodies()[problem.bodies[s]].angular_velocity;
    }
    const fclib::Vector applied_u = problem.global.h.transpose() * v + problem.global.w;  // H from before
    fclib::Vector applied_r(static_cast<Eigen::Index>(read.rows()));
    for (std::size_t k = 0; k < problem.contacts.size(); ++k) {
      const Contact& contact = resolved->contacts()[problem.contacts[k]];
      Vec3 t1, t2;
      tangent_basis(contact.normal, t1, t2);
      applied_r.segment<3>(static_cast<Eigen::Index>(3 * k)) =
          Vec3(contact.impulse, contact.tangent_impulse.dot(t1), contact.tangent_impulse.dot(t2));
    }
    EXPECT_LE(fclib::natural_map_residual(read, applied_r), 1e-10 * (1.0 + read.q.norm()));
    EXPECT_LE((read.w * applied_r + read.q - applied_u).cwiseAbs().maxCoeff(), 1e-12);

    // 2. Solved from the file by the plugin.
    PluginRequest request;
    request.kind = ModuleKind::resolver;
    request.name = "ledas";
    const std::shared_ptr<CollisionResolver> ledas = host.create_resolver(request);
    fclib::Vector r = fclib::Vector::Zero(static_cast<Eigen::Index>(read.rows())), u = r;
    LocalContactSolution solution;
    solution.r = r.data();
    solution.u = u.data();
    const double tolerance = std::max(1e-10 * read.q.norm(), 1e-12);  // as ledas solves an island
    ASSERT_TRUE(ledas->solve_contact_problem(read.view(tolerance), solution));
    EXPECT_TRUE(solution.converged) << "residual " << solution.residual;
    EXPECT_LE(fclib::natural_map_residual(read, r), tolerance);
    EXPECT_LE(fclib::merit(read, r), 1e-10);
    if (c.unique) {
      EXPECT_LE((applied_u - u).cwiseAbs().maxCoeff(), 1e-9) << "largest velocity " << u.cwiseAbs().maxCoeff();
    }
  }
}

// fclib's merit is the natural-map residual over 1 + √‖q‖ (its MERIT_1): checked on the solution and on
// impulses that solve nothing, where both are far from zero.
TEST(Fclib, FclibsMeritIsTheNaturalMapResidualScaledAsFclibScalesIt) {
  PluginHost host;
  const fclib::SceneProblem problem = detected_problem(cases()[2], host);
  const fclib::LocalProblem& local = problem.local;
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    fclib::Vector r(static_cast<Eigen::Index>(local.rows()));
    for (Eigen::Index i = 0; i < r.size(); ++i) r(i) = trial == 0 ? 0.0 : unit(random);
    const double own = fclib::natural_map_residual(local, r) / (1.0 + std::sqrt(local.q.norm()));
    EXPECT_GT(own, 1e-3);
    EXPECT_NEAR(fclib::merit(local, r), own, 1e-13 * own) << "trial " << trial;
  }
}


// One contact's natural map (the measure bench_peers applies to other engines' impulses and velocities) is
// zero exactly on Coulomb's three cases and measures the distance from them otherwise (μ = 0.5).
TEST(Fclib, OneContactsNaturalMapVanishesExactlyOnCoulombsCases) {
  const double mu = 0.5;
  using V = Eigen::Vector3d;
  // Separating with no impulse; sticking with the impulse inside the cone; sliding with the impulse on the
  // cone's edge, opposite the slip.
  EXPECT_EQ(fclib::natural_map(V(0, 0, 0), V(0.3, 0.1, -0.2), mu).norm(), 0.0);
  EXPECT_NEAR(fclib::natural_map(V(1.0, 0.2, -0.1), V(0, 0, 0), mu).norm(), 0.0, 1e-15);
  EXPECT_NEAR(fclib::natural_map(V(1.0, -0.3, -0.4), V(0, 0.6, 0.8), mu).norm(), 0.0, 1e-15);
  // Not Coulomb: an impulse while separating (the impulse itself is the error), an impulse outside the
  // cone at rest, friction along the slip instead of against it, an approach left with no impulse.
  EXPECT_NEAR(fclib::natural_map(V(0.2, 0, 0), V(1.0, 0, 0), mu).norm(), 0.2, 1e-15);
  EXPECT_GT(fclib::natural_map(V(1.0, 0.8, 0), V(0, 0, 0), mu).norm(), 0.1);
  EXPECT_GT(fclib::natural_map(V(1.0, 0.3, 0.4), V(0, 0.6, 0.8), mu).norm(), 0.5);
  EXPECT_NEAR(fclib::natural_map(V(0, 0, 0), V(-0.7, 0, 0), mu).norm(), 0.7, 1e-15);
}
// A problem with equality rows (fclib's mixed form V, R, s) keeps them through the file, and a joint
// row holds (u = 0) in the solution: two unit masses, one contact and one equality row between them.
TEST(Fclib, MixedRowsSurviveTheFileAndHoldInTheSolution) {
  fclib::LocalProblem p;
  p.mu = {0.5};
  p.equalities = 1;
  // W of a contact (rows 0..2) and a joint row along the normal's t1, two free unit masses: G M⁻¹ Gᵀ = 2 on
  // the diagonal, the joint row shares t1 with the contact.
  std::vector<Eigen::Triplet<double>> t{{0, 0, 2.0}, {1, 1, 2.0}, {2, 2, 2.0}, {3, 3, 2.0}, {1, 3, 2.0}, {3, 1, 2.0}};
  p.w.resize(4, 4);
  p.w.setFromTriplets(t.begin(), t.end());
  p.q = fclib::Vector(4);
  p.q << -1.0, 0.3, 0.0, 0.1;
  const fs::path file = temp_file("mixed.hdf5");
  fclib::write_problem(file, p);
  const fclib::LocalProblem read = fclib::read_problem(file).local;
  ASSERT_EQ(read.equalities, 1u);
  EXPECT_EQ(largest(read.w - p.w), 0.0);
  EXPECT_EQ((read.q - p.q).cwiseAbs().maxCoeff(), 0.0);

  PluginHost host;
  PluginRequest request;
  request.kind = ModuleKind::resolver;
  request.name = "ledas";
  const auto ledas = host.create_resolver(request);
  fclib::Vector r = fclib::Vector::Zero(4), u = r;
  LocalContactSolution solution;
  solution.r = r.data();
  solution.u = u.data();
  ASSERT_TRUE(ledas->solve_contact_problem(read.view(1e-12), solution));
  EXPECT_TRUE(solution.converged);
  EXPECT_NEAR(u(3), 0.0, 1e-12);           // the joint row holds
  EXPECT_NEAR(u(0), 0.0, 1e-12);           // the contact closes (it approached at 1 m/s)
  EXPECT_NEAR(r(0), 0.5, 1e-12);           // r_n = 1 m/s / W_nn
  EXPECT_LE(std::hypot(r(1), r(2)), 0.5 * r(0) + 1e-12);
  EXPECT_LE(fclib::merit(read, r), 1e-12);
}

// --- malformed files: every defect named, nothing read out of bounds (the test runs under ASan too) ---

fclib::LocalProblem small_problem() {
  fclib::LocalProblem p;
  p.info.title = "two contacts";
  p.mu = {0.5, 0.5};
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < 6; ++i) t.emplace_back(i, i, 2.0);
  t.emplace_back(0, 3, 1.0);
  t.emplace_back(3, 0, 1.0);
  p.w.resize(6, 6);
  p.w.setFromTriplets(t.begin(), t.end());
  p.q = fclib::Vector::Zero(6);
  p.q(0) = -1.0;
  p.q(3) = -0.5;
  return p;
}

// Writes small_problem() and then lets `edit` damage the file through HDF5 itself.
fs::path damaged(const std::string& name, const std::function<void(hid_t)>& edit) {
  const fs::path file = temp_file(name);
  fclib::write_problem(file, small_problem());
  const hid_t id = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  edit(id);
  H5Fclose(id);
  return file;
}

void replace_doubles(hid_t file, const char* path, std::vector<double> values) {
  H5Ldelete(file, path, H5P_DEFAULT);
  const hsize_t n = values.size();
  H5LTmake_dataset_double(file, path, 1, &n, values.data());
}

void replace_int(hid_t file, const char* path, int value) {
  H5Ldelete(file, path, H5P_DEFAULT);
  const hsize_t n = 1;
  H5LTmake_dataset_int(file, path, 1, &n, &value);
}

void expect_refused(const fs::path& file, const std::string& words) {
  try {
    fclib::read_problem(file);
    ADD_FAILURE() << file << " was accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find(words), std::string::npos) << message;
  }
}

TEST(FclibFiles, MalformedFilesAreRefusedWithTheirDefect) {
  {
    const fs::path text = temp_file("text.hdf5");
    std::ofstream(text) << "dt: 0.01\n";
    expect_refused(text, "not an HDF5 file");
  }
  expect_refused(damaged("no_problem.hdf5", [](hid_t f) { H5Ldelete(f, "/fclib_local", H5P_DEFAULT); }),
                 "no fclib problem");
  expect_refused(damaged("negative_mu.hdf5", [](hid_t f) { replace_doubles(f, "/fclib_local/vectors/mu", {0.5, -0.1}); }),
                 "mu[1]");
  expect_refused(damaged("nan_q.hdf5", [](hid_t f) {
                   replace_doubles(f, "/fclib_local/vectors/q", {-1, 0, 0, std::nan(""), 0, 0});
                 }),
                 "q[3] is not finite");
  expect_refused(damaged("short_q.hdf5", [](hid_t f) { replace_doubles(f, "/fclib_local/vectors/q", {-1, 0, 0}); }),
                 "/fclib_local/vectors/q has 3 entries where fclib expects 6");
  expect_refused(damaged("long_x.hdf5", [](hid_t f) {
                   replace_doubles(f, "/fclib_local/W/x", std::vector<double>(100, 1.0));
                 }),
                 "/fclib_local/W/x has 100 entries");
  expect_refused(damaged("spacedim.hdf5", [](hid_t f) { replace_int(f, "/fclib_local/spacedim", 2); }),
                 "spacedim is 2");
  expect_refused(damaged("huge_n.hdf5", [](hid_t f) { replace_int(f, "/fclib_local/W/n", 2000000000); }), "out of range");
  expect_refused(damaged("bad_nz.hdf5", [](hid_t f) { replace_int(f, "/fclib_local/W/nz", -7); }), "nz is -7");
  expect_refused(damaged("asymmetric.hdf5", [](hid_t f) {
                   // W's entries in column order: (0,0) (3,0) (1,1) (2,2) (0,3) (3,3) (4,4) (5,5); (3,0) changes.
                   replace_doubles(f, "/fclib_local/W/x", {2, 1.5, 2, 2, 1, 2, 2, 2});
                 }),
                 "W is not symmetric");
  expect_refused(damaged("row_range.hdf5", [](hid_t f) {
                   H5Ldelete(f, "/fclib_local/W/i", H5P_DEFAULT);
                   const std::vector<int> rows{0, 9, 1, 2, 0, 3, 4, 5};
                   const hsize_t n = rows.size();
                   H5LTmake_dataset_int(f, "/fclib_local/W/i", 1, &n, rows.data());
                 }),
                 "outside its 6 × 6");
  expect_refused(damaged("string_q.hdf5", [](hid_t f) {
                   H5Ldelete(f, "/fclib_local/vectors/q", H5P_DEFAULT);
                   H5LTmake_dataset_string(f, "/fclib_local/vectors/q", "minus one");
                 }),
                 "/fclib_local/vectors/q");
  expect_refused(damaged("vlen_title.hdf5", [](hid_t f) {
                   // fclib reads a title into as many bytes as the type's size: a variable-length string would not fit.
                   H5Ldelete(f, "/fclib_local/info/title", H5P_DEFAULT);
                   const hid_t type = H5Tcopy(H5T_C_S1);
                   H5Tset_size(type, H5T_VARIABLE);
                   const hid_t space = H5Screate(H5S_SCALAR);
                   const hid_t set = H5Dcreate2(f, "/fclib_local/info/title", type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
                   const char* text = "a title of any length";
                   H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &text);
                   H5Dclose(set);
                   H5Sclose(space);
                   H5Tclose(type);
                 }),
                 "title is not a fixed-length string");
  {  // a truncated file: an error naming it (libfclib alone would stop the process)
    const fs::path whole = temp_file("whole.hdf5"), cut = temp_file("truncated.hdf5");
    fclib::LocalProblem big = small_problem();
    big.info.title = "truncated";
    fclib::write_problem(whole, big);
    fs::copy_file(whole, cut);
    fs::resize_file(cut, fs::file_size(whole) * 6 / 10);
    expect_refused(cut, "");
  }
}

TEST(FclibFiles, AnExistingFileIsNeverWrittenInto) {
  const fs::path file = temp_file("existing.hdf5");
  std::ofstream(file) << "a user's file\n";
  EXPECT_THROW(fclib::write_problem(file, small_problem()), Error);
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "a user's file");
}

TEST(FclibFiles, ResolversWithoutALocalSolverRefuseAProblem) {
  PluginHost host;
  PluginRequest request;
  request.kind = ModuleKind::resolver;
  request.name = "mirtich";
  const auto mirtich = host.create_resolver(request);
  const fclib::LocalProblem p = small_problem();
  fclib::Vector r = fclib::Vector::Zero(6), u = r;
  LocalContactSolution solution;
  solution.r = r.data();
  solution.u = u.data();
  const ModuleStatus status = mirtich->solve_contact_problem(p.view(1e-10), solution);
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.message.find("does not solve contact problems"), std::string::npos) << status.message;
}


// r and u = W r + q of `problem` solve it to `tolerance` (fclib's natural map), and obey Coulomb's law
// contact by contact: pressed contacts do not approach, every impulse lies in its cone, and a slipping
// contact's friction is μ r_n against its slip; some pressed contact slips (no static equilibrium).
void expect_coulomb_with_slip(const fclib::LocalProblem& problem, const std::vector<double>& r,
                              const std::vector<double>& u, double tolerance) {
  EXPECT_LE(fclib::natural_map_residual(problem, Eigen::Map<const Eigen::VectorXd>(r.data(), problem.rows())), tolerance);
  int sliding = 0;
  for (std::size_t k = 0; k < problem.contacts(); ++k) {
    const Eigen::Vector3d rk(r[3 * k], r[3 * k + 1], r[3 * k + 2]), uk(u[3 * k], u[3 * k + 1], u[3 * k + 2]);
    const double mu = problem.mu[k], slip = uk.tail<2>().norm();
    EXPECT_GE(rk(0), -tolerance) << k;
    EXPECT_GE(uk(0), -tolerance) << k;
    EXPECT_LE(rk.tail<2>().norm(), mu * rk(0) + tolerance) << k;
    if (rk(0) > 1e-6 && slip > 1e-6) {  // sliding: friction at the cone's edge, against the slip
      ++sliding;
      EXPECT_NEAR(rk.tail<2>().norm(), mu * rk(0), 1e-8) << k;
      EXPECT_LT(rk.tail<2>().dot(uk.tail<2>()), 0.0) << k;
    }
  }
  EXPECT_GT(sliding, 0);
}

// The dropped sphere pyramid K = 10 at μ = 0.7 with its contact 36 left out (bench_fclib's
// pyramid_drop_10_mu0.7_without_36): the relaxation's answer slips, and Newton from it, Cadoux's step,
// the proximal points and their projected sweeps all stall near 2e-2. Nonsmooth Gauss–Seidel sweeps from
// r = 0 (each contact's own problem solved exactly) reach a Coulomb solution, checked contact by contact
// against Coulomb's law itself: pressed contacts do not approach, every impulse lies in its cone, and a
// slipping contact's friction is μ r_n against its slip.
TEST(Fclib, NonsmoothGaussSeidelSolvesWhereTheNewtonStagesStall) {
  PluginHost host;
  const Case c{"pyramid_drop_10.yaml", {"generators.0.pyramid.friction=0.7"}, nullptr};
  std::unique_ptr<World> world = make_world(c, host);
  world->detect_contacts();
  std::vector<Contact> contacts = world->contacts();
  ASSERT_EQ(contacts.size(), 145u);
  contacts.erase(contacts.begin() + 36);
  const fclib::LocalProblem problem = fclib::scene_problem(world->bodies(), contacts, world->settings().dt).local;
  const double tolerance = 1e-10 * problem.q.norm();
  std::vector<double> r(problem.rows()), u(problem.rows());
  LocalContactSolution solution{r.data(), u.data()};

  ledas::FrictionalSettings without;
  without.nonsmooth_sweeps = 0;
  without.projection_iterations = 0;  // which would run in the sweeps' place (and solves it too)
  ledas::FrictionalSolver stalled(without), solver;
  ledas::FrictionalStats stalled_stats, stats;
  ledas::solve_local_problem(stalled, problem.view(tolerance), solution, stalled_stats);
  EXPECT_FALSE(solution.converged);
  EXPECT_GT(solution.residual, 1e-4);

  ledas::solve_local_problem(solver, problem.view(tolerance), solution, stats);
  EXPECT_TRUE(solution.converged);
  EXPECT_EQ(stats.nonsmooth_solved, 1u);
  EXPECT_GT(stats.nonsmooth_sweeps, 0u);
  expect_coulomb_with_slip(problem, r, u, tolerance);
}

// A local problem solved by `solver` to `tolerance`: r, u = W r + q, and what the solve reports.
struct LocalAnswer {
  std::vector<double> r, u;
  bool converged = false;
  ledas::FrictionalStats stats;
};

LocalAnswer solve_local(ledas::FrictionalSolver& solver, const fclib::LocalProblem& problem, double tolerance) {
  LocalAnswer answer;
  answer.r.resize(problem.rows());
  answer.u.resize(problem.rows());
  LocalContactSolution solution{answer.r.data(), answer.u.data()};
  ledas::solve_local_problem(solver, problem.view(tolerance), solution, answer.stats);
  answer.converged = solution.converged;
  return answer;
}

// The dropped sphere pyramid K = 20 at μ = 0.5 (bench_fclib's pyramid_drop_20_mu0.5, 590 contacts, 1,770
// rows): every stage up to the sweeps leaves it near 1e-2 (the sweeps do not run above 1,000 rows, and
// stalled at 0.06 when they did), and the projected fixed point from the relaxation's answer, with Newton
// from its iterate, solves it. Checked against Coulomb's law contact by contact.
TEST(Fclib, ProjectionSolvesTheDroppedPyramidK20) {
  PluginHost host;
  const Case c{"pyramid_drop_10.yaml", {"generators.0.pyramid.rows=20", "generators.0.pyramid.friction=0.5"}, nullptr};
  const fclib::LocalProblem problem = detected_problem(c, host).local;
  ASSERT_EQ(problem.contacts(), 590u);
  const double tolerance = 1e-10 * problem.q.norm();
  std::vector<double> r(problem.rows()), u(problem.rows());
  LocalContactSolution solution{r.data(), u.data()};
  ledas::FrictionalSolver solver;
  ledas::FrictionalStats stats;
  ledas::solve_local_problem(solver, problem.view(tolerance), solution, stats);
  EXPECT_TRUE(solution.converged);
  EXPECT_EQ(stats.projection_solved, 1u);  // the stages before it failed
  EXPECT_GT(stats.projection_iterations, 0u);
  EXPECT_EQ(stats.nonsmooth_sweeps, 0u);
  expect_coulomb_with_slip(problem, r, u, tolerance);

  // The Newton stages before the projection get projection_stage_newton_steps (none since 2026-12-07, 50
  // before) of their 300 steps: with all 300 (the order until 2026-12-06, night) they fail as well, and the
  // projection, started from the relaxation's answer either way, reaches the same answer. At least 200
  // Newton steps fewer.
  ledas::FrictionalSettings all_first;
  all_first.projection_stage_newton_steps = all_first.max_newton_steps;
  ledas::FrictionalSolver before(all_first);
  const LocalAnswer old_order = solve_local(before, problem, tolerance);
  EXPECT_TRUE(old_order.converged);
  EXPECT_EQ(old_order.stats.projection_solved, 1u);
  EXPECT_LE(stats.newton_steps + 200, old_order.stats.newton_steps);
  for (std::size_t k = 0; k < u.size(); ++k) EXPECT_NEAR(u[k], old_order.u[k], 10 * tolerance) << "row " << k;
}

// The dropped sphere pyramid K = 10 at μ = 0.5 (bench_fclib's pyramid_drop_10_mu0.5, 435 rows): Newton
// from the relaxation's answer and one step of Cadoux's fixed point leave it unsolved, and the proximal
// rounds took some 300 Newton steps to solve it. The interior point on Coulomb's problem itself
// (cone_qp.hpp, since 2026-12-07) solves it after Newton's first attempt, in about 12 steps: checked
// against Coulomb's law contact by contact, and at least 200 Newton steps fewer than without it.
TEST(Fclib, CoulombInteriorPointSolvesTheDroppedPyramidK10) {
  PluginHost host;
  const fclib::LocalProblem problem = dropped_pyramid_10(host, "0.5");
  const double tolerance = 1e-10 * problem.q.norm();
  ledas::FrictionalSolver solver;
  const LocalAnswer answer = solve_local(solver, problem, tolerance);
  EXPECT_TRUE(answer.converged);
  EXPECT_EQ(answer.stats.coulomb_interior_point_solved, 1u);
  EXPECT_LE(answer.stats.coulomb_interior_point_steps, 30u);
  expect_coulomb_with_slip(problem, answer.r, answer.u, tolerance);

  ledas::FrictionalSettings without;
  without.coulomb_interior_point_iterations = 0;
  ledas::FrictionalSolver before(without);
  const LocalAnswer old_answer = solve_local(before, problem, tolerance);
  EXPECT_TRUE(old_answer.converged);
  EXPECT_EQ(old_answer.stats.coulomb_interior_point_steps, 0u);
  EXPECT_LE(answer.stats.newton_steps + 200, old_answer.stats.newton_steps);
}

// A standing stack of 40 boxes, each on four corners (160 contacts, μ = 0.5), given one step of gravity:
// every contact can stick, so W r = −q on every row at once (the sticking guess, one factorization) has
// an answer in the cones, and Newton finishes it without the interior point. Checked against Coulomb's
// law (every pressed contact sticks: u = 0, r in its cone) and against the relaxation's answer from the
// interior point, whose velocities are unique.
TEST(Fclib, TheStickingGuessSolvesAStandingStackWithoutTheInteriorPoint) {
  PluginHost host;
  const Case c{"accuracy_box_stack_40.yaml", {}, [](std::span<RigidBody> bodies) {
                 for (RigidBody& b : bodies) b.material.friction = 0.5;
                 gravity_kick(1.0 / 60.0)(bodies);
               }};
  const fclib::LocalProblem problem = detected_problem(c, host).local;
  ASSERT_EQ(problem.contacts(), 160u);
  const double tolerance = 1e-10 * problem.q.norm();
  ledas::FrictionalSolver solver;
  const LocalAnswer guessed = solve_local(solver, problem, tolerance);
  EXPECT_TRUE(guessed.converged);
  EXPECT_EQ(guessed.stats.sticking_guessed, 1u);
  EXPECT_EQ(guessed.stats.relaxed, 0u);
  EXPECT_EQ(guessed.stats.interior_point_steps, 0u);
  for (std::size_t k = 0; k < problem.contacts(); ++k) {
    const Eigen::Vector3d rk(guessed.r[3 * k], guessed.r[3 * k + 1], guessed.r[3 * k + 2]);
    const Eigen::Vector3d uk(guessed.u[3 * k], guessed.u[3 * k + 1], guessed.u[3 * k + 2]);
    EXPECT_GE(rk(0), 0.0) << k;
    EXPECT_LE(rk.tail<2>().norm(), problem.mu[k] * rk(0) + tolerance) << k;
    EXPECT_LE(uk.norm(), tolerance) << k;  // sticking (or touching with no impulse)
  }

  ledas::FrictionalSettings without;
  without.sticking_guess = false;
  ledas::FrictionalSolver interior(without);
  const LocalAnswer relaxed = solve_local(interior, problem, tolerance);
  EXPECT_TRUE(relaxed.converged);
  EXPECT_EQ(relaxed.stats.sticking_guessed, 0u);
  EXPECT_GT(relaxed.stats.interior_point_steps, 0u);
  for (std::size_t i = 0; i < problem.rows(); ++i) EXPECT_NEAR(guessed.u[i], relaxed.u[i], 2.0 * tolerance) << i;
}

// The dropped sphere pyramid K = 10 at μ = 0.7: every contact can stick, but W r = −q's answer nearest 0
// pulls at some contacts and leaves the cone at others, so the guess is refused and the interior point
// finds the static equilibrium.
TEST(Fclib, TheStickingGuessIsRefusedWhereItLeavesTheCones) {
  PluginHost host;
  const fclib::LocalProblem problem = dropped_pyramid_10(host, "0.7");
  const double tolerance = 1e-10 * problem.q.norm();
  ledas::FrictionalSolver solver;
  const LocalAnswer a = solve_local(solver, problem, tolerance);
  EXPECT_TRUE(a.converged);
  EXPECT_EQ(a.stats.sticking_guessed, 0u);
  EXPECT_GT(a.stats.interior_point_steps, 0u);
  for (std::size_t k = 0; k < problem.contacts(); ++k) {
    EXPECT_LE(std::hypot(a.r[3 * k + 1], a.r[3 * k + 2]), problem.mu[k] * a.r[3 * k] + tolerance) << k;
    if (a.r[3 * k] > 1e-9) {
      EXPECT_LE(std::hypot(a.u[3 * k], std::hypot(a.u[3 * k + 1], a.u[3 * k + 2])), tolerance) << k;
    }
  }
}

// A solver keeps its storage between local problems but analyses each afresh: a problem solved after
// others gives the bits it gives on a new solver, and the same problem twice in a row too.
TEST(Fclib, ALocalProblemGivesTheSameBitsAfterOthers) {
  PluginHost host;
  const std::vector<Case> all = cases();
  ledas::FrictionalSolver shared;
  for (const Case& c : all) {
    const fclib::LocalProblem problem = detected_problem(c, host).local;
    const double tolerance = 1e-10 * (1.0 + problem.q.norm());
    ledas::FrictionalSolver fresh;
    const LocalAnswer alone = solve_local(fresh, problem, tolerance);
    EXPECT_TRUE(alone.converged) << label(c);
    EXPECT_EQ(solve_local(shared, problem, tolerance).r, alone.r) << label(c);
    EXPECT_EQ(solve_local(shared, problem, tolerance).r, alone.r) << label(c) << ", again";
  }
}

}  // namespace
