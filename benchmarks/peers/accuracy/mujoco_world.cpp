// MuJoCo on the accuracy scenarios: an MJCF model written from the Impetus bodies (one free body per
// movable body, its frame the Impetus body frame, with the Impetus mass and full inertia; fixed bodies as
// world geoms), contacts as shipped (solref 0.02 1, solimp 0.9 0.95 0.001: soft by design), point-point
// constraints as `connect` equality constraints (soft too), Euler
// integrator, solver Newton or PGS with 100 iterations and tolerance 1e-10. Impetus's collision filter
// (groups and masks both ways, joined bodies) is reproduced with <exclude> pairs.
// Friction: a frictionless scene has condim 1 on every geom. With friction, condim 3 (sliding friction
// only: Impetus's point contacts have no torsional or rolling friction), geom friction "μ 0 0" and elliptic
// cones (Coulomb's circular cone, as Impetus; MuJoCo ships pyramidal ones). MuJoCo gives a contact the
// larger of its two geoms' μ, which equals Impetus's √(μ_a μ_b) only when they are equal: a scene whose
// touching bodies have different μ is refused.
#include "peer_world.hpp"

#include "../mujoco_support.hpp"

#include <mujoco/mujoco.h>

#include <sstream>
#include <variant>

namespace impetus::peers::accuracy {
namespace {

/// The one μ of every body that may touch another (mujoco_unsupported refuses a scene with several).
double scene_friction(const PeerScene& scene) {
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    for (std::size_t j = i + 1; j < scene.bodies.size(); ++j)
      if (may_collide(scene, i, j) && pair_friction(scene.bodies, i, j) > 0) return scene.bodies[i].material.friction;
  return 0.0;
}

std::string make_mjcf(const PeerScene& scene, int solver) {
  const bool no_contacts = contact_free(scene);
  const double mu = no_contacts ? 0.0 : scene_friction(scene);
  std::size_t movable = 0;
  for (const RigidBody& b : scene.bodies) movable += b.fixed ? 0 : 1;
  // MuJoCo 2.2 allocates dense njmax-sized arrays: room for 8 contact rows per body and 3 per joint.
  const std::size_t capacity = 64 + 8 * movable + 3 * scene.constraints.size();
  std::ostringstream x;
  x.precision(17);
  x << "<mujoco model=\"accuracy\">\n"
    << "  <size nconmax=\"" << capacity << "\" njmax=\"" << capacity << "\"/>\n"
    << "  <option timestep=\"" << scene.settings.dt << "\" gravity=\"" << mjcf_vec(scene.settings.gravity)
    << "\" integrator=\"Euler\" solver=\"" << (solver == mjSOL_PGS ? "PGS" : "Newton")
    << "\" iterations=\"100\" tolerance=\"1e-10\"" << (mu > 0 ? " cone=\"elliptic\"" : "") << "/>\n"
    << "  <default><geom condim=\"" << (mu > 0 ? 3 : 1) << "\" friction=\"" << mu << " 0 0\" contype=\""
    << (no_contacts ? 0 : 1) << "\" conaffinity=\"" << (no_contacts ? 0 : 1) << "\"/></default>\n  <worldbody>\n";
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const RigidBody& b = scene.bodies[i];
    if (!b.fixed) continue;
    x << "    <geom name=\"g" << i << "\" " << mjcf_geom(b);
    if (!std::holds_alternative<Plane>(b.shape))
      x << " pos=\"" << mjcf_vec(b.position) << "\" quat=\"" << mjcf_quat(b.rotation) << "\"";
    x << "/>\n";
  }
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const RigidBody& b = scene.bodies[i];
    if (b.fixed) continue;
    const Mat3& j = b.inertia_body;
    x << "    <body name=\"b" << i << "\" pos=\"" << mjcf_vec(b.position) << "\" quat=\"" << mjcf_quat(b.rotation)
      << "\"><freejoint/><inertial pos=\"0 0 0\" mass=\"" << b.mass << "\" fullinertia=\"" << j(0, 0) << ' '
      << j(1, 1) << ' ' << j(2, 2) << ' ' << j(0, 1) << ' ' << j(0, 2) << ' ' << j(1, 2) << "\"/>";
    if (!no_contacts) x << "<geom name=\"g" << i << "\" " << mjcf_geom(b) << "/>";
    x << "</body>\n";
  }
  x << "  </worldbody>\n";
  auto body_name = [&](std::size_t i) {
    return scene.bodies[i].fixed ? std::string("world") : "b" + std::to_string(i);
  };
  if (!scene.constraints.empty()) {
    x << "  <equality>\n";
    for (const Constraint& c : scene.constraints) {
      const auto& pp = std::get<PointPointConstraint>(c);
      // connect: anchor in body1's frame; body1 must move (a fixed partner is the world).
      const bool swap = scene.bodies[pp.a].fixed;
      const BodyIndex first = swap ? pp.b : pp.a, second = swap ? pp.a : pp.b;
      x << "    <connect body1=\"" << body_name(first) << "\" body2=\"" << body_name(second) << "\" anchor=\""
        << mjcf_vec(swap ? pp.anchor_b : pp.anchor_a) << "\"/>\n";
    }
    x << "  </equality>\n";
  }
  if (!no_contacts) {
    std::ostringstream excludes;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i)
      for (std::size_t k = i + 1; k < scene.bodies.size(); ++k)
        if (!(scene.bodies[i].fixed && scene.bodies[k].fixed) && !may_collide(scene, i, k))
          excludes << "    <exclude body1=\"" << body_name(i) << "\" body2=\"" << body_name(k) << "\"/>\n";
    if (!excludes.str().empty()) x << "  <contact>\n" << excludes.str() << "  </contact>\n";
  }
  x << "</mujoco>\n";
  return x.str();
}

class MujocoWorld final : public PeerWorld {
 public:
  MujocoWorld(const PeerScene& scene, int solver) : dt_(scene.settings.dt) {
    model_ = load_mjcf(make_mjcf(scene, solver));
    data_ = mj_makeData(model_);
    mj_resetData(model_, data_);
    geom_body_.assign(static_cast<std::size_t>(model_->ngeom), 0);
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const int g = mj_name2id(model_, mjOBJ_GEOM, ("g" + std::to_string(i)).c_str());
      if (g >= 0) geom_body_[static_cast<std::size_t>(g)] = i;
      const RigidBody& b = scene.bodies[i];
      if (b.fixed) continue;
      const int body = mj_name2id(model_, mjOBJ_BODY, ("b" + std::to_string(i)).c_str());
      const int joint = model_->body_jntadr[body];
      const int qvel = model_->jnt_dofadr[joint];
      // Free joint: linear velocity in the world frame, angular velocity in the body frame.
      const Vec3 w_local = b.rotation.transpose() * b.angular_velocity;
      for (int a = 0; a < 3; ++a) {
        data_->qvel[qvel + a] = b.velocity[a];
        data_->qvel[qvel + 3 + a] = w_local[a];
      }
      slots_.push_back({i, model_->jnt_qposadr[joint], qvel});
    }
  }

  ~MujocoWorld() override {
    mj_deleteData(data_);
    mj_deleteModel(model_);
  }

  void step() override { mj_step(model_, data_); }

  void read(std::span<RigidBody> bodies) const override {
    for (const Slot& s : slots_) {
      const mjtNum* q = data_->qpos + s.qpos;
      const mjtNum* v = data_->qvel + s.qvel;
      RigidBody& b = bodies[s.body];
      b.position = Vec3(q[0], q[1], q[2]);
      b.rotation = Quat(q[3], q[4], q[5], q[6]).normalized().toRotationMatrix();
      b.velocity = Vec3(v[0], v[1], v[2]);
      b.angular_velocity = b.rotation * Vec3(v[3], v[4], v[5]);
    }
  }

  std::vector<PeerContact> contacts() const override {
    std::vector<PeerContact> out;
    for (int c = 0; c < data_->ncon; ++c) {
      const mjContact& contact = data_->contact[c];
      // The normal force (N) in the contact frame (condim 1: the one row; condim 3, elliptic: the first
      // of three); its impulse over the step is force·dt.
      mjtNum force[6] = {0, 0, 0, 0, 0, 0};
      if (contact.efc_address >= 0) mj_contactForce(model_, data_, c, force);
      out.push_back({geom_body_[static_cast<std::size_t>(contact.geom1)],
                     geom_body_[static_cast<std::size_t>(contact.geom2)],
                     Vec3(contact.pos[0], contact.pos[1], contact.pos[2]), force[0] * dt_});
    }
    return out;
  }

  double failures() const override {
    return data_->warning[mjWARN_CONTACTFULL].number + data_->warning[mjWARN_CNSTRFULL].number +
           data_->warning[mjWARN_BADQACC].number;
  }

 private:
  struct Slot {
    std::size_t body;  ///< Impetus body
    int qpos, qvel;    ///< its free joint's addresses
  };
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  std::vector<std::size_t> geom_body_;  ///< MuJoCo geom → Impetus body
  std::vector<Slot> slots_;
  double dt_;
};

std::string mujoco_unsupported(const PeerScene& scene) {
  for (const Constraint& c : scene.constraints)
    if (!std::holds_alternative<PointPointConstraint>(c)) return "only point-point joints are translated";
  if (contact_free(scene)) return "";
  if (!first_mesh(scene).empty())
    return "mesh body '" + first_mesh(scene) + "': MuJoCo collides a mesh as its convex hull, not as the triangle "
           "mesh the scene asks for";
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    for (std::size_t j = i + 1; j < scene.bodies.size(); ++j)
      if (may_collide(scene, i, j) && scene.bodies[i].material.friction != scene.bodies[j].material.friction)
        return "bodies '" + scene.bodies[i].name + "' and '" + scene.bodies[j].name +
               "' have different friction: MuJoCo gives a contact the larger μ, Impetus √(μ_a μ_b)";
  if (scene_restitution(scene.bodies) > 0)
    return "restitution: MuJoCo has no coefficient of restitution (a bounce only comes from an under-damped "
           "solref, not a given e)";
  return "";
}

}  // namespace

std::string mujoco_version() { return std::string("MuJoCo ") + mj_versionString() + " (double precision)"; }

void add_mujoco_methods(std::vector<PeerMethod>& out) {
  for (const auto& [name, solver] : {std::pair{"newton", int(mjSOL_NEWTON)}, std::pair{"pgs", int(mjSOL_PGS)}}) {
    PeerMethod m;
    m.engine = "mujoco";
    m.setting = name;
    m.integrator = "MuJoCo Euler (semi-implicit)";
    m.description = std::string("solver ") + (solver == mjSOL_PGS ? "PGS" : "Newton") +
                    ", 100 iterations, tolerance 1e-10; contacts and connect constraints as shipped (soft: "
                    "solref 0.02 1, solimp 0.9 0.95 0.001); condim 1, with friction condim 3 and elliptic cones";
    m.unsupported = mujoco_unsupported;
    const int s = solver;
    m.make = [s](const PeerScene& scene) { return std::make_unique<MujocoWorld>(scene, s); };
    out.push_back(std::move(m));
  }
}

}  // namespace impetus::peers::accuracy
