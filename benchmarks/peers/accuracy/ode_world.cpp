// ODE (double precision) on the accuracy scenarios: bodies with the Impetus mass and full body-frame
// inertia (ODE accepts a non-diagonal tensor about the center of mass), geoms in a hash space, contact
// joints from dCollide (up to 8 points per pair) in the usual near callback, ball joints for point-point
// constraints; one dWorldStep (Dantzig LCP) or dWorldQuickStep (projected SOR) per step.
//
// Friction: each contact's mu is Impetus's √(μ_a μ_b) with dContactApprox1, so that ODE bounds each of its
// two friction directions (a pyramid of 4 faces, the first direction ODE's own choice) by mu times the
// contact's normal force, a Coulomb law on a pyramid. Without dContactApprox1, ODE's mu is a fixed force
// bound in newtons, not a coefficient: not a translation of μ. A frictionless pair gets mu = 0.
// Contacts: bounce = the scene's e (bounce_vel 0), surface layer 0, world CFM 1e-10 (ODE's
// double-precision default). ERP: impact scenarios 0 for QuickStep and 1e-6 for dWorldStep (the "perturbed"
// setting of bench_peers: with ERP 0 the Dantzig LCP stops with "s <= 0" on a contact touching with zero
// normal velocity and applies nothing); simulations 0.2 as shipped.
#include "peer_world.hpp"

#include "../ode_support.hpp"

#include <ode/ode.h>

#include <cstdint>
#include <deque>
#include <variant>

namespace impetus::peers::accuracy {
namespace {

struct OdeConfig {
  bool quick = false;   ///< dWorldQuickStep, else dWorldStep
  int iterations = 20;  ///< QuickStep iterations (ODE's default)
};

void to_ode(const Mat3& r, dMatrix3 out) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out[4 * i + j] = r(i, j);
    out[4 * i + 3] = 0.0;
  }
}

class OdeWorld final : public PeerWorld {
 public:
  OdeWorld(const PeerScene& scene, const OdeConfig& config) : scene_(scene), config_(config) {
    init_ode();
    messages_before_ = ode_messages();
    world_ = dWorldCreate();
    space_ = dHashSpaceCreate(nullptr);
    contact_group_ = dJointGroupCreate(0);
    const Vec3& g = scene.settings.gravity;
    dWorldSetGravity(world_, g.x(), g.y(), g.z());
    dWorldSetERP(world_, scene.settings.impulse_problem ? (config.quick ? 0.0 : 1e-6) : 0.2);
    dWorldSetCFM(world_, 1e-10);
    dWorldSetContactSurfaceLayer(world_, 0.0);
    dWorldSetQuickStepNumIterations(world_, config.iterations);
    restitution_ = scene_restitution(scene.bodies);
    const bool no_contacts = contact_free(scene);
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) add_body(scene.bodies[i], i, no_contacts);
    for (const Constraint& c : scene.constraints) {
      const auto& pp = std::get<PointPointConstraint>(c);
      const RigidBody& a = scene.bodies[pp.a];
      const Vec3 anchor = a.position + a.rotation * pp.anchor_a;
      const dJointID joint = dJointCreateBall(world_, nullptr);
      dJointAttach(joint, bodies_[pp.a], bodies_[pp.b]);  // a fixed body is the world (null)
      dJointSetBallAnchor(joint, anchor.x(), anchor.y(), anchor.z());
    }
  }

  ~OdeWorld() override {
    dJointGroupDestroy(contact_group_);
    dSpaceDestroy(space_);  // and its geoms
    dWorldDestroy(world_);  // and its bodies and joints
  }

  void step() override {
    dJointGroupEmpty(contact_group_);
    feedback_.clear();
    points_.clear();
    dSpaceCollide(space_, this, &OdeWorld::near_callback);
    if (config_.quick)
      dWorldQuickStep(world_, scene_.settings.dt);
    else
      dWorldStep(world_, scene_.settings.dt);
  }

  void read(std::span<RigidBody> bodies) const override {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const dBodyID b = bodies_[i];
      if (!b || bodies[i].fixed) continue;
      const dReal* x = dBodyGetPosition(b);
      const dReal* r = dBodyGetRotation(b);
      const dReal* v = dBodyGetLinearVel(b);
      const dReal* w = dBodyGetAngularVel(b);
      bodies[i].position = Vec3(x[0], x[1], x[2]);
      for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) bodies[i].rotation(row, col) = r[4 * row + col];
      bodies[i].velocity = Vec3(v[0], v[1], v[2]);
      bodies[i].angular_velocity = Vec3(w[0], w[1], w[2]);
    }
  }

  std::vector<PeerContact> contacts() const override {
    std::vector<PeerContact> out;
    for (std::size_t k = 0; k < points_.size(); ++k) {
      // Body 1 always has a body (near_callback orders the geoms) and the normal points into it: the
      // force on body 1 along the normal, times dt, is the contact's impulse.
      const Point& p = points_[k];
      const dReal* f = feedback_[k].f1;
      out.push_back({p.i, p.j, p.point, (f[0] * p.normal.x() + f[1] * p.normal.y() + f[2] * p.normal.z()) *
                                            scene_.settings.dt});
    }
    return out;
  }

  double failures() const override { return ode_messages() - messages_before_; }

 private:
  struct Point {
    std::size_t i, j;  ///< Impetus bodies of geom 1 and geom 2
    Vec3 point, normal;
  };

  static std::size_t index_of(dGeomID g) { return reinterpret_cast<std::uintptr_t>(dGeomGetData(g)); }

  static void near_callback(void* data, dGeomID g1, dGeomID g2) {
    auto& self = *static_cast<OdeWorld*>(data);
    if (!dGeomGetBody(g1)) std::swap(g1, g2);
    if (!dGeomGetBody(g1)) return;
    // ODE's category/collide bits accept a pair when either test passes; Impetus needs both.
    if (!may_collide(self.scene_, index_of(g1), index_of(g2))) return;
    dContact contacts[8];
    const int n = dCollide(g1, g2, 8, &contacts[0].geom, sizeof(dContact));
    for (int k = 0; k < n; ++k) {
      dContact& c = contacts[k];
      const double mu = pair_friction(self.scene_.bodies, index_of(g1), index_of(g2));
      c.surface.mode = (self.restitution_ > 0 ? dContactBounce : 0) | (mu > 0 ? dContactApprox1 : 0);
      c.surface.mu = mu;
      c.surface.bounce = self.restitution_;
      c.surface.bounce_vel = 0.0;
      const dJointID joint = dJointCreateContact(self.world_, self.contact_group_, &c);
      dJointAttach(joint, dGeomGetBody(g1), dGeomGetBody(g2));
      dJointSetFeedback(joint, &self.feedback_.emplace_back());
      self.points_.push_back({index_of(g1), index_of(g2), Vec3(c.geom.pos[0], c.geom.pos[1], c.geom.pos[2]),
                              Vec3(c.geom.normal[0], c.geom.normal[1], c.geom.normal[2])});
    }
  }

  void add_body(const RigidBody& b, std::size_t i, bool no_contacts) {
    dBodyID body = nullptr;
    dMatrix3 rotation;
    to_ode(b.rotation, rotation);
    if (!b.fixed) {
      body = dBodyCreate(world_);
      dMass mass;
      const Mat3& j = b.inertia_body;
      dMassSetParameters(&mass, b.mass, 0, 0, 0, j(0, 0), j(1, 1), j(2, 2), j(0, 1), j(0, 2), j(1, 2));
      dBodySetMass(body, &mass);
      dBodySetPosition(body, b.position.x(), b.position.y(), b.position.z());
      dBodySetRotation(body, rotation);
      dBodySetLinearVel(body, b.velocity.x(), b.velocity.y(), b.velocity.z());
      dBodySetAngularVel(body, b.angular_velocity.x(), b.angular_velocity.y(), b.angular_velocity.z());
      dBodySetAutoDisableFlag(body, 0);
    }
    bodies_.push_back(body);
    if (no_contacts) return;
    const dGeomID geom = make_ode_geom(space_, b);
    dGeomSetData(geom, reinterpret_cast<void*>(static_cast<std::uintptr_t>(i)));
    if (body) {
      dGeomSetBody(geom, body);
    } else if (!std::holds_alternative<Plane>(b.shape)) {
      dGeomSetPosition(geom, b.position.x(), b.position.y(), b.position.z());
      dGeomSetRotation(geom, rotation);
    }
  }

  const PeerScene& scene_;
  OdeConfig config_;
  dWorldID world_;
  dSpaceID space_;
  dJointGroupID contact_group_;
  std::vector<dBodyID> bodies_;  ///< per Impetus body; null for fixed ones
  std::deque<dJointFeedback> feedback_;  ///< per contact joint (a deque: ODE keeps pointers into it)
  std::vector<Point> points_;            ///< per contact joint
  double restitution_ = 0.0;
  int messages_before_ = 0;
};

std::string ode_unsupported(const PeerScene& scene) {
  for (const Constraint& c : scene.constraints)
    if (!std::holds_alternative<PointPointConstraint>(c)) return "only point-point joints are translated";
  if (!contact_free(scene) && !first_mesh(scene).empty())
    return "mesh body '" + first_mesh(scene) + "': ODE's trimesh collider (OPCODE) is not the Impetus mesh "
           "model and its trimesh-plane contacts are not translated";
  return "";
}

}  // namespace

std::string ode_version() {
  init_ode();
  return std::string("ODE " IMPETUS_PEERS_ODE_VERSION " (") +
         (dCheckConfiguration("ODE_double_precision") ? "double precision" : "SINGLE precision") + ")";
}

void add_ode_methods(std::vector<PeerMethod>& out) {
  PeerMethod quick;
  quick.engine = "ode";
  quick.setting = "quickstep_20";
  quick.integrator = "ODE (semi-implicit Euler)";
  quick.description = "dWorldQuickStep, 20 iterations (ODE's default), CFM 1e-10; ERP 0 on impacts, 0.2 (shipped) "
                      "in simulations; friction: mu = √(μ_a μ_b) with dContactApprox1 (a pyramid scaled by the "
                      "normal force)";
  quick.unsupported = ode_unsupported;
  quick.make = [](const PeerScene& scene) { return std::make_unique<OdeWorld>(scene, OdeConfig{true, 20}); };
  out.push_back(quick);
  PeerMethod exact = quick;
  exact.setting = "worldstep";
  exact.description = "dWorldStep (Dantzig LCP), CFM 1e-10; ERP 1e-6 on impacts (the light regularization without "
                      "which the LCP gives up silently on zero-velocity contacts), 0.2 (shipped) in simulations; "
                      "friction: mu = √(μ_a μ_b) with dContactApprox1 (a pyramid scaled by the normal force)";
  exact.make = [](const PeerScene& scene) { return std::make_unique<OdeWorld>(scene, OdeConfig{false, 20}); };
  out.push_back(exact);
}

}  // namespace impetus::peers::accuracy
