#pragma once
/// \file
/// The accuracy scenarios (benchmarks/accuracy/) in Bullet, ODE and MuJoCo: a peer engine's world built
/// from an Impetus world (the scene file loaded and built exactly as the accuracy suite builds it, so the
/// initial state is identical), stepped by the engine, and its bodies' state written back onto the
/// Impetus bodies so that the suite's own probes judge it (README.md in the parent folder).

#include "impetus/engine/world.hpp"

#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace impetus::peers::accuracy {

/// How a peer steps a scenario.
struct PeerSettings {
  double dt = 1e-3;             ///< s
  Vec3 gravity = Vec3::Zero();  ///< m/s²
  /// true for the impact scenarios (one step, the paper's impulse problem): no Baumgarte/ERP velocity
  /// and no split impulse, so that the velocities after the step are the velocity solve's. false for the
  /// simulations: the engine's own position correction as shipped.
  bool impulse_problem = false;
};

/// One contact point the engine solved, mapped to Impetus bodies.
struct PeerContact {
  std::size_t a = 0, b = 0;  ///< Impetus body indices
  Vec3 point = Vec3::Zero(); ///< world point (m)
  double impulse = 0.0;      ///< normal impulse over the step (N·s)
};

/// A peer engine's world, built from the Impetus bodies and constraints (same indices).
class PeerWorld {
 public:
  virtual ~PeerWorld() = default;
  /// One engine step of PeerSettings::dt (contact generation + solve + integration).
  virtual void step() = 0;
  /// Writes the engine's state of every movable body onto `bodies` (the Impetus bodies it was built
  /// from): position of the center of mass, rotation body → world, velocity, angular velocity (world).
  virtual void read(std::span<RigidBody> bodies) const = 0;
  /// The contact points of the last step with the engine's impulses.
  virtual std::vector<PeerContact> contacts() const = 0;
  /// Times the engine reported that its solver gave up since it was built (ODE: dMessage calls such as
  /// "LCP internal error"; MuJoCo: contact or constraint buffer full; Bullet: none reported).
  virtual double failures() const { return 0.0; }
};

/// What a peer method is given: the Impetus world after build_world (bodies in the initial state, fixed
/// bodies included, constraints) and the step settings.
struct PeerScene {
  std::span<const RigidBody> bodies;
  std::span<const Constraint> constraints;
  PeerSettings settings;
};

/// One engine with one setting, as a row of the accuracy suite.
struct PeerMethod {
  std::string engine;       ///< "bullet", "ode", "mujoco"
  std::string setting;      ///< "si_10", "quickstep_20", "newton", …
  std::string integrator;   ///< the engine's own integrator, for the atlas ("semi-implicit Euler", …)
  std::string description;  ///< the settings in one line
  /// Why the engine cannot run this scene faithfully (empty: it can).
  std::function<std::string(const PeerScene&)> unsupported;
  std::function<std::unique_ptr<PeerWorld>(const PeerScene&)> make;

  /// "bullet/si_10".
  std::string label() const { return engine + "/" + setting; }
};

/// The methods each engine offers (bullet_world.cpp, ode_world.cpp, mujoco_world.cpp).
void add_bullet_methods(std::vector<PeerMethod>& out);
void add_ode_methods(std::vector<PeerMethod>& out);
void add_mujoco_methods(std::vector<PeerMethod>& out);
/// "Bullet 3.24 (double precision)" and the like, for the output's header.
std::string bullet_version();
std::string ode_version();
std::string mujoco_version();

/// Shared translation helpers.
/// Principal axes of a body-frame inertia: J = V diag(d) Vᵀ with V a rotation (det +1), d ascending.
std::pair<Mat3, Vec3> principal_axes(const Mat3& inertia_body);
/// The combined restitution of two bodies as Impetus uses it (the larger of the two).
double scene_restitution(std::span<const RigidBody> bodies);
/// True when the scene has no pair of bodies that could ever touch (a single body): shapes are irrelevant.
bool contact_free(const PeerScene& scene);
/// Whether the Impetus detector lets bodies i and j touch (groups/masks both ways, joined bodies).
bool may_collide(const PeerScene& scene, std::size_t i, std::size_t j);
/// μ of a contact between bodies i and j as Impetus combines it: √(μ_i μ_j) (docs/conventions.md,
/// "Friction"); 0 when either body is frictionless.
double pair_friction(std::span<const RigidBody> bodies, std::size_t i, std::size_t j);
/// True when some pair of bodies that may touch has μ > 0.
bool has_friction(const PeerScene& scene);
/// The first shape in the scene this engine cannot represent as a collision shape ("mesh"), or "".
std::string first_mesh(const PeerScene& scene);

}  // namespace impetus::peers::accuracy
