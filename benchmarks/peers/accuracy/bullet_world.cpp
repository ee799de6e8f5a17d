// Bullet (double precision) on the accuracy scenarios: a btDiscreteDynamicsWorld built from the Impetus
// bodies, stepped with stepSimulation(dt, 0) (exactly one internal step).
//
// Bodies: each movable body in its principal frame (Bullet takes a diagonal local inertia), so the
// Bullet transform is R·V with J_body = V diag(d) Vᵀ, and the shape sits in that frame through a compound
// when V is not the identity. Restitution √e on every body (Bullet multiplies the two bodies'
// coefficients: the product is the scene's e), no damping, no deactivation.
// Friction: each body's friction is √μ, so that the product Bullet forms for a contact is Impetus's
// geometric mean √(μ_a μ_b); no rolling or spinning friction (Impetus's point contacts have none).
// Bullet's friction as shipped: per contact point one friction row along the tangential slip, or along an
// arbitrary tangent where there is none (the second direction, SOLVER_USE_2_FRICTION_DIRECTIONS, is off
// by default), clamped to ±μ times the point's current normal impulse inside the iterations.
// Joints: btPoint2PointConstraint with the joined bodies' collisions disabled, as Impetus does.
// Settings: impact scenarios use the impulse-problem settings of bench_peers (contact ERP 0, split
// impulse off); simulations keep btContactSolverInfo as shipped (ERP 0.2, split impulse on) except the
// iteration count.
#include "peer_world.hpp"

#include "../bullet_support.hpp"

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <variant>

namespace impetus::peers::accuracy {
namespace {

using peers::from_bt;  // beside the overload for matrices below
btMatrix3x3 to_bt_matrix(const Mat3& m) {
  return btMatrix3x3(m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2));
}
Mat3 from_bt(const btMatrix3x3& m) {
  Mat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = m[r][c];
  return out;
}

class BulletWorld final : public PeerWorld {
 public:
  BulletWorld(const PeerScene& scene, int iterations)
      : dispatcher_(&collision_config_), dt_(scene.settings.dt) {
    world_ = std::make_unique<btDiscreteDynamicsWorld>(&dispatcher_, &broadphase_, &solver_, &collision_config_);
    world_->setGravity(to_bt(scene.settings.gravity));
    btContactSolverInfo& info = world_->getSolverInfo();
    info.m_numIterations = iterations;
    if (scene.settings.impulse_problem) {
      info.m_erp = 0.0;
      info.m_erp2 = 0.0;
      info.m_frictionERP = 0.0;
      info.m_splitImpulse = 0;
    }
    const double restitution = std::sqrt(scene_restitution(scene.bodies));
    const bool no_contacts = contact_free(scene);
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) add_body(scene, i, restitution, no_contacts);
    for (const Constraint& c : scene.constraints) {
      const auto& pp = std::get<PointPointConstraint>(c);
      // Pivots in each Bullet body's (principal) frame.
      const btVector3 pa = to_bt(Vec3(frames_[pp.a].transpose() * pp.anchor_a));
      const btVector3 pb = to_bt(Vec3(frames_[pp.b].transpose() * pp.anchor_b));
      auto joint = std::make_unique<btPoint2PointConstraint>(*bodies_[pp.a], *bodies_[pp.b], pa, pb);
      world_->addConstraint(joint.get(), /*disableCollisionsBetweenLinkedBodies=*/!pp.collide);
      joints_.push_back(std::move(joint));
    }
  }

  ~BulletWorld() override {
    for (auto& joint : joints_) world_->removeConstraint(joint.get());
    for (auto& body : bodies_) world_->removeRigidBody(body.get());
  }

  void step() override { world_->stepSimulation(dt_, 0); }

  void read(std::span<RigidBody> bodies) const override {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (bodies[i].fixed) continue;
      const btRigidBody& b = *bodies_[i];
      bodies[i].position = from_bt(b.getWorldTransform().getOrigin());
      bodies[i].rotation = from_bt(b.getWorldTransform().getBasis()) * frames_[i].transpose();
      bodies[i].velocity = from_bt(b.getLinearVelocity());
      bodies[i].angular_velocity = from_bt(b.getAngularVelocity());
    }
  }

  std::vector<PeerContact> contacts() const override {
    std::vector<PeerContact> out;
    for (int m = 0; m < dispatcher_.getNumManifolds(); ++m) {
      const btPersistentManifold& manifold = *dispatcher_.getManifoldByIndexInternal(m);
      const auto i = static_cast<std::size_t>(manifold.getBody0()->getUserIndex());
      const auto j = static_cast<std::size_t>(manifold.getBody1()->getUserIndex());
      for (int p = 0; p < manifold.getNumContacts(); ++p) {
        const btManifoldPoint& point = manifold.getContactPoint(p);
        out.push_back({i, j, from_bt(0.5 * (point.getPositionWorldOnA() + point.getPositionWorldOnB())),
                       point.getAppliedImpulse()});
      }
    }
    return out;
  }

 private:
  static std::unique_ptr<btCollisionShape> make_shape(const RigidBody& b, bool no_contacts) {
    if (no_contacts) return std::make_unique<btSphereShape>(0.1);  // never touches anything
    return make_bullet_shape(b);
  }

  void add_body(const PeerScene& scene, std::size_t i, double restitution, bool no_contacts) {
    const RigidBody& b = scene.bodies[i];
    std::unique_ptr<btCollisionShape> shape = make_shape(b, no_contacts);
    Mat3 frame = Mat3::Identity();
    btVector3 inertia(0, 0, 0);
    if (!b.fixed) {
      const auto [v, d] = principal_axes(b.inertia_body);
      frame = v;
      inertia = to_bt(d);
      if (!frame.isIdentity(0.0)) {
        // The shape is given in the Impetus body frame: place it in the principal frame.
        auto compound = std::make_unique<btCompoundShape>();
        compound->addChildShape(btTransform(to_bt_matrix(Mat3(frame.transpose())), btVector3(0, 0, 0)), shape.get());
        children_.push_back(std::move(shape));
        shape = std::move(compound);
      }
    }
    btTransform pose;
    pose.setIdentity();
    if (!std::holds_alternative<Plane>(b.shape)) {
      pose.setOrigin(to_bt(b.position));
      pose.setBasis(to_bt_matrix(Mat3(b.rotation * frame)));
    }
    btRigidBody::btRigidBodyConstructionInfo info(b.fixed ? 0.0 : b.mass, nullptr, shape.get(), inertia);
    info.m_startWorldTransform = pose;
    info.m_friction = std::sqrt(b.material.friction);
    info.m_rollingFriction = 0.0;
    info.m_spinningFriction = 0.0;
    info.m_restitution = restitution;
    auto body = std::make_unique<btRigidBody>(info);
    body->setUserIndex(static_cast<int>(i));
    if (!b.fixed) {
      body->setActivationState(DISABLE_DEACTIVATION);
      body->setLinearVelocity(to_bt(b.velocity));
      body->setAngularVelocity(to_bt(b.angular_velocity));
    }
    // Bullet, like Impetus, needs both group/mask tests to agree; masks are ints.
    const int group = no_contacts ? 0 : static_cast<int>(b.collision_group & 0x7fffffffu);
    const int mask = no_contacts ? 0 : static_cast<int>(b.collision_mask & 0x7fffffffu);
    world_->addRigidBody(body.get(), group, mask);
    shapes_.push_back(std::move(shape));
    frames_.push_back(frame);
    bodies_.push_back(std::move(body));
  }

  btDefaultCollisionConfiguration collision_config_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_, children_;
  std::vector<Mat3> frames_;  ///< per body: V, the principal frame in the Impetus body frame
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::unique_ptr<btPoint2PointConstraint>> joints_;
  double dt_;
};

std::string bullet_unsupported(const PeerScene& scene) {
  for (const Constraint& c : scene.constraints)
    if (!std::holds_alternative<PointPointConstraint>(c)) return "only point-point joints are translated";
  if (!contact_free(scene) && !first_mesh(scene).empty())
    return "mesh body '" + first_mesh(scene) + "': a moving concave triangle mesh needs Bullet's GImpact shape, "
           "a different collision model from the Impetus mesh; not translated";
  return "";
}

}  // namespace

std::string bullet_version() {
  const int v = btGetVersion();
  return "Bullet " + std::to_string(v / 100) + "." + std::to_string(v % 100) + " (double precision)";
}

void add_bullet_methods(std::vector<PeerMethod>& out) {
  for (const int iterations : {10, 100}) {
    PeerMethod m;
    m.engine = "bullet";
    m.setting = "si_" + std::to_string(iterations);
    m.integrator = "Bullet (semi-implicit Euler)";
    m.description = "btSequentialImpulseConstraintSolver, " + std::to_string(iterations) +
                    " iterations" + (iterations == 10 ? " (Bullet's default)" : "") +
                    "; friction as shipped (one row per point, along the slip); impacts: contact ERP 0, split "
                    "impulse off; simulations: ERP 0.2 and split impulse as shipped";
    m.unsupported = bullet_unsupported;
    m.make = [iterations](const PeerScene& scene) { return std::make_unique<BulletWorld>(scene, iterations); };
    out.push_back(std::move(m));
  }
}

}  // namespace impetus::peers::accuracy
