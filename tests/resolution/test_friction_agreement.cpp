// The two frictional resolvers on one contact with e = 0: `ledas` solves the instantaneous Coulomb
// impact, `mirtich` integrates the collision in the normal impulse. Where the slip does not turn during
// the collision (planar impacts) or the collision ends sticking (then P = −K⁻¹ u⁻ in both), they give
// the same impulse to 1e-9 (docs/conventions.md, "Friction"; resolution/mirtich/README.md says where
// they differ).
#include "impetus/resolution/ledas/ledas.hpp"
#include "impetus/resolution/mirtich/mirtich.hpp"
#include "impetus_test/bodies.hpp"

#include "impetus/core/mass.hpp"

#include <gtest/gtest.h>

#include <random>

namespace impetus {
namespace {

struct Outcome {
  double normal = 0.0;
  Vec3 tangent = Vec3::Zero();
  ContactMode mode = ContactMode::separate;
};

// A 1 × 0.6 × 0.4 m box of 2 kg whose lowest corner touches the ground z = 0, friction μ on both. With
// `mid_edge` the contact is the midpoint of the lowest edge along y instead (a box turned about y only:
// then the contact, the velocity and the spin lie in the x–z plane through the centre, and so does the
// slip).
std::vector<RigidBody> corner_on_ground(const Mat3& rotation, const Vec3& velocity, const Vec3& spin, double mu,
                                        bool mid_edge, Vec3& corner) {
  RigidBody box;
  box.shape = Box{Vec3(1.0, 0.6, 0.4)};
  set_primitive_mass(box, 2.0);
  box.rotation = rotation;
  box.velocity = velocity;
  box.angular_velocity = spin;
  box.material.friction = mu;
  Vec3 lowest = Vec3::Constant(1e9);
  for (int k = 0; k < 8; ++k) {
    const Vec3 p = rotation * Vec3(k & 1 ? 0.5 : -0.5, mid_edge ? 0.0 : k & 2 ? 0.3 : -0.3, k & 4 ? 0.2 : -0.2);
    if (p.z() < lowest.z()) lowest = p;
  }
  box.position = Vec3(0.0, 0.0, -lowest.z());
  corner = Vec3(lowest.x(), lowest.y(), 0.0);
  RigidBody ground = test::ground_plane();
  ground.material.friction = mu;
  return {ground, box};
}

Outcome resolve_with(CollisionResolver& resolver, std::vector<RigidBody> bodies, const Vec3& corner) {
  std::vector<Contact> contacts{test::contact(0, 1, corner, Vec3::UnitZ())};
  ResolverCounters counters;
  StepContext ctx;
  resolver.resolve(bodies, contacts, {}, ctx, counters);
  EXPECT_EQ(counters.non_converged, 0u);
  return {contacts[0].impulse, contacts[0].tangent_impulse, contacts[0].mode};
}

TEST(FrictionAgreement, OneContactWithoutRestitutionGivesTheSameImpulseInBothResolvers) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  LedasResolver ledas;
  MirtichResolver mirtich{MirtichSettings{}};
  int planar = 0, stuck = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const bool in_plane = trial % 2 == 0;  // turned about y, moving in x–z, contact mid-edge: planar
    const Mat3 rotation = in_plane ? Mat3(Eigen::AngleAxisd(0.8 * uniform(random), Vec3::UnitY()))
                                   : Mat3(Eigen::AngleAxisd(0.8 * uniform(random), Vec3::UnitY()) *
                                          Eigen::AngleAxisd(0.8 * uniform(random), Vec3::UnitX()));
    const Vec3 velocity = in_plane ? Vec3(uniform(random), 0.0, -1.0 - uniform(random) * 0.5)
                                   : Vec3(uniform(random), uniform(random), -1.0 - uniform(random) * 0.5);
    const Vec3 spin = in_plane ? Vec3(0.0, 3.0 * uniform(random), 0.0)
                               : 3.0 * Vec3(uniform(random), uniform(random), uniform(random));
    const double mu = 0.05 + 0.95 * (0.5 + 0.5 * uniform(random));
    Vec3 corner;
    const std::vector<RigidBody> bodies = corner_on_ground(rotation, velocity, spin, mu, in_plane, corner);
    const Vec3 u = bodies[1].velocity_at(corner);
    if (u.z() >= -0.1) continue;  // not an impact
    const Outcome m = resolve_with(mirtich, bodies, corner);
    // Where the slip turns during the collision (in 3D, or reverses in the plane) and the collision
    // ends sliding, the two models legitimately differ: compare only collisions that end sticking, and
    // planar ones that slide all along against the initial slip (‖p_t‖ = μ p_n, opposite to u_t⁻).
    const Vec3 slip(u.x(), u.y(), 0.0);
    const bool slid_straight = m.mode == ContactMode::slide && m.tangent.dot(slip) < 0.0 &&
                               std::abs(m.tangent.norm() - mu * m.normal) <= 1e-9 * m.normal;
    if (m.mode != ContactMode::stick && !(in_plane && slid_straight)) continue;
    const Outcome l = resolve_with(ledas, bodies, corner);
    const double scale = std::max(m.normal, 1e-3);
    EXPECT_NEAR(l.normal, m.normal, 1e-9 * scale) << "trial " << trial;
    EXPECT_LE((l.tangent - m.tangent).norm(), 1e-9 * scale) << "trial " << trial;
    EXPECT_EQ(l.mode, m.mode) << "trial " << trial;
    ++(m.mode == ContactMode::stick ? stuck : planar);
  }
  std::printf("[ friction ] ledas = mirtich on %d impacts sliding straight and %d ending stuck\n", planar, stuck);
  EXPECT_GE(planar, 20);
  EXPECT_GE(stuck, 20);
}

}  // namespace
}  // namespace impetus
