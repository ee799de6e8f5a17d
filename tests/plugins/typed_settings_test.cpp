// Typed settings (impetus/settings/): each shipped plugin's options as a struct. They survive the trip
// to options and back exactly, the defaults give no options, they reach the plugin loaded by
// PluginHost (each checked by a behaviour that depends on it), and bad values are refused as a scene's are.
#include "impetus/conformance/fixtures.hpp"
#include "impetus/core/error.hpp"
#include "impetus/plugins/host.hpp"
#include "impetus/settings/fcl.hpp"
#include "impetus/settings/integrators.hpp"
#include "impetus/settings/ledas.hpp"
#include "impetus/settings/mirtich.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace impetus {
namespace {

using conformance::contact;
using conformance::sphere;

TEST(TypedSettings, SurviveTheRoundTripThroughOptionsExactly) {
  LedasSettings ledas;
  ledas.mode = LedasMode::paper;
  ledas.tolerance = 0.1 / 3.0;  // no short decimal: the text must still read back bit for bit
  ledas.max_rounds = 77;
  ledas.start_set = LedasStartSet::touching;
  ledas.solver.dense_limit = 9;
  ledas.solver.polish_limit = 3;
  ledas.solver.rank_tolerance = 2e-9;
  ledas.solver.update_limit = 5;
  ledas.solver.regularization = 3e-12;
  ledas.solver.search_regularization = 0.0;
  ledas.solver.sharpen_refinement = false;
  ledas.solver.interior_point_rows = 1234;
  ledas.solver.interior_point_stall_excess = 1.0 / 3.0;
  ledas.islands = false;
  ledas.warm_start = false;
  ledas.resting.slop = 1.0 / 7.0 * 1e-3;
  ledas.resting.correction = 0.5;
  ledas.resting.bounce_threshold = 0.2;
  const LedasSettings l = LedasSettings::from_options(ledas.to_options());
  EXPECT_EQ(l.mode, ledas.mode);
  EXPECT_EQ(l.tolerance, ledas.tolerance);
  EXPECT_EQ(l.max_rounds, ledas.max_rounds);
  EXPECT_EQ(l.solver.max_iterations, ledas.max_rounds);  // the solver's cap follows max_rounds
  EXPECT_EQ(l.start_set, ledas.start_set);
  EXPECT_EQ(l.solver.dense_limit, ledas.solver.dense_limit);
  EXPECT_EQ(l.solver.polish_limit, ledas.solver.polish_limit);
  EXPECT_EQ(l.solver.rank_tolerance, ledas.solver.rank_tolerance);
  EXPECT_EQ(l.solver.update_limit, ledas.solver.update_limit);
  EXPECT_EQ(l.solver.regularization, ledas.solver.regularization);
  EXPECT_EQ(l.solver.search_regularization, ledas.solver.search_regularization);
  EXPECT_EQ(l.solver.sharpen_refinement, ledas.solver.sharpen_refinement);
  EXPECT_EQ(l.solver.interior_point_rows, ledas.solver.interior_point_rows);
  EXPECT_EQ(l.solver.interior_point_stall_excess, ledas.solver.interior_point_stall_excess);
  EXPECT_EQ(l.islands, ledas.islands);
  EXPECT_EQ(l.warm_start, ledas.warm_start);
  EXPECT_EQ(l.resting.slop, ledas.resting.slop);
  EXPECT_EQ(l.resting.correction, ledas.resting.correction);
  EXPECT_EQ(l.resting.bounce_threshold, ledas.resting.bounce_threshold);

  MirtichSettings mirtich;
  mirtich.order = MirtichOrder::index;
  mirtich.tolerance = 1.0 / 3.0;
  mirtich.max_impulses = 1234;
  mirtich.position_iterations = 7;
  mirtich.resting.slop = 2e-4;
  const MirtichSettings m = MirtichSettings::from_options(mirtich.to_options());
  EXPECT_EQ(m.order, mirtich.order);
  EXPECT_EQ(m.tolerance, mirtich.tolerance);
  EXPECT_EQ(m.max_impulses, mirtich.max_impulses);
  EXPECT_EQ(m.position_iterations, mirtich.position_iterations);
  EXPECT_EQ(m.resting.slop, mirtich.resting.slop);

  FclDetectorSettings fcl;
  fcl.margin = 1.0 / 300.0;
  fcl.max_contacts_per_pair = 2;
  fcl.merge_tolerance = 0.25;
  const FclDetectorSettings f = FclDetectorSettings::from_options(fcl.to_options());
  EXPECT_EQ(f.margin, fcl.margin);
  EXPECT_EQ(f.max_contacts_per_pair, fcl.max_contacts_per_pair);
  EXPECT_EQ(f.merge_tolerance, fcl.merge_tolerance);

  SplittingSettings splitting;
  splitting.orthonormalize = false;
  EXPECT_FALSE(integrators::RotationSettings::from_options(splitting.to_options()).orthonormalize);
}

// Defaults are the plugins' own: default settings give no options at all (so the run summary lists
// none), and reading no options gives the default settings.
TEST(TypedSettings, DefaultsGiveNoOptions) {
  EXPECT_TRUE(LedasSettings{}.to_options().values().empty());
  EXPECT_TRUE(MirtichSettings{}.to_options().values().empty());
  EXPECT_TRUE(FclDetectorSettings{}.to_options().values().empty());
  EXPECT_TRUE(EulerSettings{}.to_options().values().empty());
  EXPECT_TRUE(MomentumSettings{}.to_options().values().empty());
  EXPECT_EQ(LedasSettings::from_options(ModuleOptions{}).tolerance, LedasSettings{}.tolerance);
  EXPECT_EQ(FclDetectorSettings::from_options(ModuleOptions{}).margin, FclDetectorSettings{}.margin);
}

// Each typed setting reaches the plugin the host loads:
//  - ledas in paper mode refuses friction (the default complementary mode models it);
//  - an fcl detector with a 1 cm margin reports two spheres 5 mm apart as a contact of depth −5 mm (the
//    default 0.1 mm margin reports none);
//  - euler without orthonormalization counts no orthonormalization;
//  - mirtich with a 2 m/s touch tolerance leaves a 1 m/s head-on approach alone (the default resolves it).
TEST(TypedSettings, ReachThePluginTheHostLoads) {
  PluginHost host;
  LedasSettings paper;
  paper.mode = LedasMode::paper;
  EXPECT_FALSE(host.create_resolver(paper)->accept_friction());
  EXPECT_TRUE(host.create_resolver(LedasSettings{})->accept_friction());
  EXPECT_FALSE(host.create_resolver("ledas", paper)->accept_friction());

  std::vector<RigidBody> pair{sphere(1.0, 0.5, Vec3::Zero()), sphere(1.0, 0.5, Vec3(1.005, 0, 0))};
  const auto contacts_with = [&](const FclDetectorSettings& settings) {
    const auto detector = host.create_detector(settings);
    EXPECT_TRUE(detector->set_bodies(pair, {}));
    std::vector<Contact> found;
    DetectorCounters counters;
    detector->detect(pair, StepContext{}, found, counters);
    return found;
  };
  FclDetectorSettings wide;
  wide.margin = 0.01;
  const std::vector<Contact> near = contacts_with(wide);
  ASSERT_EQ(near.size(), 1u);
  EXPECT_NEAR(near[0].depth, -0.005, 1e-12);
  EXPECT_TRUE(contacts_with(FclDetectorSettings{}).empty());

  std::vector<RigidBody> spinning{sphere(1.0, 0.5, Vec3::Zero())};
  spinning[0].angular_velocity = Vec3(0, 0, 3);
  EulerSettings raw;
  raw.orthonormalize = false;
  EXPECT_EQ(conformance::run(*host.create_integrator(raw), spinning, StepContext{}, 1).orthonormalized, 0u);
  EXPECT_EQ(conformance::run(*host.create_integrator(EulerSettings{}), spinning, StepContext{}, 1).orthonormalized, 1u);

  const auto approach_after = [&](const MirtichSettings& settings) {
    std::vector<RigidBody> balls{sphere(1.0, 0.5, Vec3::Zero(), Vec3(0.5, 0, 0)),
                                 sphere(1.0, 0.5, Vec3(1, 0, 0), Vec3(-0.5, 0, 0))};
    std::vector<Contact> touching{contact(0, 1, Vec3(0.5, 0, 0), Vec3::UnitX())};
    ResolverCounters counters;
    host.create_resolver(settings)->resolve(balls, touching, {}, StepContext{}, counters);
    return balls[1].velocity.x() - balls[0].velocity.x();
  };
  MirtichSettings lax;
  lax.tolerance = 2.0;
  EXPECT_EQ(approach_after(lax), -1.0);
  EXPECT_NEAR(approach_after(MirtichSettings{}), 0.0, 1e-12);
}

// A bad value is refused as a scene's is, with the option named and "code" as where it was written; a
// plugin that does not read an option the settings give refuses it.
TEST(TypedSettings, BadValuesAreRefusedNamingTheOption) {
  PluginHost host;
  LedasSettings bad;
  bad.tolerance = -1.0;
  try {
    host.create_resolver(bad);
    ADD_FAILURE() << "a negative tolerance was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("option 'tolerance' must be between"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("code", 0), 0u) << e.what();
  }
  LedasSettings paper;
  paper.mode = LedasMode::paper;
  try {
    host.create_resolver("mirtich", paper);
    ADD_FAILURE() << "mirtich accepted ledas's option 'mode'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'mode'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace impetus
