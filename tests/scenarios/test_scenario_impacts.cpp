// Impacts with known answers, end to end: a bundled scene → the fcl detector → each resolver, one
// detection and one resolution (World::detect_and_resolve, the paper's experiment). The tolerance
// (1e-9) allows for the detector's normals, which come from geometry rather than being given exactly.
#include "scenario_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace impetus::scenario {
namespace {

constexpr double kTol = 1e-9;

// The resolver configurations every impact scene is run with.
struct ResolverCase {
  const char* label;
  std::vector<SceneOverride> overrides;
  const char* plugin;
};

std::vector<ResolverCase> all_resolvers() {
  return {{"ledas", {}, "ledas"},
          {"ledas paper", {{"modules.resolver.mode", "paper"}}, "ledas"},
          {"ledas complementary", {{"modules.resolver.mode", "complementary"}}, "ledas"},
          {"mirtich", {{"modules.resolver", "mirtich"}}, "mirtich"}};
}

// two_balls.yaml: 1 kg at 2 m/s meets 2 kg at −1 m/s. For e = 0, 0.5, 1 every resolver gives the 1D
// formulas v1 = (m1u1 + m2u2 + m2 e (u2 − u1))/(m1 + m2), v2 = (m1u1 + m2u2 + m1 e (u1 − u2))/(m1 + m2).
TEST(ScenarioImpacts, TwoBallsFollowTheOneDimensionalFormulas) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  const double m1 = 1, m2 = 2, u1 = 2, u2 = -1;
  for (const ResolverCase& rc : all_resolvers()) {
    for (const double e : {0.0, 0.5, 1.0}) {
      std::vector<SceneOverride> overrides = rc.overrides;
      overrides.push_back({"bodies.left.restitution", std::to_string(e)});
      overrides.push_back({"bodies.right.restitution", std::to_string(e)});
      SceneRun run("two_balls.yaml", overrides);
      const StepStatus& status = run.world->detect_and_resolve();
      SCOPED_TRACE(std::string(rc.label) + ", e = " + std::to_string(e));
      ASSERT_TRUE(status.ok) << status.message;
      ASSERT_EQ(run.world->contacts().size(), 1u);
      EXPECT_NEAR(run.body("left").velocity.x(), (m1 * u1 + m2 * u2 + m2 * e * (u2 - u1)) / (m1 + m2), kTol);
      EXPECT_NEAR(run.body("right").velocity.x(), (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2), kTol);
    }
  }
}

// billiards.yaml, the paper's Figure 1 (e = 1): the simultaneous resolver gives balls 2 and 3 mirror
// images of each other's velocity (1e-9); the sequential one does not (asymmetry > 1e-3). Momentum is
// conserved (1e-9) and energy with it (e = 1), whatever the resolver.
TEST(ScenarioImpacts, BilliardsSymmetricOnlyForTheSimultaneousResolver) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  for (const ResolverCase& rc : all_resolvers()) {
    SceneRun run("billiards.yaml", rc.overrides);
    const Vec3 p0 = momentum(*run.world);
    const double k0 = kinetic_energy(*run.world);
    const StepStatus& status = run.world->detect_and_resolve();
    SCOPED_TRACE(rc.label);
    ASSERT_TRUE(status.ok) << status.message;
    const std::size_t contacts = run.world->contacts().size();
    EXPECT_TRUE(contacts == 2 || contacts == 3) << contacts;
    const Vec3 v2 = run.body("ball2").velocity, v3 = run.body("ball3").velocity;
    const double asymmetry = std::abs(v2.norm() - v3.norm());
    std::printf("[ scenario ] billiards %-20s contacts %zu  |v2| %.6f  |v3| %.6f  asymmetry %.3g  rounds %llu\n",
                rc.label, contacts, v2.norm(), v3.norm(), asymmetry,
                static_cast<unsigned long long>(status.resolver.rounds));
    if (std::string(rc.plugin) == "mirtich") {
      EXPECT_GT(asymmetry, 1e-3);
    } else {
      EXPECT_LT((v2 - Vec3(v3.x(), -v3.y(), v3.z())).norm(), kTol);
    }
    EXPECT_LT((momentum(*run.world) - p0).norm(), kTol);
    EXPECT_NEAR(kinetic_energy(*run.world), k0, kTol);
  }
}

// knocked_wall.yaml: a 200 kg ball at 8 m/s into a frictionless wall of 60 bricks on the ground. Gravity
// and the ground's impulses are vertical, so the bodies' horizontal momentum stays 1,600 kg·m/s along y
// (1e-9 relative) over 150 steps (1 ms each, the impact included), whether the wall's island of ~600 rows
// goes to the interior point in body space (the default: at least 500 rows, more than 6 per body) or to
// the active-set search (interior_point_rows 0). No step leaves a contact approaching by more than the
// resolver's tolerance (1e-9 m/s) or an unconverged system.
TEST(ScenarioImpacts, KnockedWallKeepsItsHorizontalMomentum) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"});
  for (const char* rows : {"500", "0"}) {
    SceneRun run("knocked_wall.yaml", {{"modules.resolver.interior_point_rows", rows}});
    SCOPED_TRACE(std::string("interior_point_rows ") + rows);
    const Vec3 p0 = momentum(*run.world);
    ASSERT_NEAR(p0.y(), 1600.0, 1e-9);
    std::size_t most_contacts = 0;
    for (int step = 0; step < 150; ++step) {
      const StepStatus& status = run.world->step();
      ASSERT_TRUE(status.ok) << status.message;
      most_contacts = std::max(most_contacts, run.world->contacts().size());
      EXPECT_LE(status.resolver.residual, 1e-9) << "step " << step;
      EXPECT_EQ(status.resolver.non_converged, 0u) << "step " << step;
    }
    const Vec3 p = momentum(*run.world);
    EXPECT_LE(std::hypot(p.x() - p0.x(), p.y() - p0.y()), 1e-9 * p0.norm());
    EXPECT_GE(most_contacts, 500u);  // the island is large enough for the interior point's default
  }
}

// The interior point's answers taken at a stall (resolution/ledas/README.md, "Creeping at the floor"),
// against the active-set search's from the same state: knocked_wall.yaml stepped twice in lockstep, with
// the default interior_point_stall_excess (100) and with 0 (every stall to the search). While both
// agree bit for bit nothing was taken loosely; at the first step where they differ (a loose answer, or
// the search's own split among redundant rows), every body's velocity agrees to 1e-8 m/s and 1e-8
// rad/s, its position to 1e-10 m, and neither leaves a contact approaching by more than 1e-9 m/s.
TEST(ScenarioImpacts, KnockedWallStallAnswersMatchTheSearch) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"});
  SceneRun loose("knocked_wall.yaml");
  SceneRun exact("knocked_wall.yaml", {{"modules.resolver.interior_point_stall_excess", "0"}});
  int differs_at = -1;
  for (int step = 0; step < 150 && differs_at < 0; ++step) {
    const StepStatus& a = loose.world->step();
    ASSERT_TRUE(a.ok) << a.message;
    EXPECT_LE(a.resolver.residual, 1e-9) << "step " << step;
    const StepStatus& b = exact.world->step();
    ASSERT_TRUE(b.ok) << b.message;
    EXPECT_LE(b.resolver.residual, 1e-9) << "step " << step;
    double dv = 0.0, dw = 0.0, dx = 0.0;
    const auto& x = loose.world->bodies();
    const auto& y = exact.world->bodies();
    ASSERT_EQ(x.size(), y.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      dv = std::max(dv, (x[i].velocity - y[i].velocity).norm());
      dw = std::max(dw, (x[i].angular_velocity - y[i].angular_velocity).norm());
      dx = std::max(dx, (x[i].position - y[i].position).norm());
    }
    if (dv == 0.0 && dw == 0.0 && dx == 0.0) continue;
    differs_at = step;
    std::printf("[ scenario ] knocked wall: first difference at step %d: %.2e m/s, %.2e rad/s, %.2e m\n", step, dv,
                dw, dx);
    EXPECT_LE(dv, 1e-8);
    EXPECT_LE(dw, 1e-8);
    EXPECT_LE(dx, 1e-10);
  }
  EXPECT_GE(differs_at, 0) << "no stall taken loosely in 150 steps: the test no longer exercises it";
}

// Newton's cradle (e = 1), 5 and 20 balls, the first at 1 m/s. Sequential and round-by-round (ledas
// paper mode): only the last ball moves, at 1 m/s. All contacts at once (ledas complementary): the
// inelastic solve gives everyone 1/N, doubled by e = 1, so ball 1 leaves at 2/N − 1 and the others at
// 2/N (−0.6 and 0.4 for five balls). Momentum and energy are conserved either way (1e-9).
TEST(ScenarioImpacts, NewtonsCradleClassicOrShared) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  for (const int n : {5, 20}) {
    for (const ResolverCase& rc : all_resolvers()) {
      if (rc.overrides.empty()) continue;  // the default mode is one of the two named ones
      SceneRun run("newtons_cradle_" + std::to_string(n) + ".yaml", rc.overrides);
      const StepStatus& status = run.world->detect_and_resolve();
      SCOPED_TRACE(std::string(rc.label) + ", " + std::to_string(n) + " balls");
      ASSERT_TRUE(status.ok) << status.message;
      ASSERT_EQ(run.world->contacts().size(), static_cast<std::size_t>(n - 1));
      const bool shared = std::string(rc.label) == "ledas complementary";
      for (int i = 1; i <= n; ++i) {
        const double expected = shared ? (i == 1 ? 2.0 / n - 1.0 : 2.0 / n) : (i == n ? 1.0 : 0.0);
        EXPECT_LT((run.body("ball" + std::to_string(i)).velocity - Vec3(expected, 0, 0)).norm(), kTol) << "ball " << i;
      }
      EXPECT_LT((momentum(*run.world) - Vec3(1, 0, 0)).norm(), kTol);
      EXPECT_NEAR(kinetic_energy(*run.world), 0.5, kTol);
      std::printf("[ scenario ] cradle %2d %-20s rounds %llu\n", n, rc.label,
                  static_cast<unsigned long long>(status.resolver.rounds));
    }
  }
}

// line_push_10.yaml: e = 1 sends the pulse to the wall and back (ball 0 leaves at −1 m/s, the rest
// stop); e = 0 brings the line to rest against the wall (1e-5 m/s). Every resolver.
TEST(ScenarioImpacts, LinePushBouncesOrStops) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  for (const ResolverCase& rc : all_resolvers()) {
    for (const char* e : {"0", "1"}) {
      std::vector<SceneOverride> overrides = rc.overrides;
      overrides.push_back({"generators.0.line.restitution", e});
      SceneRun run("line_push_10.yaml", overrides);
      const StepStatus& status = run.world->detect_and_resolve();
      SCOPED_TRACE(std::string(rc.label) + ", e = " + e);
      ASSERT_TRUE(status.ok) << status.message;
      EXPECT_EQ(run.world->contacts().size(), 10u);
      const bool elastic = std::string(e) == "1";
      for (int i = 0; i < 10; ++i) {
        const Vec3 expected = elastic && i == 0 ? Vec3(-1, 0, 0) : Vec3::Zero();
        EXPECT_LT((run.body("line_" + std::to_string(i)).velocity - expected).norm(), elastic ? kTol : 1e-5)
            << "ball " << i;
      }
      std::printf("[ scenario ] line 10 e=%s %-20s rounds %llu non_converged %llu\n", e, rc.label,
                  static_cast<unsigned long long>(status.resolver.rounds),
                  static_cast<unsigned long long>(status.resolver.non_converged));
    }
  }
}

// pyramid_drop_10.yaml: 145 contacts (135 + 10 on the ground). Every resolver leaves no contact
// approaching beyond 1e-6 m/s (or, sequentially, reports its cap), gains no energy, and keeps the
// horizontal momentum (the ground only pushes along z), to 1e-9.
TEST(ScenarioImpacts, PyramidDropResolvesOrReportsItsCap) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  for (const ResolverCase& rc : all_resolvers()) {
    SceneRun run("pyramid_drop_10.yaml", rc.overrides);
    const double k0 = kinetic_energy(*run.world);
    const StepStatus& status = run.world->detect_and_resolve();
    SCOPED_TRACE(rc.label);
    ASSERT_TRUE(status.ok) << status.message;
    EXPECT_EQ(run.world->contacts().size(), 145u);
    const ResolverCounters& c = status.resolver;
    std::printf("[ scenario ] pyramid 10 %-20s rounds %llu non_converged %llu residual %.3g m/s\n", rc.label,
                static_cast<unsigned long long>(c.rounds), static_cast<unsigned long long>(c.non_converged), c.residual);
    if (c.non_converged == 0) {
      EXPECT_LE(c.residual, 1e-6);
    }
    EXPECT_LE(kinetic_energy(*run.world), k0 * (1 + 1e-12));
    EXPECT_LT(momentum(*run.world).head<2>().norm(), kTol);
  }
}

// figure2.yaml: a plank lands flat on a longer fixed beam (e = 0). However many points the detector
// reports (the paper's overdetermined case), every resolver stops the plank: no approach left.
TEST(ScenarioImpacts, FigureTwoPlankStops) {
  IMPETUS_REQUIRE_PLUGINS({"detector", "fcl"}, {"resolver", "ledas"}, {"resolver", "mirtich"});
  for (const ResolverCase& rc : all_resolvers()) {
    SceneRun run("figure2.yaml", rc.overrides);
    const StepStatus& status = run.world->detect_and_resolve();
    SCOPED_TRACE(rc.label);
    ASSERT_TRUE(status.ok) << status.message;
    EXPECT_GE(run.world->contacts().size(), 2u);
    const RigidBody& plank = run.body("plank");
    std::printf("[ scenario ] figure 2 %-20s contacts %zu rounds %llu singular %llu redundant %llu v_z %.3g |w| %.3g\n",
                rc.label, run.world->contacts().size(), static_cast<unsigned long long>(status.resolver.rounds),
                static_cast<unsigned long long>(status.resolver.singular_systems),
                static_cast<unsigned long long>(status.resolver.redundant_systems), plank.velocity.z(),
                plank.angular_velocity.norm());
    // The overdetermined set is redundant, not a failure: nothing is counted as singular.
    EXPECT_EQ(status.resolver.singular_systems, 0u);
    EXPECT_LE(status.resolver.residual, 1e-6);
    EXPECT_GE(plank.velocity.z(), -1e-6);
  }
}

}  // namespace
}  // namespace impetus::scenario
