// Bullet (double-precision build, BT_USE_DOUBLE_PRECISION from pkg-config bullet-float64) on the peers'
// scenes: a btDiscreteDynamicsWorld with the same bodies (make_bullet_shape in bullet_support.hpp; poses,
// masses and the principal inertia Impetus has), stepped once with dt.
//
// Settings for the impulse problem: contact and friction ERP 0 and split impulse off (so the velocities
// are the velocity solve's and nothing else), restitution e on every body (Bullet multiplies the two
// bodies' coefficients), no damping, no deactivation. Friction (the "_mu" scenes): each body's friction
// √μ, so that Bullet's product is the scene's μ; Bullet's friction rows as shipped (one per contact point,
// along its slip) or with SOLVER_USE_2_FRICTION_DIRECTIONS (the `_2dir` rows: two, each clamped to ±μ p_n,
// a box around the cone). The impulse a point applied to body A is p n_B + l1 d1 + l2 d2
// (btManifoldPoint's applied impulses along its normal and its two lateral directions). Every reset
// clears the contact manifolds, so no step is warm-started from the previous one.
#include "bullet_support.hpp"
#include "peers.hpp"

#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/MLCPSolvers/btDantzigSolver.h>
#include <BulletDynamics/MLCPSolvers/btMLCPSolver.h>

#include <chrono>
#include <cmath>

namespace impetus::peers {
namespace {

/// A Bullet solver whose solveGroup calls (setup + iterations + write-back) are timed.
template <class Solver>
class TimedSolver final : public Solver {
 public:
  using Solver::Solver;
  btScalar solveGroup(btCollisionObject** bodies, int num_bodies, btPersistentManifold** manifolds,
                      int num_manifolds, btTypedConstraint** constraints, int num_constraints,
                      const btContactSolverInfo& info, btIDebugDraw* debug, btDispatcher* dispatcher) override {
    const auto start = std::chrono::steady_clock::now();
    const btScalar r = Solver::solveGroup(bodies, num_bodies, manifolds, num_manifolds, constraints,
                                          num_constraints, info, debug, dispatcher);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
  }
  double seconds = 0.0;
};

using SiSolver = TimedSolver<btSequentialImpulseConstraintSolver>;
using MlcpSolver = TimedSolver<btMLCPSolver>;

struct BulletConfig {
  bool mlcp = false;          ///< btMLCPSolver + btDantzigSolver, else sequential impulse
  int iterations = 10;        ///< SI iterations (also the MLCP's fallback)
  double global_cfm = 0.0;    ///< regularization: Bullet adds cfm/dt to the MLCP's diagonal
  double erp = 0.0;           ///< contact ERP (Baumgarte velocity erp·depth/dt), split impulse off
  bool shipped = false;       ///< leave btContactSolverInfo as shipped (erp 0.2, split impulse on) but iterations
  bool two_directions = false;  ///< SOLVER_USE_2_FRICTION_DIRECTIONS (off as shipped)
};

class BulletStep final : public PeerStep {
 public:
  BulletStep(const bench::PreparedScene& scene, const StepSettings& settings, const BulletConfig& config)
      : scene_(scene), settings_(settings), config_(config), pairs_(scene.contacts),
        dispatcher_(&collision_config_) {
    if (config.mlcp) {
      auto solver = std::make_unique<MlcpSolver>(&dantzig_);
      mlcp_ = solver.get();
      solver_ = std::move(solver);
    } else {
      solver_ = std::make_unique<SiSolver>();
    }
    world_ = std::make_unique<btDiscreteDynamicsWorld>(&dispatcher_, &broadphase_, solver_.get(), &collision_config_);
    world_->setGravity(to_bt(settings.gravity));
    btContactSolverInfo& info = world_->getSolverInfo();
    info.m_numIterations = config.iterations;
    if (!config.shipped) {
      // With split impulse off, Bullet uses m_erp for contacts (m_erp2 only with split impulse on).
      info.m_erp = config.erp;
      info.m_erp2 = config.erp;
      info.m_frictionERP = 0.0;
      info.m_splitImpulse = 0;
      info.m_globalCfm = config.global_cfm;
    }
    if (config.two_directions) info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
    add_bodies();
  }

  ~BulletStep() override {
    for (auto& body : bodies_) world_->removeRigidBody(body.get());
  }

  void reset(std::span<const RigidBody> state, Carry carry) override {
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      const RigidBody& b = state[i];
      if (b.fixed) continue;
      btRigidBody& body = *bodies_[i];
      const btTransform pose = transform(b);
      body.setWorldTransform(pose);
      body.setInterpolationWorldTransform(pose);
      body.setLinearVelocity(to_bt(b.velocity));
      body.setAngularVelocity(to_bt(b.angular_velocity));
      body.setInterpolationLinearVelocity(to_bt(b.velocity));
      body.setInterpolationAngularVelocity(to_bt(b.angular_velocity));
      body.clearForces();
    }
    // Carry::drop, no warm start: the contact points (and their cached impulses) of the last step are
    // dropped. Carry::keep: the next step refreshes them at the new poses and warm-starts from them.
    if (carry == Carry::drop)
      for (int m = 0; m < dispatcher_.getNumManifolds(); ++m) dispatcher_.getManifoldByIndexInternal(m)->clearManifold();
    solver_seconds_before_ = solver_seconds();
    fallbacks_before_ = mlcp_ ? mlcp_->getNumFallbacks() : 0;
  }

  void step() override {
    // maxSubSteps = 0: exactly one internal step of length dt.
    world_->stepSimulation(settings_.dt, 0);
  }

  StepResult result() override {
    StepResult r;
    for (const auto& body : bodies_) {
      r.velocity.push_back(from_bt(body->getLinearVelocity()));
      r.angular_velocity.push_back(from_bt(body->getAngularVelocity()));
    }
    ContactTally tally(pairs_, scene_.contacts, true);
    for (int m = 0; m < dispatcher_.getNumManifolds(); ++m) {
      const btPersistentManifold& manifold = *dispatcher_.getManifoldByIndexInternal(m);
      const auto i = static_cast<std::size_t>(manifold.getBody0()->getUserIndex());
      const auto j = static_cast<std::size_t>(manifold.getBody1()->getUserIndex());
      for (int p = 0; p < manifold.getNumContacts(); ++p) {
        const btManifoldPoint& point = manifold.getContactPoint(p);
        // On body 0 (A); the normal points from B to A. The second lateral impulse is 0 unless the second
        // friction direction is on.
        const Vec3 on_a = from_bt(point.m_normalWorldOnB * point.getAppliedImpulse() +
                                  point.m_lateralFrictionDir1 * point.m_appliedImpulseLateral1 +
                                  point.m_lateralFrictionDir2 * point.m_appliedImpulseLateral2);
        tally.add(i, j, point.getAppliedImpulse(), Vec3(-on_a));
      }
    }
    tally.finish(r);
    r.iterations = config_.iterations;
    r.failures = mlcp_ ? mlcp_->getNumFallbacks() - fallbacks_before_ : 0.0;
    r.solver_seconds = solver_seconds() - solver_seconds_before_;
    return r;
  }

 private:
  double solver_seconds() const {
    if (mlcp_) return mlcp_->seconds;
    return static_cast<const SiSolver*>(solver_.get())->seconds;
  }

  static btTransform transform(const RigidBody& b) {
    const Quat q = b.orientation();
    return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), to_bt(b.position));
  }

  void add_bodies() {
    const double restitution = scene_.bodies.front().material.restitution;
    for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
      const RigidBody& b = scene_.bodies[i];
      check_peer_shape(b);
      shapes_.push_back(make_bullet_shape(b));
      std::unique_ptr<btRigidBody> body;
      if (b.fixed) {
        body = std::make_unique<btRigidBody>(
            btRigidBody::btRigidBodyConstructionInfo(0.0, nullptr, shapes_.back().get()));
      } else {
        btRigidBody::btRigidBodyConstructionInfo info(b.mass, nullptr, shapes_.back().get(),
                                                      to_bt(principal_inertia(b)));
        info.m_startWorldTransform = transform(b);
        body = std::make_unique<btRigidBody>(info);
        body->setActivationState(DISABLE_DEACTIVATION);
      }
      body->setFriction(std::sqrt(b.material.friction));
      body->setRollingFriction(0.0);
      body->setSpinningFriction(0.0);
      body->setRestitution(restitution);
      body->setUserIndex(static_cast<int>(i));
      world_->addRigidBody(body.get());
      bodies_.push_back(std::move(body));
    }
    reset(scene_.bodies, Carry::drop);
  }

  const bench::PreparedScene& scene_;
  StepSettings settings_;
  BulletConfig config_;
  PairIndex pairs_;
  btDefaultCollisionConfiguration collision_config_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btDantzigSolver dantzig_;
  std::unique_ptr<btConstraintSolver> solver_;
  MlcpSolver* mlcp_ = nullptr;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;  ///< per body
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  double solver_seconds_before_ = 0.0;
  int fallbacks_before_ = 0;
};

Method bullet_method(std::string name, const BulletConfig& config, std::size_t max_bodies) {
  Method m;
  m.name = std::move(name);
  m.max_bodies = max_bodies;
  m.make = [config](const bench::PreparedScene& scene, const StepSettings& settings) {
    return std::make_unique<BulletStep>(scene, settings, config);
  };
  return m;
}

}  // namespace

std::string bullet_description() {
  const int v = btGetVersion();
  return "Bullet " + std::to_string(v / 100) + "." + std::to_string(v % 100) + " (double precision)";
}

void add_bullet_methods(std::vector<Method>& out) {
  for (int iterations : {10, 50, 200}) {
    BulletConfig c;
    c.iterations = iterations;
    out.push_back(bullet_method("bullet_si_" + std::to_string(iterations), c, std::size_t(1) << 40));
    out.back().friction = true;
  }
  BulletConfig two;
  two.iterations = 50;
  two.two_directions = true;
  out.push_back(bullet_method("bullet_si_50_2dir", two, std::size_t(1) << 40));
  out.back().friction_only = out.back().friction = true;
  // The Dantzig MLCP builds a dense matrix of 2 rows per contact (normal + one friction row): pyramid 50
  // would need ~0.5 GB, so it stops at 1000 bodies.
  BulletConfig mlcp;
  mlcp.mlcp = true;
  out.push_back(bullet_method("bullet_mlcp", mlcp, 1000));
  mlcp.global_cfm = 1e-8;  // regularized
  out.push_back(bullet_method("bullet_mlcp_cfm", mlcp, 1000));
  // CFM does not help a contact touching with exactly zero normal velocity (the Dantzig ratio test meets
  // w = 0 and stops at step s = 0): a tiny ERP makes every right-hand side nonzero, at ~1e-7 m/s cost.
  mlcp.erp = 1e-6;
  mlcp.global_cfm = 1e-10;  // as ODE's default
  out.push_back(bullet_method("bullet_mlcp_perturbed", mlcp, 1000));
  out.back().friction = true;
  BulletConfig mlcp_two = mlcp;
  mlcp_two.two_directions = true;
  out.push_back(bullet_method("bullet_mlcp_perturbed_2dir", mlcp_two, 1000));
  out.back().friction_only = out.back().friction = true;
  mlcp.erp = 0.0;
  mlcp.shipped = true;
  out.push_back(bullet_method("bullet_mlcp_shipped", mlcp, 1000));
}

}  // namespace impetus::peers
