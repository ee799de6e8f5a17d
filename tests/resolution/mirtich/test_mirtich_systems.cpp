// The sequential resolver on many contacts: conservation laws, the paper's benchmark scenes (pyramid,
// line) with their impulse counts, stacks that make sequential resolution "almost freeze" (paper,
// sec. 1), the cap, the position correction and the options.
#include "impetus/engine/generators.hpp"
#include "mirtich_test_support.hpp"

#include <chrono>
#include <cstdio>
#include <random>

namespace impetus::mirtich_test {
namespace {

constexpr double kExact = 1e-12;

// Prints one measured figure in a form easy to collect from the test log.
void report(const char* scene, const ResolverCounters& c, double seconds) {
  std::printf("[ mirtich ] %-28s contacts %4llu  impulses %7llu  %s  residual %.3g m/s  %.4f s\n", scene,
              static_cast<unsigned long long>(c.contacts), static_cast<unsigned long long>(c.rounds),
              c.non_converged ? "CAP HIT  " : "converged", c.residual, seconds);
}

ResolverCounters timed_resolve(const char* scene, std::vector<RigidBody>& bodies, std::vector<Contact>& contacts,
                               const MirtichSettings& settings = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  const ResolverCounters c = resolve(bodies, contacts, settings);
  report(scene, c, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return c;
}

// Either the sweep converged (nothing approaches beyond the tolerance) or it stopped exactly at its cap
// and said so; never anything in between, never a pulling impulse.
void expect_converged_or_capped(const ResolverCounters& c, std::size_t contacts, const MirtichSettings& s = {}) {
  if (c.non_converged == 0) {
    EXPECT_LE(c.residual, s.tolerance);
  } else {
    EXPECT_EQ(c.non_converged, 1u);
    EXPECT_EQ(c.rounds, s.impulse_cap(contacts));
    EXPECT_GT(c.residual, s.tolerance);
  }
  EXPECT_EQ(c.pulling_impulses, 0u);
  EXPECT_EQ(c.nan_caught, 0u);
}

// Random boxes joined by random contacts, no fixed body: every single impulse is equal and opposite at
// one point, so linear and angular momentum are conserved (1e-12 relative), and with e ≤ 1 each one
// changes the energy by (v_n²/A)(1 + e)(e − 1)/2 ≤ 0: no energy gain.
TEST(MirtichSystems, MomentumConservedAndNoEnergyGainedWithoutGravity) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto random_vec = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<RigidBody> bodies;
    for (int i = 0; i < 6; ++i) {
      const Mat3 r = Eigen::AngleAxisd(3 * u(rng), random_vec().normalized()).toRotationMatrix();
      bodies.push_back(box(1.5 + u(rng), Vec3(1.0 + 0.5 * u(rng), 0.8, 0.6), 2 * random_vec(), r, random_vec(),
                           0.5 + 0.5 * u(rng)));
      bodies.back().angular_velocity = random_vec();
    }
    std::vector<Contact> contacts;
    for (int k = 0; k < 10; ++k) {
      const int a = static_cast<int>(rng() % 5);
      const int b = a + 1 + static_cast<int>(rng() % (5 - a));
      contacts.push_back(contact(a, b, 2 * random_vec(), random_vec()));
    }
    const Vec3 p0 = linear_momentum(bodies), l0 = angular_momentum(bodies);
    const double k0 = kinetic_energy(bodies);
    const ResolverCounters c = resolve(bodies, contacts);
    SCOPED_TRACE("trial " + std::to_string(trial));
    EXPECT_LT((linear_momentum(bodies) - p0).norm(), kExact * (1 + p0.norm()));
    EXPECT_LT((angular_momentum(bodies) - l0).norm(), kExact * (1 + l0.norm()) * 10);
    EXPECT_LE(kinetic_energy(bodies), k0 * (1 + kExact));
    for (const Contact& k : contacts) EXPECT_GE(k.impulse, 0.0);
    expect_converged_or_capped(c, contacts.size());
  }
}

// Contacts of the generator's pyramid computed analytically: sphere pairs closer than 2r(1 + 1e-6),
// and spheres below z = r(1 + 1e-6) on the ground (the last body).
std::vector<Contact> pyramid_contacts(const std::vector<RigidBody>& bodies, double r) {
  std::vector<Contact> contacts;
  const BodyIndex ground_index = static_cast<BodyIndex>(bodies.size() - 1);
  for (BodyIndex i = 0; i < ground_index; ++i) {
    for (BodyIndex j = i + 1; j < ground_index; ++j) {
      const Vec3 d = bodies[j].position - bodies[i].position;
      if (d.norm() < 2 * r * (1 + 1e-6))
        contacts.push_back(contact(i, j, bodies[i].position + r * d.normalized(), d, 2 * r - d.norm()));
    }
    if (bodies[i].position.z() < r * (1 + 1e-6))
      contacts.push_back(contact(i, ground_index, bodies[i].position - r * Vec3::UnitZ(), -Vec3::UnitZ(),
                                 r - bodies[i].position.z()));
  }
  return contacts;
}

// The paper's pyramid drop (every sphere at (0, 0, −1), e = 0). The ground pushes only along z, so
// horizontal momentum is conserved (1e-12); energy is not gained; the sweep converges or reports its cap.
TEST(MirtichSystems, PyramidDropImpulseCounts) {
  const std::pair<int, std::size_t> sizes[] = {{3, 9}, {4, 18}, {10, 135}, {20, 570}};
  for (const auto& [rows, sphere_contacts] : sizes) {
    PyramidParams params;
    params.rows = rows;
    std::vector<RigidBody> bodies = make_pyramid(params);
    std::vector<Contact> contacts = pyramid_contacts(bodies, params.radius);
    ASSERT_EQ(contacts.size(), sphere_contacts + static_cast<std::size_t>(rows)) << "K = " << rows;
    const Vec3 p0 = linear_momentum(bodies);
    const double k0 = kinetic_energy(bodies);
    const std::string name = "pyramid K=" + std::to_string(rows) + " (" + std::to_string(bodies.size() - 1) + " spheres)";
    const ResolverCounters c = timed_resolve(name.c_str(), bodies, contacts);
    SCOPED_TRACE(name);
    expect_converged_or_capped(c, contacts.size());
    EXPECT_LT((linear_momentum(bodies) - p0).head<2>().norm(), kExact * rows * rows);
    EXPECT_LE(kinetic_energy(bodies), k0 * (1 + kExact));
  }
}

// The paper's line push (first sphere at (1, 0, 0), wall after the last). e = 1: the pulse runs down
// the line, off the wall and back: exactly 2N − 1 impulses, ball 0 leaves at −1 m/s, the rest stop,
// energy conserved (1e-12). e = 0: velocities stay in [0, 1] and the only admissible end state is rest,
// reached (to the tolerance) or reported as capped.
TEST(MirtichSystems, LinePushImpulseCounts) {
  for (const int n : {10, 100}) {
    for (const double e : {0.0, 1.0}) {
      LineParams params;
      params.count = n;
      params.restitution = e;
      std::vector<RigidBody> bodies = make_line(params);
      std::vector<Contact> contacts;
      const double r = params.radius;
      for (BodyIndex i = 0; i + 1 < bodies.size(); ++i) {
        const double gap = i + 2 < bodies.size() ? bodies[i + 1].position.x() - bodies[i].position.x() - 2 * r
                                                 : -std::get<Plane>(bodies.back().shape).offset - bodies[i].position.x() - r;
        contacts.push_back(contact(i, i + 1, bodies[i].position + r * Vec3::UnitX(), Vec3::UnitX(), -gap));
      }
      const std::string name = "line N=" + std::to_string(n) + " e=" + (e == 0.0 ? "0" : "1");
      const double k0 = kinetic_energy(bodies);
      const ResolverCounters c = timed_resolve(name.c_str(), bodies, contacts);
      SCOPED_TRACE(name);
      expect_converged_or_capped(c, contacts.size());
      if (e == 1.0) {
        EXPECT_EQ(c.rounds, static_cast<std::uint64_t>(2 * n - 1));
        EXPECT_LT((bodies[0].velocity - Vec3(-1, 0, 0)).norm(), kExact);
        for (int i = 1; i < n; ++i) EXPECT_LT(bodies[i].velocity.norm(), kExact) << "ball " << i;
        EXPECT_NEAR(kinetic_energy(bodies), k0, kExact);
      } else {
        for (int i = 0; i < n; ++i) {
          EXPECT_GE(bodies[i].velocity.x(), -kExact);
          if (c.non_converged == 0) {
            EXPECT_LE(bodies[i].velocity.x(), n * MirtichSettings{}.tolerance);
          }
        }
      }
    }
  }
}

// A stack of unit boxes resting on each other, 4 corner contacts per face, all falling at 1 m/s onto
// the ground: the paper's "four or more stacked boxes" that make sequential resolution almost freeze.
void box_stack(int count, double restitution, std::vector<RigidBody>& bodies, std::vector<Contact>& contacts) {
  bodies.clear();
  contacts.clear();
  for (int i = 0; i < count; ++i)
    bodies.push_back(box(1.0, Vec3::Ones(), Vec3(0, 0, 0.5 + i), Mat3::Identity(), Vec3(0, 0, -1), restitution));
  bodies.push_back(ground());
  for (int i = 0; i < count; ++i)
    for (const double x : {-0.5, 0.5})
      for (const double y : {-0.5, 0.5}) {
        if (i == 0) contacts.push_back(contact(0, count, Vec3(x, y, 0), -Vec3::UnitZ()));
        if (i + 1 < count) contacts.push_back(contact(i, i + 1, Vec3(x, y, i + 1.0), Vec3::UnitZ()));
      }
}

// It never hangs: every stack finishes within its cap, converged or reporting the cap; energy is not
// gained; at convergence with e = 0 the stack is at rest (the tolerance times the box count).
TEST(MirtichSystems, BoxStacksNeverHangAndReportTheirCap) {
  for (const int count : {4, 10}) {
    for (const double e : {0.0, 0.5}) {
      std::vector<RigidBody> bodies;
      std::vector<Contact> contacts;
      box_stack(count, e, bodies, contacts);
      const double k0 = kinetic_energy(bodies);
      const std::string name = "box stack " + std::to_string(count) + " e=" + (e == 0.0 ? "0" : "0.5");
      const ResolverCounters c = timed_resolve(name.c_str(), bodies, contacts);
      SCOPED_TRACE(name);
      expect_converged_or_capped(c, contacts.size());
      EXPECT_LE(kinetic_energy(bodies), k0 * (1 + kExact));
      if (e == 0.0 && c.non_converged == 0) {
        for (int i = 0; i < count; ++i) EXPECT_LT(bodies[i].velocity.norm(), count * 1e-5) << "box " << i;
      }
    }
  }
}

// A small cap stops the sweep at exactly that many impulses and counts the island as not converged.
TEST(MirtichSystems, ExplicitCapStopsTheSweepAndIsReported) {
  std::vector<RigidBody> bodies;
  std::vector<Contact> contacts;
  box_stack(4, 0.0, bodies, contacts);
  MirtichSettings settings;
  settings.max_impulses = 7;
  const ResolverCounters c = resolve(bodies, contacts, settings);
  EXPECT_EQ(c.rounds, 7u);
  EXPECT_EQ(c.non_converged, 1u);
  EXPECT_GT(c.residual, settings.tolerance);
  for (const RigidBody& b : bodies) EXPECT_TRUE(b.velocity.allFinite() && b.angular_velocity.allFinite());
}

// Position correction: a sphere 1 cm into the ground at rest rises by correction·(depth − slop) along
// the normal (its contact passes through the centre: A = 1/m, so q/m = target), and its velocity stays
// exactly zero. Two spheres stacked (1 kg below 3 kg), both contacts 1 cm deep: each contact opens by
// its target (1e-9) once the pseudo-impulse iteration has converged.
TEST(MirtichSystems, PositionCorrectionSeparatesWithoutChangingVelocities) {
  const resolution::RestingSettings resting;
  const double depth = 0.01, target = resting.correction * (depth - resting.slop);
  std::vector<RigidBody> bodies{sphere(2, 0.5, Vec3(0, 0, 0.5 - depth), Vec3::Zero()), ground()};
  std::vector<Contact> contacts{contact(0, 1, Vec3(0, 0, -depth), -Vec3::UnitZ(), depth)};
  resolve(bodies, contacts);
  EXPECT_NEAR(bodies[0].position.z(), 0.5 - depth + target, kExact);
  EXPECT_EQ(bodies[0].velocity, Vec3::Zero());
  EXPECT_EQ(bodies[0].angular_velocity, Vec3::Zero());
  EXPECT_EQ(contacts[0].impulse, 0.0);

  std::vector<RigidBody> stack{sphere(1, 0.5, Vec3(0, 0, 0.5 - depth), Vec3::Zero()),
                               sphere(3, 0.5, Vec3(0, 0, 1.5 - 2 * depth), Vec3::Zero()), ground()};
  std::vector<Contact> stack_contacts{contact(0, 2, Vec3(0, 0, -depth), -Vec3::UnitZ(), depth),
                                      contact(0, 1, Vec3(0, 0, 1 - 1.5 * depth), Vec3::UnitZ(), depth)};
  const Vec3 z0 = stack[0].position, z1 = stack[1].position;
  // Gauss–Seidel contracts by a12²/(a11 a22) = 3/4 per pass here: 500 passes to reach rounding.
  MirtichSettings settings;
  settings.position_iterations = 500;
  resolve(stack, stack_contacts, settings);
  EXPECT_NEAR(stack[0].position.z() - z0.z(), target, 1e-9);
  EXPECT_NEAR((stack[1].position.z() - z1.z()) - (stack[0].position.z() - z0.z()), target, 1e-9);
  EXPECT_EQ(stack[0].velocity, Vec3::Zero());
  EXPECT_EQ(stack[1].velocity, Vec3::Zero());
}

// Options are read and checked: a bad `order` is an error naming the option.
TEST(MirtichSystems, OptionsAreReadAndChecked) {
  ModuleOptions options("plugin 'mirtich' (resolver)");
  options.set("order", OptionValue{"index", {}, false, "test"});
  options.set("max_impulses", OptionValue{"123", {}, false, "test"});
  options.set("tolerance", OptionValue{"1e-8", {}, false, "test"});
  options.set("slop", OptionValue{"0.001", {}, false, "test"});
  const MirtichResolver resolver(options);
  EXPECT_EQ(resolver.settings().order, MirtichOrder::index);
  EXPECT_EQ(resolver.settings().impulse_cap(5), 123u);
  EXPECT_EQ(resolver.settings().tolerance, 1e-8);
  EXPECT_EQ(resolver.settings().resting.slop, 0.001);
  EXPECT_TRUE(options.unread().empty());
  EXPECT_EQ(MirtichSettings{}.impulse_cap(5), 10000u);
  EXPECT_EQ(MirtichSettings{}.impulse_cap(590), 59000u);

  ModuleOptions bad("plugin 'mirtich' (resolver)");
  bad.set("order", OptionValue{"random", {}, false, "scene.yaml:7:12"});
  try {
    MirtichResolver r(bad);
    FAIL() << "expected an OptionError";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("order"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("scene.yaml:7:12"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace impetus::mirtich_test
