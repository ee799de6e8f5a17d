// The sequential resolver with Coulomb friction, one collision at a time (Mirtich's integration in the
// normal impulse, resolution/mirtich/friction.hpp): closed forms for a sliding sphere, isotropy,
// agreement with the instantaneous Coulomb impact where the slip direction does not turn, energy for
// an oblique spinning rod (Kane's example), and bit-identity of the frictionless path.
#include "impetus/resolution/mirtich/friction.hpp"
#include "mirtich_test_support.hpp"

#include <Eigen/Dense>

#include <cstdio>
#include <numbers>
#include <optional>
#include <random>

namespace impetus::mirtich_test {
namespace {

constexpr double kExact = 1e-12;     // closed forms: rounding only
constexpr double kAgreement = 1e-9;  // the tolerance for an integrated impulse

double relative_error(const Vec3& got, const Vec3& want) { return (got - want).norm() / want.norm(); }

// K measured, not computed: the change of u_b − u_a at `point` caused by each unit world impulse.
Mat3 measured_collision_matrix(const RigidBody& a, const RigidBody& b, const Vec3& point) {
  Mat3 k;
  const auto u = [&point](const RigidBody& x, const RigidBody& y) -> Vec3 { return y.velocity_at(point) - x.velocity_at(point); };
  for (int i = 0; i < 3; ++i) {
    RigidBody a1 = a, b1 = b;
    Contact c = contact(0, 1, point, Vec3::UnitZ());
    apply_contact_impulse(c, Vec3(Vec3::Unit(i)), a1, b1);
    k.col(i) = u(a1, b1) - u(a, b);
  }
  return k;
}

// The instantaneous Coulomb impact with e = 0 at one contact (the model the integration must agree
// with where the slip does not turn): P with u⁺ = u⁻ + K P, u_n⁺ = 0, and either u_t⁺ = 0 with
// ‖p_t‖ ≤ μ p_n (stick, one linear solve) or p_t = −μ p_n ŵ with u_t⁺ = s ŵ, s > 0 (slide: ŵ found by
// scanning its angle and bisecting the sign changes of ŵ × u_t⁺). Returns nothing if neither exists.
std::optional<Vec3> instantaneous_coulomb(const Mat3& k, const Vec3& u, const Vec3& n, double mu) {
  const Vec3 stick = k.fullPivLu().solve(-u);
  const double pn = stick.dot(n);
  if (pn >= 0.0 && (stick - pn * n).norm() <= mu * pn) return stick;
  Vec3 t1, t2;
  tangent_basis(n, t1, t2);
  const auto impulse = [&](double angle) {
    const Vec3 w = std::cos(angle) * t1 + std::sin(angle) * t2;
    const Vec3 d = n - mu * w;
    return Vec3((-u.dot(n) / n.dot(k * d)) * d);
  };
  const auto turning = [&](double angle) {  // ŵ × u_t⁺ (along n) and ŵ·u_t⁺
    const Vec3 w = std::cos(angle) * t1 + std::sin(angle) * t2;
    const Vec3 after = u + k * impulse(angle);
    return std::pair{w.cross(after).dot(n), w.dot(after)};
  };
  const int samples = 3600;
  for (int i = 0; i < samples; ++i) {
    double lo = 2 * std::numbers::pi * i / samples, hi = 2 * std::numbers::pi * (i + 1) / samples;
    double f_lo = turning(lo).first;
    if ((f_lo < 0) == (turning(hi).first < 0)) continue;
    for (int j = 0; j < 200; ++j) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      const double f = turning(mid).first;
      if ((f < 0) == (f_lo < 0)) {
        lo = mid;
        f_lo = f;
      } else {
        hi = mid;
      }
    }
    const Vec3 p = impulse(hi);
    if (turning(hi).second > 0.0 && p.dot(n) > 0.0) return p;
  }
  return std::nullopt;
}

// The world impulse a resolved contact applied to b.
Vec3 applied_impulse(const Contact& c) { return c.impulse * c.normal + c.tangent_impulse; }

void set_friction(RigidBody& body, double mu) { body.material.friction = mu; }

// A sphere (mass m, radius R, no spin) sliding on the fixed ground with horizontal velocity v0 and
// approach speed vn, e = 0: compression takes p_n = m vn (K_nn = 1/m, K_tn = 0), the slip closes at
// rate (7/2) μ / m per unit p_n. If μ p_n ≥ (2/7) m v0 the ball ends rolling: slip 0 and v = 5/7 v0;
// otherwise it slides throughout and Δv_t = μ p_n / m exactly. Both 1e-12 relative.
TEST(MirtichFriction, SlidingSphereMatchesTheClosedForm) {
  const double m = 2.0, r = 0.3;
  struct Case {
    double mu, v0, vn;
    bool sticks;
  };
  for (const Case& k : {Case{0.5, 1.0, 0.2, false}, Case{0.5, 0.2, 1.0, true}, Case{1.0, 3.0, 0.5, false},
                        Case{0.3, 0.7, 2.0, true}}) {
    std::vector<RigidBody> bodies{ground(), sphere(m, r, Vec3(0, 0, r), Vec3(k.v0, 0, -k.vn))};
    set_friction(bodies[0], k.mu);
    set_friction(bodies[1], k.mu);
    std::vector<Contact> contacts{contact(0, 1, Vec3::Zero(), Vec3::UnitZ())};
    const ResolverCounters c = resolve(bodies, contacts);
    ASSERT_EQ(k.mu * m * k.vn >= 2.0 / 7.0 * m * k.v0, k.sticks);
    EXPECT_NEAR(contacts[0].impulse, m * k.vn, kExact * m * k.vn);
    const RigidBody& ball = bodies[1];
    const double slip = ball.velocity_at(Vec3::Zero()).x();
    if (k.sticks) {
      EXPECT_NEAR(ball.velocity.x(), 5.0 / 7.0 * k.v0, kExact * k.v0);
      EXPECT_NEAR(slip, 0.0, kExact * k.v0);
      EXPECT_EQ(contacts[0].mode, ContactMode::stick);
      EXPECT_EQ(c.sticking, 1u);
    } else {
      EXPECT_NEAR(ball.velocity.x(), k.v0 - k.mu * k.vn, kExact * k.v0);
      EXPECT_NEAR(contacts[0].tangent_impulse.x(), -k.mu * m * k.vn, kExact * m * k.vn);
      EXPECT_EQ(contacts[0].mode, ContactMode::slide);
      EXPECT_EQ(c.sliding, 1u);
      // Friction work = −μ ∫ ‖u_t‖ dp_n with ‖u_t‖ linear in p_n.
      const double closing = 3.5 * k.mu / m;
      const double p = m * k.vn;
      EXPECT_NEAR(c.friction_work, -k.mu * (k.v0 * p - 0.5 * closing * p * p), kExact * k.v0 * p);
    }
    EXPECT_NEAR(ball.velocity.z(), 0.0, kExact * k.vn);
    EXPECT_LE(c.friction_work, 0.0);
    EXPECT_EQ(c.non_converged, 0u);
  }
}

// The same sphere with its slide direction turned about the normal by several angles: the impulse
// turns with it and keeps its size (1e-12), in both the sliding and the sticking regime.
TEST(MirtichFriction, FrictionIsIsotropicAboutTheNormal) {
  const double m = 1.5, r = 0.25, mu = 0.4;
  for (const double v0 : {2.0, 0.1}) {
    Vec3 reference = Vec3::Zero();
    for (const double angle : {0.0, 0.3, 1.0, 2.5, 4.0, 5.9}) {
      const Vec3 dir(std::cos(angle), std::sin(angle), 0.0);
      std::vector<RigidBody> bodies{ground(), sphere(m, r, Vec3(0, 0, r), v0 * dir - Vec3(0, 0, 0.8))};
      set_friction(bodies[0], mu);
      set_friction(bodies[1], mu);
      std::vector<Contact> contacts{contact(0, 1, Vec3::Zero(), Vec3::UnitZ())};
      resolve(bodies, contacts);
      // The impulse in the frame that turns with the slide direction.
      const Vec3 p = applied_impulse(contacts[0]);
      const Vec3 in_slide_frame(p.dot(dir), p.dot(Vec3::UnitZ().cross(dir)), p.z());
      if (angle == 0.0) reference = in_slide_frame;
      EXPECT_LT(relative_error(in_slide_frame, reference), kExact) << "v0 " << v0 << " angle " << angle;
    }
  }
}

// K as integrate_frictional_impact uses it equals the velocity change measured by applying unit
// impulses (1e-12 relative) for two movable boxes in general orientations.
TEST(MirtichFriction, CollisionMatrixIsTheMeasuredVelocityChange) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto rotation = [&] { return Mat3(Quat(unit(random), unit(random), unit(random), unit(random)).normalized()); };
  const RigidBody a = box(2.0, Vec3(0.5, 0.3, 0.2), Vec3(0.1, 0.2, -0.3), rotation());
  const RigidBody b = box(0.7, Vec3(0.2, 0.6, 0.4), Vec3(-0.2, 0.1, 0.4), rotation());
  const Vec3 point(0.05, -0.1, 0.1);
  const Mat3 k = mirtich::collision_matrix(a, b, point);
  const Mat3 measured = measured_collision_matrix(a, b, point);
  EXPECT_LT((k - measured).norm() / measured.norm(), kExact);
  EXPECT_LT((k - k.transpose()).norm() / k.norm(), kExact);
  EXPECT_EQ(mirtich::collision_matrix(ground(), ground(), point), Mat3::Zero());
}

// A box corner (box 0.4 × 0.3 × 0.2 m, 1.3 kg, seeded random orientation and spin) hitting the fixed
// ground; `slip` and the approach speed set the contact velocity, the spin is random.
struct CornerImpact {
  std::vector<RigidBody> bodies;
  std::vector<Contact> contacts;
  Mat3 k;
  Vec3 u;  // relative contact velocity before
};
CornerImpact corner_impact(std::mt19937& random, double mu, double restitution, const Vec3& slip, double approach) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Mat3 rotation = Quat(unit(random), unit(random), unit(random), unit(random)).normalized().toRotationMatrix();
  const Vec3 half(0.2, 0.15, 0.1);
  RigidBody b = box(1.3, 2.0 * half, Vec3::Zero(), rotation);
  // The lowest corner touches the ground at the origin.
  Vec3 lowest = Vec3::Zero();
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p = rotation * Vec3((corner & 1 ? 1 : -1) * half.x(), (corner & 2 ? 1 : -1) * half.y(),
                                   (corner & 4 ? 1 : -1) * half.z());
    if (corner == 0 || p.z() < lowest.z()) lowest = p;
  }
  b.position = -lowest;
  b.angular_velocity = 3.0 * Vec3(unit(random), unit(random), unit(random));
  const Vec3 u(slip.x(), slip.y(), -approach);
  b.velocity = u - b.angular_velocity.cross(Vec3::Zero() - b.position);  // u = v + ω × r at the corner
  b.material.restitution = restitution;
  CornerImpact out;
  out.bodies = {test::ground_plane(restitution), b};
  set_friction(out.bodies[0], mu);
  set_friction(out.bodies[1], mu);
  out.contacts = {contact(0, 1, Vec3::Zero(), Vec3::UnitZ())};
  out.k = mirtich::collision_matrix(out.bodies[0], out.bodies[1], Vec3::Zero());
  out.u = u;
  return out;
}

// The unit slip directions ŵ along which the slip keeps its direction while it closes:
// K_tn − μ K_tt ŵ = λ ŵ with λ < 0 (contact frame of the ground: t = x, y).
std::vector<Vec3> straight_closing_directions(const Mat3& k, double mu) {
  std::vector<Vec3> out;
  const int samples = 3600;
  const auto rate = [&](double angle) {
    const Vec3 w(std::cos(angle), std::sin(angle), 0.0);
    Vec3 r = k * Vec3(-mu * w.x(), -mu * w.y(), 1.0);
    r.z() = 0.0;
    return std::pair{w.cross(r).z(), w};
  };
  for (int i = 0; i < samples; ++i) {
    double lo = 2 * std::numbers::pi * i / samples, hi = 2 * std::numbers::pi * (i + 1) / samples;
    double f_lo = rate(lo).first;
    if ((f_lo < 0) == (rate(hi).first < 0)) continue;
    for (int j = 0; j < 200; ++j) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      if ((rate(mid).first < 0) == (f_lo < 0)) {
        lo = mid;
        f_lo = rate(mid).first;
      } else {
        hi = mid;
      }
    }
    const Vec3 w = rate(hi).second;
    Vec3 r = k * Vec3(-mu * w.x(), -mu * w.y(), 1.0);
    if (r.head<2>().dot(w.head<2>()) < 0.0) out.push_back(w);
  }
  return out;
}

// Agreement with the instantaneous Coulomb impact (e = 0, 1e-9 relative in the whole impulse) for a
// box corner hitting the ground obliquely with spin, 3D slip, seeded random cases where the two models
// must agree: (a) the slip starts along a direction it keeps while it closes (planar sliding), slow or
// fast, so the contact ends stuck or still sliding; (b) any slip direction, small enough that the
// contact ends stuck (then u⁺ = 0 and P = −K⁻¹ u⁻ whichever way the slip turned). At least 20
// compared cases are required.
TEST(MirtichFriction, AgreesWithTheInstantaneousCoulombImpactWhereTheSlipDoesNotTurn) {
  std::mt19937 random(2024);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int compared = 0, stuck = 0, slid = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const double mu = 0.2 + 0.8 * unit(random);
    const double approach = 0.5 + unit(random);
    const bool straight = trial % 2 == 0;
    const double speed = straight ? 0.05 + 4.0 * unit(random) : 0.02 * unit(random);
    // Draw the box first (the direction depends on K), then set the slip on the same box.
    std::mt19937 box_random = random;
    CornerImpact probe = corner_impact(box_random, mu, 0.0, Vec3::Zero(), approach);
    Vec3 slip_dir(std::cos(7.0 * trial), std::sin(7.0 * trial), 0.0);
    if (straight) {
      const std::vector<Vec3> dirs = straight_closing_directions(probe.k, mu);
      if (dirs.empty()) continue;
      slip_dir = dirs[trial % dirs.size()];
    }
    CornerImpact impact = corner_impact(random, mu, 0.0, speed * slip_dir, approach);
    const double k0 = kinetic_energy(impact.bodies);
    const ResolverCounters c = resolve(impact.bodies, impact.contacts);
    const Contact& r = impact.contacts[0];
    const Vec3 got = applied_impulse(r);
    const std::optional<Vec3> want = instantaneous_coulomb(impact.k, impact.u, Vec3::UnitZ(), mu);
    ASSERT_TRUE(want.has_value()) << "trial " << trial;
    if (!straight && r.mode != ContactMode::stick) continue;  // turned and slid: not comparable
    EXPECT_LT(relative_error(got, *want), kAgreement) << "trial " << trial << " mode " << contact_mode_name(r.mode);
    EXPECT_EQ(c.non_converged, 0u);
    EXPECT_LE(kinetic_energy(impact.bodies), k0 * (1 + kExact));
    ++compared;
    ++(r.mode == ContactMode::stick ? stuck : slid);
  }
  std::printf("[ mirtich friction ] instantaneous agreement: %d cases compared (%d stuck, %d slid)\n", compared,
              stuck, slid);
  EXPECT_GE(compared, 20);
  EXPECT_GE(stuck, 3);
  EXPECT_GE(slid, 3);
}

// Where the slip direction turns during a collision that ends sliding, the integrated impulse and the
// instantaneous one legitimately differ (the friction impulse follows the turning slip instead of
// pointing against the final slip). Printed: the largest relative difference over 20 seeded corner
// impacts with large slip in random directions; asserted: physics only (no energy gain, 1e-12
// relative; u_n⁺ ≥ −1e-12 m/s; ‖p_t‖ ≤ μ p_n).
TEST(MirtichFriction, TurningSlipDiffersFromTheInstantaneousModelWithoutGainingEnergy) {
  std::mt19937 random(99);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double largest = 0.0;
  int turning = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const double mu = 0.3 + 0.6 * unit(random);
    const double angle = 2 * std::numbers::pi * unit(random);
    CornerImpact impact =
        corner_impact(random, mu, 0.0, (2.0 + 2.0 * unit(random)) * Vec3(std::cos(angle), std::sin(angle), 0), 1.0);
    const double k0 = kinetic_energy(impact.bodies);
    const ResolverCounters c = resolve(impact.bodies, impact.contacts);
    const Contact& r = impact.contacts[0];
    const std::optional<Vec3> want = instantaneous_coulomb(impact.k, impact.u, Vec3::UnitZ(), mu);
    if (want && r.mode == ContactMode::slide) {
      largest = std::max(largest, relative_error(applied_impulse(r), *want));
      ++turning;
    }
    EXPECT_LE(kinetic_energy(impact.bodies), k0 * (1 + kExact)) << "trial " << trial;
    EXPECT_GE(relative_velocity(r, impact.bodies[0], impact.bodies[1]).z(), -kExact) << "trial " << trial;
    EXPECT_LE(r.tangent_impulse.norm(), mu * r.impulse * (1 + kExact)) << "trial " << trial;
    EXPECT_EQ(c.non_converged, 0u);
    EXPECT_LE(c.friction_work, 0.0);
  }
  std::printf("[ mirtich friction ] turning slip: %d sliding cases, largest relative difference from the "
              "instantaneous impact %.3e\n", turning, largest);
  EXPECT_GE(turning, 5);
}

// Where the slip direction turns, the adaptive RK4 integration is accurate to the tolerance:
// 20 seeded corner impacts with large slip in random directions, e = 0 and 0.5, give the same whole
// impulse (1e-9 relative) with the default limits as with a 100 times tighter local tolerance and ten
// times the step cap; both converge.
TEST(MirtichFriction, TurningSlipIntegrationIsConverged) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  mirtich::FrictionalImpactLimits tight;
  tight.relative_tolerance = 1e-15;
  tight.max_steps = 200000;
  double largest = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const double mu = 0.3 + 0.6 * unit(random), e = trial % 2 == 0 ? 0.0 : 0.5;
    const double angle = 2 * std::numbers::pi * unit(random);
    const CornerImpact impact =
        corner_impact(random, mu, e, (0.5 + 2.0 * unit(random)) * Vec3(std::cos(angle), std::sin(angle), 0), 1.0);
    const mirtich::FrictionalImpact normal = mirtich::integrate_frictional_impact(impact.k, impact.u, Vec3::UnitZ(), mu, e);
    const mirtich::FrictionalImpact fine =
        mirtich::integrate_frictional_impact(impact.k, impact.u, Vec3::UnitZ(), mu, e, tight);
    ASSERT_TRUE(normal.converged && fine.converged) << "trial " << trial;
    const double difference = relative_error(normal.impulse(Vec3::UnitZ()), fine.impulse(Vec3::UnitZ()));
    largest = std::max(largest, difference);
    EXPECT_LT(difference, kAgreement) << "trial " << trial << " steps " << normal.steps << " / " << fine.steps;
  }
  std::printf("[ mirtich friction ] turning slip: largest change with a 100x tighter tolerance %.3e\n", largest);
}

// A collision recorded from the pile of 1,000 primitives at μ = 0.5 (a box's corner on a capsule, e = 0):
// its slip spirals into zero, the direction turning ever faster, and before the slip's stall rule it sat
// at 3e-12 of the impact speed until the 20,000 steps ran out (43,410 such collisions made one step of
// the pile take 5 minutes). It must end, stuck, in a few thousand steps at most, as the instantaneous
// model says (sticking is inside the cone: u⁺ = 0 with ‖p_t‖ ≤ μ p_n), and agree with it to the
// integration's tolerance.
TEST(MirtichFriction, SlipSpirallingIntoZeroEndsStuck) {
  Mat3 k;
  k << 1.4450889470163437, 0.36245674839213282, 0.13026579052654894,  //
      0.36245674839213282, 0.80143577088779039, -0.2898679416413254,  //
      0.13026579052654891, -0.28986794164132534, 0.78185851709368559;
  const Vec3 u(-0.021151607067290995, -0.040807008194839622, 0.065646666452352731);
  const Vec3 n(0.0, 0.0, -1.0);
  const double mu = 0.5;
  const mirtich::FrictionalImpact impact = mirtich::integrate_frictional_impact(k, u, n, mu, 0.0);
  ASSERT_TRUE(impact.converged) << impact.steps << " steps";
  EXPECT_TRUE(impact.stuck);
  EXPECT_LT(impact.steps, 5000u);
  const Vec3 p = impact.impulse(n);
  EXPECT_LT((u + k * p).norm(), 1e-9 * u.norm());  // stuck with e = 0: the contact point stops
  EXPECT_LE(impact.tangent_impulse.norm(), mu * impact.normal_impulse * (1 + 1e-12));
  const std::optional<Vec3> instantaneous = instantaneous_coulomb(k, u, n, mu);
  ASSERT_TRUE(instantaneous.has_value());
  EXPECT_LT((u + k * *instantaneous).norm(), 1e-12 * u.norm());  // the model sticks too
}

// Kane's example: a slender rod (1 m × 2 cm × 2 cm, 1 kg) at 45° in the xz plane hits the ground with
// its lower end, moving obliquely and spinning. With Stronge's coefficient the collision never gains
// kinetic energy (after ≤ before × (1 + 1e-12)) for μ = 0.5 and 1, e = 0.5 and 1, several spins; with
// e = 1 and μ = 0 the energy is conserved to 1e-12 relative. The set must contain at least one
// collision whose slip reverses (Kane's case) and one that ends stuck.
TEST(MirtichFriction, SpinningRodNeverGainsEnergy) {
  const double tilt = std::numbers::pi / 4;
  const Mat3 rotation = Eigen::AngleAxisd(-tilt, Vec3::UnitY()).toRotationMatrix();  // long axis x → (cos, 0, sin)
  const Vec3 axis = rotation * Vec3::UnitX();
  int reversals = 0, sticks = 0;
  for (const double mu : {0.0, 0.5, 1.0}) {
    for (const double e : {0.5, 1.0}) {
      for (const double spin : {-8.0, 0.0, 5.0}) {
        for (const double vx : {-1.0, 0.5, 2.0}) {
          RigidBody rod = box(1.0, Vec3(1.0, 0.02, 0.02), 0.5 * axis, rotation, Vec3(vx, 0, -1.0), e);
          rod.angular_velocity = Vec3(0, spin, 0);
          std::vector<RigidBody> bodies{test::ground_plane(e), rod};
          set_friction(bodies[0], mu);
          set_friction(bodies[1], mu);
          std::vector<Contact> contacts{contact(0, 1, Vec3::Zero(), Vec3::UnitZ())};
          const double before = kinetic_energy(bodies);
          const Vec3 u = relative_velocity(contacts[0], bodies[0], bodies[1]);
          if (u.z() >= 0.0) continue;
          const mirtich::FrictionalImpact alone = mirtich::integrate_frictional_impact(
              mirtich::collision_matrix(bodies[0], bodies[1], Vec3::Zero()), u, Vec3::UnitZ(), mu, e);
          reversals += alone.reversed ? 1 : 0;
          sticks += alone.stuck ? 1 : 0;
          const ResolverCounters c = resolve(bodies, contacts);
          const double after = kinetic_energy(bodies);
          EXPECT_LE(after, before * (1 + kExact)) << "mu " << mu << " e " << e << " spin " << spin << " vx " << vx;
          if (mu == 0.0 && e == 1.0) {
            EXPECT_NEAR(after, before, kExact * before) << "spin " << spin << " vx " << vx;
          }
          EXPECT_EQ(c.non_converged, 0u);
        }
      }
    }
  }
  std::printf("[ mirtich friction ] rod impacts: %d with slip reversal, %d ending stuck\n", reversals, sticks);
  EXPECT_GE(reversals, 1);  // the set exercises Kane's case: slip reversal during the collision
  EXPECT_GE(sticks, 1);
}

// With μ = 0 the integration reduces to the frictionless closed form: p = −(1 + e) v_n / A_kk and
// energy conserved at e = 1 (1e-12 relative), for the 45° rod (the frictionless resolver path does not
// call it; this checks the integrator on its own).
TEST(MirtichFriction, FrictionlessIntegrationIsTheClosedForm) {
  const Mat3 rotation = Eigen::AngleAxisd(-std::numbers::pi / 4, Vec3::UnitY()).toRotationMatrix();
  RigidBody rod = box(1.0, Vec3(1.0, 0.02, 0.02), 0.5 * (rotation * Vec3::UnitX()), rotation, Vec3(1.0, 0.3, -1.0));
  rod.angular_velocity = Vec3(0.5, -4.0, -1.0);  // u_n = −1 − 4 × 0.354: approaching
  const std::vector<RigidBody> bodies{ground(), rod};
  const Mat3 k = mirtich::collision_matrix(bodies[0], bodies[1], Vec3::Zero());
  const Vec3 u = bodies[1].velocity_at(Vec3::Zero());
  for (const double e : {0.0, 0.5, 1.0}) {
    const mirtich::FrictionalImpact impact = mirtich::integrate_frictional_impact(k, u, Vec3::UnitZ(), 0.0, e);
    const double closed = -(1 + e) * u.z() / k(2, 2);
    EXPECT_NEAR(impact.normal_impulse, closed, kExact * closed) << "e " << e;
    EXPECT_EQ(impact.tangent_impulse, Vec3::Zero());
    EXPECT_NEAR(impact.velocity_after.z(), -e * u.z(), kExact * std::abs(u.z())) << "e " << e;
    EXPECT_NEAR(impact.restitution_work, -e * e * impact.compression_work, kExact * -impact.compression_work);
  }
}

// The frictionless resolver path is today's, bit for bit: a box corner with friction 0 (and e = 0.5)
// gets exactly p = −(1 + e) v_n / A_kk applied along the row (EXPECT_EQ on every double).
TEST(MirtichFriction, FrictionlessPathIsBitIdentical) {
  std::mt19937 random(5);
  for (int trial = 0; trial < 5; ++trial) {
    CornerImpact impact = corner_impact(random, 0.0, 0.5, Vec3(0.7, -0.4, 0), 1.2);
    std::vector<RigidBody> expected = impact.bodies;
    const resolution::ImpulseRow row = resolution::make_contact_row(expected, impact.contacts[0]);
    const double vn = resolution::row_velocity(row, expected);
    const double e = resolution::effective_restitution(row, -vn, MirtichSettings{}.resting);
    const double p = -(1.0 + e) * vn / resolution::self_coupling(row);
    resolution::apply_row_impulse(row, p, expected);

    resolve(impact.bodies, impact.contacts);
    EXPECT_EQ(impact.contacts[0].impulse, p);
    EXPECT_EQ(impact.contacts[0].tangent_impulse, Vec3::Zero());
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(impact.bodies[1].velocity[i], expected[1].velocity[i]);
      EXPECT_EQ(impact.bodies[1].angular_velocity[i], expected[1].angular_velocity[i]);
    }
  }
}

// The resolver accepts scenes with friction.
TEST(MirtichFriction, AcceptsFriction) {
  MirtichResolver resolver{MirtichSettings{}};
  EXPECT_TRUE(static_cast<bool>(resolver.accept_friction()));
}

}  // namespace
}  // namespace impetus::mirtich_test
