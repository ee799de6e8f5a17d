// The resolver conformance suite: the promises of impetus/modules/resolver.hpp and contact.hpp, checked
// on a resolver loaded from its .so. Convention: n points out of a into b, v_n = (u_b − u_a)·n < 0
// approaches, an impulse p ≥ 0 acts −p n on a and +p n on b, a contact's e is the larger of its bodies'.
#include "impetus/conformance/conformance.hpp"

#include <cmath>
#include <random>

namespace impetus::conformance {
namespace {

constexpr double kExact = 1e-12;      // closed forms and conservation laws: rounding only
constexpr double kRestitutions[] = {0.0, 0.25, 0.5, 1.0};

/// One resolve of `contacts` on `bodies` by `resolver` (no constraints, default step); the counters.
ResolverCounters resolve(CollisionResolver& resolver, std::vector<RigidBody>& bodies, std::vector<Contact>& contacts) {
  ResolverCounters counters;
  resolver.resolve(bodies, contacts, {}, StepContext{}, counters);
  return counters;
}

/// A gravity-free multi-contact scene: a hexagonal cluster of seven touching spheres (twelve contacts)
/// with random masses, velocities and spins, and two tilted boxes pressed face to face (four corner
/// contacts), all with restitution e. Contacts touch exactly (depth 0), so no position correction runs.
struct Scene {
  std::vector<RigidBody> bodies;
  std::vector<Contact> contacts;
};

Scene cluster(unsigned seed, double e) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Scene s;
  for (int i = 0; i < 7; ++i) {
    const Vec3 x = i == 0 ? Vec3::Zero() : Vec3(std::cos(i * M_PI / 3), std::sin(i * M_PI / 3), 0.0);
    s.bodies.push_back(sphere(1.5 + u(rng), 0.5, x, Vec3(u(rng), u(rng), u(rng)), e));
    s.bodies.back().angular_velocity = Vec3(u(rng), u(rng), u(rng));
  }
  for (BodyIndex i = 0; i < 7; ++i)
    for (BodyIndex j = i + 1; j < 7; ++j) {
      const Vec3 d = s.bodies[j].position - s.bodies[i].position;
      if (d.norm() < 1.0 + 1e-9) s.contacts.push_back(contact(i, j, s.bodies[i].position + 0.5 * d.normalized(), d));
    }
  const Mat3 r = Eigen::AngleAxisd(u(rng), Vec3(u(rng), u(rng), 1).normalized()).toRotationMatrix();
  const BodyIndex b0 = static_cast<BodyIndex>(s.bodies.size());
  s.bodies.push_back(box(1.5, Vec3(1, 1, 1), Vec3(10, 0, 0), r, Vec3(u(rng), u(rng), 1 + u(rng)), e));
  s.bodies.push_back(box(0.7, Vec3(0.8, 0.6, 1), Vec3(10, 0, 0) + r.col(2), r, Vec3(u(rng), u(rng), u(rng)), e));
  s.bodies[b0].angular_velocity = Vec3(u(rng), u(rng), u(rng));
  for (int k = 0; k < 4; ++k)
    s.contacts.push_back(contact(b0, b0 + 1, s.bodies[b0].position + r * Vec3(k & 1 ? 0.4 : -0.4, k & 2 ? 0.3 : -0.3, 0.5),
                                 r.col(2)));
  return s;
}

/// Every cluster the scene tests run: twenty seeds for each uniform e.
template <typename F>
void for_each_cluster(F&& check) {
  for (const double e : kRestitutions)
    for (unsigned seed = 1; seed <= 20; ++seed) {
      SCOPED_TRACE("cluster seed " + std::to_string(seed) + ", e = " + std::to_string(e));
      Scene s = cluster(seed, e);
      check(s, e);
    }
}

// Law: a single head-on contact between spheres m1, m2 approaching along n = +x at u1 > u2, uniform e:
//   v1 = (m1 u1 + m2 u2 − m2 e (u1 − u2)) / (m1 + m2),  v2 = (m1 u1 + m2 u2 + m1 e (u1 − u2)) / (m1 + m2),
// impulse p = m1 (u1 − v1); nothing moves sideways or spins (central impact: 1e-15). 1e-12, every e in
// {0, 0.25, 0.5, 1}. Counters: one island, one contact, at least one round, nothing pulling, non-finite,
// singular or unconverged, residual within the resolver's tolerance.
TEST_P(ResolverConformance, SingleHeadOnContactFollowsTheClosedForm) {
  const auto resolver = load_resolver(GetParam());
  for (const auto& [m1, m2] : {std::pair{1.0, 1.0}, std::pair{1.0, 3.0}, std::pair{5.0, 0.5}, std::pair{0.25, 4.0}})
    for (const double e : kRestitutions) {
      SCOPED_TRACE("m1 = " + std::to_string(m1) + ", m2 = " + std::to_string(m2) + ", e = " + std::to_string(e));
      const double u1 = 2.0, u2 = -0.5;
      std::vector<RigidBody> bodies{sphere(m1, 0.5, Vec3(0, 0, 0), Vec3(u1, 0, 0), e),
                                    sphere(m2, 0.5, Vec3(1, 0, 0), Vec3(u2, 0, 0), e)};
      std::vector<Contact> contacts{contact(0, 1, Vec3(0.5, 0, 0), Vec3::UnitX())};
      const ResolverCounters c = resolve(*resolver, bodies, contacts);
      const double v1 = (m1 * u1 + m2 * u2 - m2 * e * (u1 - u2)) / (m1 + m2);
      const double v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2);
      EXPECT_NEAR(bodies[0].velocity.x(), v1, kExact);
      EXPECT_NEAR(bodies[1].velocity.x(), v2, kExact);
      EXPECT_NEAR(contacts[0].impulse, m1 * (u1 - v1), kExact);
      for (const RigidBody& b : bodies) EXPECT_LT(b.velocity.tail<2>().norm() + b.angular_velocity.norm(), 1e-15);
      EXPECT_EQ(c.islands, 1u);
      EXPECT_EQ(c.contacts, 1u);
      EXPECT_GE(c.rounds, 1u);
      EXPECT_EQ(c.pulling_impulses, 0u);
      EXPECT_EQ(c.non_converged, 0u);
      EXPECT_EQ(c.singular_systems, 0u);
      EXPECT_EQ(c.nan_caught, 0u);
      EXPECT_LE(c.residual, GetParam().approach_tolerance);
    }
}

// Law: an oblique central impact changes only the velocity components along the line of centres n,
// by the 1D law above; tangential components are untouched and nothing spins. Equal masses, e = 1, one
// at rest: the spheres leave at right angles. 1e-12.
TEST_P(ResolverConformance, ObliqueImpactKeepsTangentialVelocities) {
  const auto resolver = load_resolver(GetParam());
  const Vec3 n = Vec3(std::cos(0.5), std::sin(0.5), 0.2).normalized();
  for (const auto& [m2, e] : {std::pair{1.0, 1.0}, std::pair{3.0, 0.5}, std::pair{0.5, 0.25}}) {
    SCOPED_TRACE("m2 = " + std::to_string(m2) + ", e = " + std::to_string(e));
    const double m1 = 1.0;
    const Vec3 u1(1.0, 0.4, -0.3), u2 = m2 == 1.0 ? Vec3::Zero() : Vec3(-0.2, 0.1, 0.5);
    std::vector<RigidBody> bodies{sphere(m1, 0.5, Vec3::Zero(), u1, e), sphere(m2, 0.5, n, u2, e)};
    std::vector<Contact> contacts{contact(0, 1, 0.5 * n, n)};
    resolve(*resolver, bodies, contacts);
    const double a1 = u1.dot(n), a2 = u2.dot(n);
    const double b1 = (m1 * a1 + m2 * a2 - m2 * e * (a1 - a2)) / (m1 + m2);
    const double b2 = (m1 * a1 + m2 * a2 + m1 * e * (a1 - a2)) / (m1 + m2);
    EXPECT_LT((bodies[0].velocity - (u1 + (b1 - a1) * n)).norm(), kExact);
    EXPECT_LT((bodies[1].velocity - (u2 + (b2 - a2) * n)).norm(), kExact);
    EXPECT_LT(bodies[0].angular_velocity.norm() + bodies[1].angular_velocity.norm(), kExact);
    if (m2 == 1.0 && e == 1.0) {
      EXPECT_NEAR(bodies[0].velocity.dot(bodies[1].velocity), 0.0, kExact);
    }
  }
}

// Law: a tilted box hits the fixed ground with one corner P, r = P − x. For one contact with normal n,
//   A = 1/m + (r × n)·J⁻¹(r × n),  p = −(1 + e) v_n / A,  and so v_n⁺ = −e v_n,
// v⁺ = v ∓ p n / m, ω⁺ = ω ∓ J⁻¹ (r × p n) (− when the box is body a), and the angular momentum about P
// is conserved (the impulse passes through P). Both orders of the pair (box as a, n = −z; box as b,
// n = +z), every e in {0, 0.25, 0.5, 1}; 1e-12.
TEST_P(ResolverConformance, TiltedBoxCornerFollowsTheClosedForm) {
  const auto resolver = load_resolver(GetParam());
  const Mat3 rot = (Eigen::AngleAxisd(0.5, Vec3::UnitY()) * Eigen::AngleAxisd(0.2, Vec3::UnitX())).toRotationMatrix();
  const Vec3 size(1.0, 0.6, 0.4);
  const double m = 2.0;
  Vec3 corner = -0.5 * size;  // body frame: the lowest corner
  for (int i = 1; i < 8; ++i) {
    const Vec3 c((i & 1 ? 0.5 : -0.5) * size.x(), (i & 2 ? 0.5 : -0.5) * size.y(), (i & 4 ? 0.5 : -0.5) * size.z());
    if ((rot * c).z() < (rot * corner).z()) corner = c;
  }
  const Vec3 x(0.1, -0.2, -(rot * corner).z());
  const Vec3 v(0.3, -0.2, -1.5), w(0.5, 1.0, -0.3);
  const Vec3 P = x + rot * corner;
  for (const bool box_first : {true, false})
    for (const double e : kRestitutions) {
      SCOPED_TRACE(std::string(box_first ? "box is body a" : "box is body b") + ", e = " + std::to_string(e));
      RigidBody falling = box(m, size, x, rot, v, e);
      falling.angular_velocity = w;
      std::vector<RigidBody> bodies = box_first ? std::vector<RigidBody>{falling, ground()}
                                                : std::vector<RigidBody>{ground(), falling};
      const BodyIndex k = box_first ? 0 : 1;
      const Vec3 n = box_first ? Vec3(-Vec3::UnitZ()) : Vec3(Vec3::UnitZ());
      std::vector<Contact> contacts{contact(0, 1, P, n)};
      const double sign = box_first ? -1.0 : 1.0;  // the box gets sign · p n
      const Vec3 r = P - x;
      const Mat3 inv_j = bodies[k].inv_inertia_world();
      const double A = 1.0 / m + r.cross(n).dot(inv_j * r.cross(n));
      const double vn = normal_velocity(contacts[0], bodies[0], bodies[1]);
      ASSERT_LT(vn, -0.1);
      const double p = -(1.0 + e) * vn / A;
      const Vec3 l_about_p = m * (x - P).cross(v) + bodies[k].inertia_world() * w;

      resolve(*resolver, bodies, contacts);
      EXPECT_NEAR(contacts[0].impulse, p, kExact);
      EXPECT_LT((bodies[k].velocity - (v + sign * p * n / m)).norm(), kExact);
      EXPECT_LT((bodies[k].angular_velocity - (w + sign * inv_j * r.cross(p * n))).norm(), kExact);
      EXPECT_NEAR(normal_velocity(contacts[0], bodies[0], bodies[1]), -e * vn, kExact);
      const Vec3 l_after = m * (x - P).cross(bodies[k].velocity) + bodies[k].inertia_world() * bodies[k].angular_velocity;
      EXPECT_LT((l_after - l_about_p).norm(), kExact);
      EXPECT_EQ(bodies[1 - k].velocity, Vec3::Zero()) << "the ground is fixed";
    }
}

// Law: in a gravity-free scene impulses are internal, equal and opposite at one point: linear and
// angular momentum (about the origin) are conserved, to 1e-12 relative to Σ m|v| and Σ (|x × m v| + |J ω|).
TEST_P(ResolverConformance, ConservesMomentumInGravityFreeScenes) {
  const auto resolver = load_resolver(GetParam());
  for_each_cluster([&](Scene& s, double) {
    double p_scale = 0.0, l_scale = 0.0;
    for (const RigidBody& b : s.bodies) {
      p_scale += b.mass * b.velocity.norm();
      l_scale += b.position.cross(b.mass * b.velocity).norm() + (b.inertia_world() * b.angular_velocity).norm();
    }
    const Vec3 p0 = linear_momentum(s.bodies), l0 = angular_momentum(s.bodies);
    resolve(*resolver, s.bodies, s.contacts);
    EXPECT_LE((linear_momentum(s.bodies) - p0).norm(), kExact * p_scale);
    EXPECT_LE((angular_momentum(s.bodies) - l0).norm(), kExact * l_scale);
  });
}

// Law: with one e ≤ 1 for every contact, an impact never adds kinetic energy: E⁺ ≤ E (1 + 1e-12), and the
// resolver reports no energy_gain_events. Claim `elastic`: at e = 1 it keeps it, |E⁺ − E| ≤ 1e-12 E (a
// resolver that does not bounce slow contacts, e.g. below a bounce threshold, loses some).
TEST_P(ResolverConformance, NeverGainsEnergyWithUniformRestitution) {
  const auto resolver = load_resolver(GetParam());
  for_each_cluster([&](Scene& s, double e) {
    const double e0 = kinetic_energy(s.bodies);
    const ResolverCounters c = resolve(*resolver, s.bodies, s.contacts);
    EXPECT_LE(kinetic_energy(s.bodies), e0 * (1 + kExact));
    if (e == 1.0 && GetParam().claims_capability("elastic")) {
      EXPECT_NEAR(kinetic_energy(s.bodies), e0, kExact * e0);
    }
    EXPECT_EQ(c.energy_gain_events, 0u);
  });
}

// Law: after the resolve no contact approaches: v_n ≥ −tolerance at every contact (the plugin's stated
// tolerance, `approach_tolerance`), and the counters' residual says so too.
TEST_P(ResolverConformance, LeavesNoContactApproaching) {
  const auto resolver = load_resolver(GetParam());
  const double tolerance = GetParam().approach_tolerance;
  for_each_cluster([&](Scene& s, double) {
    const ResolverCounters c = resolve(*resolver, s.bodies, s.contacts);
    for (const Contact& k : s.contacts)
      EXPECT_GE(normal_velocity(k, s.bodies[k.a], s.bodies[k.b]), -tolerance) << "contact " << k.a << "–" << k.b;
    EXPECT_LE(c.residual, tolerance);
    EXPECT_EQ(c.non_converged, 0u);
  });
}

// Law: each contact's `impulse` is the total normal impulse applied there (finite): applying −impulse at
// every contact to the resolved velocities gives back the initial ones (1e-12 relative to the speeds).
// A negative (pulling) impulse is never silent: contacts with impulse < 0 ≤ pulling_impulses. Counters
// are filled: at least one island, contacts in (0, all], at least one round, residual finite and ≥ 0,
// no non-finite value caught. (The hexagon's twelve contacts on seven spheres are rank-deficient, so
// singular_systems may count them; it is not asserted.)
TEST_P(ResolverConformance, ReportsImpulsesAndCounters) {
  const auto resolver = load_resolver(GetParam());
  for_each_cluster([&](Scene& s, double) {
    const std::vector<RigidBody> before = s.bodies;
    const ResolverCounters c = resolve(*resolver, s.bodies, s.contacts);
    std::vector<RigidBody> undone = s.bodies;
    std::uint64_t pulling = 0;
    for (const Contact& k : s.contacts) {
      EXPECT_TRUE(std::isfinite(k.impulse)) << "impulse " << k.impulse;
      pulling += k.impulse < 0.0;
      apply_contact_impulse(k, -k.impulse, undone[k.a], undone[k.b]);
    }
    EXPECT_LE(pulling, c.pulling_impulses);
    for (std::size_t i = 0; i < before.size(); ++i) {
      const double scale = 1.0 + before[i].velocity.norm() + before[i].angular_velocity.norm();
      EXPECT_LT((undone[i].velocity - before[i].velocity).norm(), kExact * scale) << "body " << i;
      EXPECT_LT((undone[i].angular_velocity - before[i].angular_velocity).norm(), kExact * scale) << "body " << i;
    }
    EXPECT_GE(c.islands, 1u);
    EXPECT_GE(c.contacts, 1u);
    EXPECT_LE(c.contacts, s.contacts.size());
    EXPECT_GE(c.rounds, 1u);
    EXPECT_TRUE(std::isfinite(c.residual) && c.residual >= 0.0);
    EXPECT_EQ(c.nan_caught, 0u);
  });
}

// Law: a contact that separates (v_n > 0), alone, receives no impulse: velocities bit-identical.
TEST_P(ResolverConformance, LeavesASeparatingContactAlone) {
  const auto resolver = load_resolver(GetParam());
  std::vector<RigidBody> bodies{ground(1.0), sphere(1.0, 0.5, Vec3(0, 0, 0.5), Vec3(0.2, 0, 0.3), 1.0)};
  bodies[1].angular_velocity = Vec3(0.1, -0.4, 0.2);
  const std::vector<RigidBody> before = bodies;
  std::vector<Contact> contacts{contact(0, 1, Vec3::Zero(), Vec3::UnitZ())};
  resolve(*resolver, bodies, contacts);
  EXPECT_EQ(contacts[0].impulse, 0.0);
  EXPECT_EQ(bodies[1].velocity, before[1].velocity);
  EXPECT_EQ(bodies[1].angular_velocity, before[1].angular_velocity);
}

// Refusal: an option the resolver does not read is refused when it is loaded, with a message naming it.
TEST_P(ResolverConformance, RefusesAnUnknownOption) {
  const std::string message = unknown_option_message(GetParam(), ModuleKind::resolver, "conformance_no_such_option");
  EXPECT_NE(message.find("has no option 'conformance_no_such_option'"), std::string::npos) << message;
}

// Determinism: two modules loaded separately resolve the same scenes to bit-identical velocities,
// impulses and counters.
TEST_P(ResolverConformance, TwoRunsAreBitIdentical) {
  const auto first = load_resolver(GetParam());
  const auto second = load_resolver(GetParam());
  for_each_cluster([&](Scene& s, double) {
    Scene t = s;
    const ResolverCounters c1 = resolve(*first, s.bodies, s.contacts);
    const ResolverCounters c2 = resolve(*second, t.bodies, t.contacts);
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      EXPECT_EQ(s.bodies[i].velocity, t.bodies[i].velocity) << "body " << i;
      EXPECT_EQ(s.bodies[i].angular_velocity, t.bodies[i].angular_velocity) << "body " << i;
      EXPECT_EQ(s.bodies[i].position, t.bodies[i].position) << "body " << i;
    }
    for (std::size_t k = 0; k < s.contacts.size(); ++k) EXPECT_EQ(s.contacts[k].impulse, t.contacts[k].impulse);
    EXPECT_EQ(c1.rounds, c2.rounds);
    EXPECT_EQ(c1.islands, c2.islands);
    EXPECT_EQ(c1.residual, c2.residual);
  });
}

}  // namespace
}  // namespace impetus::conformance
