// The sequential resolver on impacts with a known answer specific to it: one impulse per single contact,
// the paper's Figure 1 (where sequential resolution breaks the symmetry) and Newton's cradle. The
// contract's closed forms (head-on, oblique, a box corner) are checked by the resolver conformance suite
// (plugins/conformance, tests/conformance).
#include "mirtich_test_support.hpp"

#include <cstdio>

namespace impetus::mirtich_test {
namespace {

constexpr double kExact = 1e-12;  // tolerance for closed-form answers (rounding only)

// A single approaching contact takes exactly one impulse (its closed form, checked by the conformance
// suite), which leaves it at v_n⁺ = −e v_n with no residual: rounds = 1, residual exactly 0, for two
// touching balls at 2 m/s and e = 0, 0.5, 1.
TEST(MirtichImpacts, ASingleContactTakesOneImpulse) {
  for (const double e : {0.0, 0.5, 1.0}) {
    std::vector<RigidBody> bodies;
    std::vector<Contact> contacts;
    cradle(2, e, 2.0, bodies, contacts);
    const ResolverCounters c = resolve(bodies, contacts);
    EXPECT_EQ(c.rounds, 1u) << "e = " << e;
    EXPECT_EQ(c.residual, 0.0) << "e = " << e;
    EXPECT_EQ(c.non_converged, 0u) << "e = " << e;
  }
}

// The paper's Figure 1: ball 1 moves along +x into balls 2 and 3, which touch each other and ball 1
// symmetrically (equal spheres). Resolving P12 before P13 (the tie is broken by index) gives ball 2 a
// larger momentum than ball 3, although symmetry says they should be equal (paper, sec. 1). The
// asymmetry ||p2| − |p3|| must exceed 1e-3; momentum is conserved and energy not gained (1e-12).
TEST(MirtichImpacts, FigureOneBilliardsComeOutAsymmetric) {
  for (const double e : {1.0, 0.0}) {
    for (const MirtichOrder order : {MirtichOrder::most_approaching, MirtichOrder::index}) {
      const double r = 0.5;
      std::vector<RigidBody> bodies{sphere(1, r, Vec3(-std::sqrt(3.0) * r, 0, 0), Vec3(1, 0, 0), e),
                                    sphere(1, r, Vec3(0, r, 0), Vec3::Zero(), e),
                                    sphere(1, r, Vec3(0, -r, 0), Vec3::Zero(), e)};
      const auto touching = [&](BodyIndex a, BodyIndex b) {
        const Vec3 n = (bodies[b].position - bodies[a].position).normalized();
        return contact(a, b, bodies[a].position + r * n, n);
      };
      std::vector<Contact> contacts{touching(0, 1), touching(0, 2), touching(1, 2)};
      const Vec3 p0 = linear_momentum(bodies);
      const double k0 = kinetic_energy(bodies);
      MirtichSettings settings;
      settings.order = order;
      const ResolverCounters c = resolve(bodies, contacts, settings);
      const double p2 = bodies[1].velocity.norm(), p3 = bodies[2].velocity.norm();
      std::printf("[ figure 1 ] e = %.1f order %s: |p1| = %.6f |p2| = %.6f |p3| = %.6f, asymmetry %.6f, "
                  "%llu impulses, impulses P12 %.6f P13 %.6f P23 %.6f\n",
                  e, order == MirtichOrder::index ? "index" : "most_approaching", bodies[0].velocity.norm(), p2, p3,
                  p2 - p3, static_cast<unsigned long long>(c.rounds), contacts[0].impulse, contacts[1].impulse,
                  contacts[2].impulse);
      EXPECT_GT(std::abs(p2 - p3), 1e-3) << "e = " << e;
      EXPECT_EQ(c.non_converged, 0u);
      EXPECT_LE(c.residual, settings.tolerance);
      EXPECT_LT((linear_momentum(bodies) - p0).norm(), kExact);
      EXPECT_LE(kinetic_energy(bodies), k0 + kExact);
    }
  }
}

// Newton's cradle, 5 equal balls, e = 1, the first moving at 1 m/s: one impulse per contact in turn,
// and only the last ball moves, at 1 m/s; the others stop (1e-12). Momentum and energy conserved.
TEST(MirtichImpacts, NewtonsCradleGivesTheClassicResult) {
  for (const MirtichOrder order : {MirtichOrder::most_approaching, MirtichOrder::index}) {
    std::vector<RigidBody> bodies;
    std::vector<Contact> contacts;
    cradle(5, 1.0, 1.0, bodies, contacts);
    MirtichSettings settings;
    settings.order = order;
    const ResolverCounters c = resolve(bodies, contacts, settings);
    for (int i = 0; i < 4; ++i) EXPECT_LT(bodies[i].velocity.norm(), kExact) << "ball " << i;
    EXPECT_LT((bodies[4].velocity - Vec3(1, 0, 0)).norm(), kExact);
    EXPECT_LT((linear_momentum(bodies) - Vec3(1, 0, 0)).norm(), kExact);
    EXPECT_NEAR(kinetic_energy(bodies), 0.5, kExact);
    EXPECT_EQ(c.rounds, 4u);
    for (const Contact& k : contacts) EXPECT_NEAR(k.impulse, 1.0, kExact);
  }
}

// Two balls in, two balls out: the first two of five move at 1 m/s (e = 1); sequential impulses end
// with the last two moving at 1 m/s and the rest at rest (1e-12), as the classic cradle does.
TEST(MirtichImpacts, NewtonsCradleTwoInTwoOut) {
  std::vector<RigidBody> bodies;
  std::vector<Contact> contacts;
  cradle(5, 1.0, 1.0, bodies, contacts);
  bodies[1].velocity = Vec3(1, 0, 0);
  const ResolverCounters c = resolve(bodies, contacts);
  for (int i = 0; i < 3; ++i) EXPECT_LT(bodies[i].velocity.norm(), kExact) << "ball " << i;
  for (int i = 3; i < 5; ++i) EXPECT_LT((bodies[i].velocity - Vec3(1, 0, 0)).norm(), kExact) << "ball " << i;
  EXPECT_NEAR(kinetic_energy(bodies), 1.0, kExact);
  EXPECT_EQ(c.non_converged, 0u);
}

// Contacts that separate or touch get nothing; below the bounce threshold restitution is not applied.
TEST(MirtichImpacts, SeparatingContactsAreLeftAloneAndSlowImpactsDoNotBounce) {
  std::vector<RigidBody> bodies{sphere(1, 0.5, Vec3(0, 0, 0.5), Vec3(0, 0, 0.3), 1.0), ground()};
  std::vector<Contact> contacts{contact(0, 1, Vec3::Zero(), -Vec3::UnitZ())};
  ResolverCounters c = resolve(bodies, contacts);
  EXPECT_EQ(c.rounds, 0u);
  EXPECT_EQ(contacts[0].impulse, 0.0);
  EXPECT_EQ(bodies[0].velocity, Vec3(0, 0, 0.3));

  bodies[0].velocity = Vec3(0, 0, -0.01);  // slower than the default bounce threshold 0.05 m/s
  c = resolve(bodies, contacts);
  EXPECT_EQ(c.rounds, 1u);
  EXPECT_LT(bodies[0].velocity.norm(), kExact);
  EXPECT_NEAR(contacts[0].impulse, 0.01, kExact);
}

}  // namespace
}  // namespace impetus::mirtich_test
