// MuJoCo on the peers' scenes: a model built from an MJCF string (loaded through a virtual file system):
// one free body per movable body (a sphere, box, capsule or cylinder geom; the body's pose, and an
// explicit inertial with Impetus's mass and principal inertia), each fixed plane a world geom, every
// geom condim = 1 (frictionless; with friction, the "_mu" scenes: condim 3, friction
// "μ 0 0" — sliding only — and elliptic cones, or pyramidal ones in the `_pyramidal` rows), Euler
// integrator, dt, gravity as set; solver PGS, CG or
// Newton with iterations 100 and tolerance 1e-10. One mj_step from mj_resetData (no warm start), or on
// a dynamic scene from the state a step after an untimed one (qacc_warmstart kept).
//
// MuJoCo's contacts are soft (DESIGN of MuJoCo, "solver parameters"): the solve gives J a = d·a_ref with
// impedance d < 1 and a_ref = −b v − k r, not the hard v_n⁺ = 0. Two settings:
//   default   solref/solimp as shipped (0.02 1 / 0.9 0.95 0.001 0.5 2): a contact absorbs only part of the
//             approach velocity per step (the spring-damper reference), by design.
//   stiff     the hardest MuJoCo allows: solimp 0.9999 (its clamp mjMAXIMP) everywhere, and solref in the
//             direct form "0 −1/dt" (stiffness 0: no position term; damping 1/dt: a_ref·dt = −v, so a hard
//             contact would stop exactly in one step).
#include "mujoco_support.hpp"
#include "peers.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace impetus::peers {
namespace {

/// mjcb_time for d->timer: seconds on the steady clock.
mjtNum steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct MujocoConfig {
  int solver = mjSOL_NEWTON;
  bool stiff = false;
  int iterations = 100;
  double tolerance = 1e-10;
  bool pyramidal = false;  ///< pyramidal friction cones (MuJoCo's default), else elliptic
};

/// The scene as MJCF: movable bodies in Impetus order (MuJoCo body k + 1 is the k-th movable one), the
/// fixed planes as world geoms.
std::string make_mjcf(const bench::PreparedScene& scene, const StepSettings& settings, const MujocoConfig& config) {
  std::ostringstream x;
  x.precision(17);
  // MuJoCo 2.2 allocates dense njmax × nv and njmax × njmax arrays: size them for the contacts the Impetus
  // detector found (+10 %), not generously, or pyramid 50 cannot allocate its mjData. Spheres touch at one
  // point; boxes and capsules at up to 4 (8 for two boxes), where Impetus may keep fewer: twice its count.
  // A frictional contact has 3 rows (elliptic cone) or 4 (pyramidal: 2 per tangent direction).
  const std::size_t rows = scene.bodies.front().material.friction > 0 ? 4 : 1;
  const bool spheres = std::all_of(scene.bodies.begin(), scene.bodies.end(), [](const RigidBody& b) {
    return b.fixed || std::holds_alternative<Sphere>(b.shape);
  });
  const std::size_t points = spheres ? scene.contacts.size() + scene.contacts.size() / 10 : 2 * scene.contacts.size();
  const std::size_t capacity = rows * points + 20;
  x << "<mujoco model=\"peers\">\n"
    << "  <size nconmax=\"" << capacity << "\" njmax=\"" << capacity << "\"/>\n"
    << "  <option timestep=\"" << settings.dt << "\" gravity=\"" << mjcf_vec(settings.gravity)
    << "\" integrator=\"Euler\" cone=\"" << (config.pyramidal ? "pyramidal" : "elliptic") << "\"/>\n";
  const double mu = scene.bodies.front().material.friction;  // every body's (bench_scenes.hpp)
  if (mu > 0)
    x << "  <default><geom condim=\"3\" friction=\"" << mu << " 0 0\"";
  else
    x << "  <default><geom condim=\"1\"";
  if (config.stiff) x << " solref=\"0 " << -1.0 / settings.dt << "\" solimp=\"0.9999 0.9999 0.001 0.5 2\"";
  x << "/></default>\n  <worldbody>\n";
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {  // the fixed planes, as world geoms
    const RigidBody& b = scene.bodies[i];
    check_peer_shape(b);
    if (b.fixed) x << "    <geom name=\"g" << i << "\" " << mjcf_geom(b) << "/>\n";
  }
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const RigidBody& b = scene.bodies[i];
    if (b.fixed) continue;
    x << "    <body pos=\"" << mjcf_vec(b.position) << "\" quat=\"" << mjcf_quat(b.rotation)
      << "\"><freejoint/><inertial pos=\"0 0 0\" mass=\"" << b.mass << "\" diaginertia=\""
      << mjcf_vec(principal_inertia(b)) << "\"/><geom name=\"g" << i << "\" " << mjcf_geom(b) << "/></body>\n";
  }
  x << "  </worldbody>\n</mujoco>\n";
  return x.str();
}

class MujocoStep final : public PeerStep {
 public:
  MujocoStep(const bench::PreparedScene& scene, const StepSettings& settings, const MujocoConfig& config)
      : scene_(scene), settings_(settings), pairs_(scene.contacts) {
    mjcb_time = &steady_seconds;
    model_ = load_mjcf(make_mjcf(scene, settings, config));
    for (int g = 0; g < model_->ngeom; ++g)  // "g<i>": Impetus body i
      geom_body_.push_back(static_cast<std::size_t>(std::stoul(model_->names + model_->name_geomadr[g] + 1)));
    model_->opt.solver = config.solver;
    model_->opt.iterations = config.iterations;
    model_->opt.tolerance = config.tolerance;
    data_ = mj_makeData(model_);
    reset(scene_.bodies, Carry::drop);
  }

  ~MujocoStep() override {
    mj_deleteData(data_);
    mj_deleteModel(model_);
  }

  void reset(std::span<const RigidBody> state, Carry carry) override {
    if (carry == Carry::drop) mj_resetData(model_, data_);  // the warm start (qacc_warmstart) cleared
    std::size_t k = 0;
    for (const RigidBody& b : state) {
      if (b.fixed) continue;
      // Free joint: position and orientation (w, x, y, z); linear velocity in the world frame, angular
      // velocity in the body frame.
      const Quat q = b.orientation();
      const mjtNum pose[7] = {b.position.x(), b.position.y(), b.position.z(), q.w(), q.x(), q.y(), q.z()};
      std::copy(pose, pose + 7, data_->qpos + 7 * k);
      const Vec3 local = b.rotation.transpose() * b.angular_velocity;
      for (int a = 0; a < 3; ++a) {
        data_->qvel[6 * k + a] = b.velocity[a];
        data_->qvel[6 * k + 3 + a] = local[a];
      }
      ++k;
    }
    solver_seconds_ = 0.0;
    steps_ = 0;
  }

  void step() override {
    const double before = data_->timer[mjTIMER_CONSTRAINT].duration;
    mj_step(model_, data_);
    solver_seconds_ += data_->timer[mjTIMER_CONSTRAINT].duration - before;
    ++steps_;
  }

  StepResult result() override {
    StepResult r;
    std::size_t k = 0;
    for (const RigidBody& b : scene_.bodies) {
      if (b.fixed) {
        r.velocity.push_back(Vec3::Zero());
        r.angular_velocity.push_back(Vec3::Zero());
        continue;
      }
      const mjtNum* v = data_->qvel + 6 * k;
      // The body frame after the step: the rotation about ω over the step leaves ω's direction as it was,
      // so the new pose maps the body-frame ω to the world frame as the old one would.
      const mjtNum* q = data_->qpos + 7 * k + 3;
      ++k;
      r.velocity.push_back(Vec3(v[0], v[1], v[2]));
      r.angular_velocity.push_back(Quat(q[0], q[1], q[2], q[3]).normalized() * Vec3(v[3], v[4], v[5]));
    }
    ContactTally tally(pairs_, scene_.contacts, true);
    for (int c = 0; c < data_->ncon; ++c) {
      const mjContact& contact = data_->contact[c];
      // The contact force in its frame (normal, then the two tangents; mj_contactForce also converts a
      // pyramidal cone's edge forces), exerted by geom 1 on geom 2 along the normal from 1 to 2; times dt,
      // the impulse over the step.
      mjtNum f[6];
      mj_contactForce(model_, data_, c, f);
      const Vec3 on_2 = f[0] * Vec3(contact.frame[0], contact.frame[1], contact.frame[2]) +
                        f[1] * Vec3(contact.frame[3], contact.frame[4], contact.frame[5]) +
                        f[2] * Vec3(contact.frame[6], contact.frame[7], contact.frame[8]);
      const std::size_t body_1 = geom_body_[static_cast<std::size_t>(contact.geom1)];
      const std::size_t body_2 = geom_body_[static_cast<std::size_t>(contact.geom2)];
      tally.add(body_1, body_2, f[0] * settings_.dt, Vec3(settings_.dt * on_2));
    }
    tally.finish(r);
    r.iterations = data_->solver_iter;
    r.failures = data_->warning[mjWARN_CONTACTFULL].number + data_->warning[mjWARN_CNSTRFULL].number;
    r.solver_seconds = steps_ ? solver_seconds_ / steps_ : kNaN;
    return r;
  }

 private:
  const bench::PreparedScene& scene_;
  StepSettings settings_;
  PairIndex pairs_;
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  std::vector<std::size_t> geom_body_;  ///< per MuJoCo geom, its Impetus body
  double solver_seconds_ = 0.0;
  long steps_ = 0;
};

Method mujoco_method(std::string name, const MujocoConfig& config, std::size_t max_bodies) {
  Method m;
  m.name = std::move(name);
  m.restitution = false;  // no Newton restitution coefficient: bounce only through the soft reference
  m.max_bodies = max_bodies;
  m.make = [config](const bench::PreparedScene& scene, const StepSettings& settings) {
    return std::make_unique<MujocoStep>(scene, settings, config);
  };
  return m;
}

}  // namespace

std::string mujoco_description() { return std::string("MuJoCo ") + mj_versionString() + " (double precision)"; }

void add_mujoco_methods(std::vector<Method>& out) {
  const std::pair<const char*, int> solvers[] = {{"pgs", mjSOL_PGS}, {"cg", mjSOL_CG}, {"newton", mjSOL_NEWTON}};
  for (const auto& [name, solver] : solvers) {
    for (const bool stiff : {false, true}) {
      MujocoConfig c;
      c.solver = solver;
      c.stiff = stiff;
      // Newton factors a dense nv × nv Hessian: pyramid 50 (nv = 7650) takes ~1 s (default) to ~24 s (stiff).
      const std::size_t max_bodies = solver == mjSOL_NEWTON ? 1000 : std::size_t(1) << 40;
      out.push_back(mujoco_method(std::string("mujoco_") + name + (stiff ? "_stiff" : ""), c, max_bodies));
      out.back().friction = solver != mjSOL_CG;
    }
  }
  // Newton with MuJoCo's default pyramidal cones, on the frictional scenes only (elsewhere the cone is moot).
  for (const bool stiff : {false, true}) {
    MujocoConfig c;
    c.stiff = stiff;
    c.pyramidal = true;
    out.push_back(mujoco_method(std::string("mujoco_newton") + (stiff ? "_stiff" : "") + "_pyramidal", c, 1000));
    out.back().friction = out.back().friction_only = true;
  }
}

}  // namespace impetus::peers
