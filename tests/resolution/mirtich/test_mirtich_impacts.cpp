// The sequential resolver on impacts with a known answer: single contacts (closed form), the paper's
// Figure 1 (where sequential resolution breaks the symmetry) and Newton's cradle.
#include "mirtich_test_support.hpp"

#include <cstdio>

namespace impetus::mirtich_test {
namespace {

constexpr double kExact = 1e-12;  // tolerance for closed-form answers (rounding only)

// 1D head-on impact of masses m1, m2 (velocities u1 > u2 along +x), restitution e:
//   v1 = (m1 u1 + m2 u2 + m2 e (u2 − u1)) / (m1 + m2),  v2 = (m1 u1 + m2 u2 + m1 e (u1 − u2)) / (m1 + m2).
// Checked for equal and unequal masses and e = 0, 0.5, 1 to 1e-12, with momentum conserved.
TEST(MirtichImpacts, HeadOnSpheresFollowTheOneDimensionalFormulas) {
  for (const auto& [m1, m2] : {std::pair{1.0, 1.0}, std::pair{2.0, 3.0}, std::pair{0.25, 4.0}}) {
    for (const double e : {0.0, 0.5, 1.0}) {
      const double u1 = 2.0, u2 = -1.0;
      std::vector<RigidBody> bodies{sphere(m1, 0.5, Vec3(0, 0, 0), Vec3(u1, 0, 0), e),
                                    sphere(m2, 0.5, Vec3(1, 0, 0), Vec3(u2, 0, 0), e)};
      std::vector<Contact> contacts{contact(0, 1, Vec3(0.5, 0, 0), Vec3::UnitX())};
      const ResolverCounters c = resolve(bodies, contacts);
      const double v1 = (m1 * u1 + m2 * u2 + m2 * e * (u2 - u1)) / (m1 + m2);
      const double v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2);
      SCOPED_TRACE("m1 = " + std::to_string(m1) + ", m2 = " + std::to_string(m2) + ", e = " + std::to_string(e));
      EXPECT_NEAR(bodies[0].velocity.x(), v1, kExact);
      EXPECT_NEAR(bodies[1].velocity.x(), v2, kExact);
      EXPECT_LT((bodies[0].velocity.tail<2>()).norm() + (bodies[1].velocity.tail<2>()).norm(), kExact);
      EXPECT_NEAR(m1 * bodies[0].velocity.x() + m2 * bodies[1].velocity.x(), m1 * u1 + m2 * u2, kExact);
      // The impulse is the momentum change of body b: p = m2 (v2 − u2).
      EXPECT_NEAR(contacts[0].impulse, m2 * (v2 - u2), kExact);
      EXPECT_EQ(c.rounds, 1u);
      EXPECT_EQ(c.islands, 1u);
      EXPECT_EQ(c.contacts, 1u);
      EXPECT_EQ(c.non_converged, 0u);
      EXPECT_EQ(c.residual, 0.0);
    }
  }
}

// Oblique impact of spheres along the line of centres n at 30°: tangential velocities are unchanged,
// normal ones follow the 1D formulas. For equal masses and e = 1 the balls leave at right angles.
TEST(MirtichImpacts, ObliqueImpactKeepsTangentialVelocities) {
  const Vec3 n(std::cos(M_PI / 6), std::sin(M_PI / 6), 0.0);
  for (const auto& [m2, e] : {std::pair{1.0, 1.0}, std::pair{3.0, 0.5}}) {
    const double m1 = 1.0;
    const Vec3 u1(1.0, 0.0, 0.2);
    std::vector<RigidBody> bodies{sphere(m1, 0.5, Vec3::Zero(), u1, e), sphere(m2, 0.5, n, Vec3::Zero(), e)};
    std::vector<Contact> contacts{contact(0, 1, 0.5 * n, n)};
    resolve(bodies, contacts);
    const double un = u1.dot(n);
    const double v1n = (m1 * un + m2 * e * (0.0 - un)) / (m1 + m2);
    const double v2n = (m1 * un + m1 * e * un) / (m1 + m2);
    EXPECT_LT((bodies[0].velocity - ((u1 - un * n) + v1n * n)).norm(), kExact);
    EXPECT_LT((bodies[1].velocity - v2n * n).norm(), kExact);
    EXPECT_LT(bodies[0].angular_velocity.norm() + bodies[1].angular_velocity.norm(), kExact);  // central impact
    if (m2 == 1.0 && e == 1.0) {
      EXPECT_NEAR(bodies[0].velocity.dot(bodies[1].velocity), 0.0, kExact);
    }
  }
}

// A box falling and spinning onto one corner of a fixed ground. Closed form for one contact with
// r = P − x, n = −z (out of the box into the ground), J⁻¹ = R J_body⁻¹ Rᵀ:
//   A = 1/m + (r × n)·J⁻¹(r × n),  p = −(1 + e) v_n / A,  v⁺ = v − p n / m,  ω⁺ = ω − J⁻¹(r × p n),
// so v_n⁺ = −e v_n; and angular momentum about P is conserved (the impulse passes through P). 1e-12.
TEST(MirtichImpacts, TiltedBoxOnOneCornerMatchesTheClosedForm) {
  const Mat3 rot = (Eigen::AngleAxisd(0.5, Vec3::UnitY()) * Eigen::AngleAxisd(0.2, Vec3::UnitX())).toRotationMatrix();
  const Vec3 size(1.0, 0.6, 0.4);
  const double m = 2.0, e = 0.5;
  // The lowest corner touches z = 0.
  Vec3 corner_body = Vec3::Zero();
  double lowest = 1e9;
  for (int i = 0; i < 8; ++i) {
    const Vec3 c((i & 1 ? 0.5 : -0.5) * size.x(), (i & 2 ? 0.5 : -0.5) * size.y(), (i & 4 ? 0.5 : -0.5) * size.z());
    if ((rot * c).z() < lowest) {
      lowest = (rot * c).z();
      corner_body = c;
    }
  }
  const Vec3 x(0.1, -0.2, -lowest);
  const Vec3 v(0.3, -0.2, -1.5), w(0.5, 1.0, -0.3);
  std::vector<RigidBody> bodies{box(m, size, x, rot, v, e), ground()};
  bodies[0].angular_velocity = w;
  const Vec3 P = x + rot * corner_body;
  ASSERT_NEAR(P.z(), 0.0, kExact);
  std::vector<Contact> contacts{contact(0, 1, P, -Vec3::UnitZ())};

  const Vec3 n = -Vec3::UnitZ(), r = P - x;
  const Mat3 inv_j = rot * bodies[0].inv_inertia_body * rot.transpose();
  const double A = 1.0 / m + r.cross(n).dot(inv_j * r.cross(n));
  const double vn = (Vec3::Zero() - (v + w.cross(r))).dot(n);
  ASSERT_LT(vn, 0.0);
  const double p = -(1.0 + e) * vn / A;
  const Vec3 l_about_p_before = m * (x - P).cross(v) + bodies[0].inertia_world() * w;

  resolve(bodies, contacts);
  EXPECT_NEAR(contacts[0].impulse, p, kExact);
  EXPECT_LT((bodies[0].velocity - (v - p * n / m)).norm(), kExact);
  EXPECT_LT((bodies[0].angular_velocity - (w - inv_j * r.cross(p * n))).norm(), kExact);
  EXPECT_NEAR(normal_velocity(contacts[0], bodies[0], bodies[1]), -e * vn, kExact);
  const Vec3 l_about_p_after = m * (x - P).cross(bodies[0].velocity) + bodies[0].inertia_world() * bodies[0].angular_velocity;
  EXPECT_LT((l_about_p_after - l_about_p_before).norm(), kExact);
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
