// ODE (double precision: dDOUBLE, checked at start-up with dCheckConfiguration) on the peers' scenes: the
// same bodies (spheres, boxes, capsules along body z, planes; poses, masses and the principal inertia
// Impetus has) in a hash space, contact joints made by dCollide (up to 8 points per pair) in the usual
// near callback, one dWorldStep (Dantzig LCP) or dWorldQuickStep (projected SOR).
//
// Settings: world ERP 0 (no Baumgarte velocity) unless a row says otherwise, contact surface layer 0,
// bounce = e with bounce_vel 0 for e > 0, world CFM as configured (contacts use it: no dContactSoftCFM).
// Friction (the "_mu" scenes): mu = the scene's μ with dContactApprox1, so that each of ODE's two friction
// directions is bounded by μ times the contact's normal force (a pyramid around the cone); without
// dContactApprox1 ODE's mu is a force bound in newtons, not a coefficient. The impulse on body 1 is its
// dJointFeedback force f1 times dt. ODE's LCP errors ("LCP internal error, s <= 0") arrive through
// dMessage: a handler
// counts them as failures.
#include "ode_support.hpp"
#include "peers.hpp"

#include <ode/ode.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <deque>

namespace impetus::peers {
namespace {

struct OdeConfig {
  bool quick = false;       ///< dWorldQuickStep, else dWorldStep
  int iterations = 20;      ///< QuickStep iterations (ODE's default is 20)
  double cfm = 1e-10;       ///< world CFM (ODE's double-precision default is 1e-10)
  double erp = 0.0;         ///< world ERP (ODE's default is 0.2): Baumgarte velocity erp·depth/dt
};

class OdeStep final : public PeerStep {
 public:
  OdeStep(const bench::PreparedScene& scene, const StepSettings& settings, const OdeConfig& config)
      : scene_(scene), settings_(settings), config_(config), pairs_(scene.contacts) {
    init_ode();
    world_ = dWorldCreate();
    space_ = dHashSpaceCreate(nullptr);
    joints_ = dJointGroupCreate(0);
    dWorldSetGravity(world_, settings.gravity.x(), settings.gravity.y(), settings.gravity.z());
    dWorldSetERP(world_, config.erp);
    dWorldSetCFM(world_, config.cfm);
    dWorldSetContactSurfaceLayer(world_, 0.0);
    dWorldSetQuickStepNumIterations(world_, config.iterations);
    add_bodies();
  }

  ~OdeStep() override {
    dJointGroupDestroy(joints_);
    dSpaceDestroy(space_);  // destroys its geoms
    dWorldDestroy(world_);  // destroys its bodies
  }

  /// ODE keeps nothing from step to step (its contact joints are made anew each step): `carry` is moot.
  void reset(std::span<const RigidBody> state, Carry) override {
    dJointGroupEmpty(joints_);
    feedback_.clear();
    contact_pairs_.clear();
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      const RigidBody& b = state[i];
      if (!bodies_[i]) continue;
      dBodySetPosition(bodies_[i], b.position.x(), b.position.y(), b.position.z());
      const Quat q = b.orientation();
      const dQuaternion orientation = {q.w(), q.x(), q.y(), q.z()};
      dBodySetQuaternion(bodies_[i], orientation);
      dBodySetLinearVel(bodies_[i], b.velocity.x(), b.velocity.y(), b.velocity.z());
      dBodySetAngularVel(bodies_[i], b.angular_velocity.x(), b.angular_velocity.y(), b.angular_velocity.z());
      dBodySetForce(bodies_[i], 0, 0, 0);
      dBodySetTorque(bodies_[i], 0, 0, 0);
    }
    ode_messages() = 0;
    solver_seconds_ = 0.0;
    steps_ = 0;
  }

  void step() override {
    dSpaceCollide(space_, this, &OdeStep::near_callback);
    const auto start = std::chrono::steady_clock::now();
    if (config_.quick)
      dWorldQuickStep(world_, settings_.dt);
    else
      dWorldStep(world_, settings_.dt);
    solver_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++steps_;
  }

  StepResult result() override {
    StepResult r;
    for (dBodyID body : bodies_) {
      const dReal* v = body ? dBodyGetLinearVel(body) : nullptr;
      const dReal* w = body ? dBodyGetAngularVel(body) : nullptr;
      r.velocity.push_back(v ? Vec3(v[0], v[1], v[2]) : Vec3::Zero());
      r.angular_velocity.push_back(w ? Vec3(w[0], w[1], w[2]) : Vec3::Zero());
    }
    ContactTally tally(pairs_, scene_.contacts, true);
    for (std::size_t k = 0; k < feedback_.size(); ++k) {
      // Body 1 is never a plane (near_callback orders the geoms) and the normal points into it, so the
      // force ODE applied to body 1 along the normal, times dt, is the contact's impulse.
      const ContactPair& c = contact_pairs_[k];
      const dReal* f = feedback_[k].f1;
      tally.add(c.i, c.j, (f[0] * c.normal.x() + f[1] * c.normal.y() + f[2] * c.normal.z()) * settings_.dt,
                Vec3(-settings_.dt * Vec3(f[0], f[1], f[2])));
    }
    tally.finish(r);
    r.iterations = config_.quick ? config_.iterations : 0;
    r.failures = ode_messages();
    r.solver_seconds = steps_ ? solver_seconds_ / steps_ : kNaN;
    return r;
  }

 private:
  struct ContactPair {
    std::size_t i, j;  ///< Impetus bodies of geom 1 and geom 2
    Vec3 normal;       ///< ODE's contact normal (into geom 1)
  };

  static std::size_t index_of(dGeomID g) { return reinterpret_cast<std::uintptr_t>(dGeomGetData(g)); }

  static void near_callback(void* data, dGeomID g1, dGeomID g2) {
    auto& self = *static_cast<OdeStep*>(data);
    if (!dGeomGetBody(g1)) std::swap(g1, g2);  // a plane (no body) second
    if (!dGeomGetBody(g1)) return;             // two planes
    dContact contacts[8];
    const int n = dCollide(g1, g2, 8, &contacts[0].geom, sizeof(dContact));
    for (int k = 0; k < n; ++k) {
      dContact& c = contacts[k];
      c.surface.mode = (self.restitution_ > 0 ? dContactBounce : 0) | (self.friction_ > 0 ? dContactApprox1 : 0);
      c.surface.mu = self.friction_;
      c.surface.bounce = self.restitution_;
      c.surface.bounce_vel = 0.0;
      const dJointID joint = dJointCreateContact(self.world_, self.joints_, &c);
      dJointAttach(joint, dGeomGetBody(g1), dGeomGetBody(g2));
      dJointSetFeedback(joint, &self.feedback_.emplace_back());
      self.contact_pairs_.push_back(
          {index_of(g1), index_of(g2), Vec3(c.geom.normal[0], c.geom.normal[1], c.geom.normal[2])});
    }
  }

  void add_bodies() {
    restitution_ = scene_.bodies.front().material.restitution;
    friction_ = scene_.bodies.front().material.friction;  // every body's (bench_scenes.hpp)
    for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
      const RigidBody& b = scene_.bodies[i];
      check_peer_shape(b);
      dGeomID geom = make_ode_geom(space_, b);
      dBodyID body = nullptr;
      if (!b.fixed) {
        body = dBodyCreate(world_);
        dMass mass;
        const Vec3 inertia = principal_inertia(b);
        dMassSetParameters(&mass, b.mass, 0, 0, 0, inertia.x(), inertia.y(), inertia.z(), 0, 0, 0);
        dBodySetMass(body, &mass);
        dGeomSetBody(geom, body);
      }
      dGeomSetData(geom, reinterpret_cast<void*>(static_cast<std::uintptr_t>(i)));
      bodies_.push_back(body);
    }
    reset(scene_.bodies, Carry::drop);
  }

  const bench::PreparedScene& scene_;
  StepSettings settings_;
  OdeConfig config_;
  PairIndex pairs_;
  dWorldID world_;
  dSpaceID space_;
  dJointGroupID joints_;
  std::vector<dBodyID> bodies_;             ///< per Impetus body; null for a fixed plane
  std::deque<dJointFeedback> feedback_;     ///< per contact joint (a deque: ODE keeps pointers into it)
  std::vector<ContactPair> contact_pairs_;  ///< per contact joint
  double restitution_ = 0.0, friction_ = 0.0;
  double solver_seconds_ = 0.0;
  long steps_ = 0;
};

Method ode_method(std::string name, const OdeConfig& config, std::size_t max_bodies) {
  Method m;
  m.name = std::move(name);
  m.max_bodies = max_bodies;
  m.make = [config](const bench::PreparedScene& scene, const StepSettings& settings) {
    return std::make_unique<OdeStep>(scene, settings, config);
  };
  return m;
}

}  // namespace

std::string ode_description() {
  init_ode();
  return std::string("ODE " IMPETUS_PEERS_ODE_VERSION " (") +
         (dCheckConfiguration("ODE_double_precision") ? "double precision" : "SINGLE precision") + ")";
}

void add_ode_methods(std::vector<Method>& out) {
  // dWorldStep's Dantzig LCP is dense in the contacts: pyramid 50 (3725 contacts) is left out.
  OdeConfig exact;
  exact.cfm = 0.0;
  out.push_back(ode_method("ode_worldstep_cfm0", exact, 1000));
  exact.cfm = 1e-10;  // as shipped (double precision)
  out.push_back(ode_method("ode_worldstep", exact, 1000));
  out.back().friction = true;
  exact.cfm = 1e-8;  // regularized
  out.push_back(ode_method("ode_worldstep_cfm", exact, 1000));
  // Neither CFM helps a contact that touches with exactly zero normal velocity (the Dantzig ratio test
  // divides w = 0 and stops at s = 0): a tiny ERP makes every right-hand side nonzero, at ~1e-7 m/s cost.
  exact.cfm = 1e-10;
  exact.erp = 1e-6;
  out.push_back(ode_method("ode_worldstep_perturbed", exact, 1000));
  out.back().friction = true;
  exact.erp = 0.2;  // everything as shipped: Baumgarte pushes the overlapping spheres apart
  out.push_back(ode_method("ode_worldstep_shipped", exact, 1000));
  for (int iterations : {10, 20, 50, 200}) {
    OdeConfig quick;
    quick.quick = true;
    quick.iterations = iterations;
    out.push_back(ode_method("ode_quickstep_" + std::to_string(iterations), quick, std::size_t(1) << 40));
    out.back().friction = iterations == 20 || iterations == 200;
  }
}

}  // namespace impetus::peers
