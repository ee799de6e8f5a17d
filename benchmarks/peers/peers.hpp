#pragma once
/// \file
/// What every peer engine (Bullet, ODE, MuJoCo) and the Impetus rows of `bench_peers` share: one
/// configured method on one prepared scene, stepped once from the scene's initial state, and what the step
/// left behind mapped back onto the Impetus bodies and contacts so that bench::measure_quality judges
/// every engine by the same counters (README.md).

#include "support/bench_scenes.hpp"

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <variant>
#include <vector>

namespace impetus::peers {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The step everyone takes: dt = 1 ms; gravity off for the impulse problem (the paper's: one solve on the
/// initial velocities), on for the "full step" rows.
struct StepSettings {
  double dt = 1e-3;                  ///< s
  Vec3 gravity = Vec3::Zero();       ///< m/s²
};

/// One engine step mapped back onto the Impetus scene. Body and contact indices are the Impetus ones
/// (PreparedScene::bodies, PreparedScene::contacts).
struct StepResult {
  std::vector<Vec3> velocity;           ///< post-step linear velocity per body (m/s)
  std::vector<Vec3> angular_velocity;   ///< post-step angular velocity per body, world frame (rad/s)
  /// Normal impulse the engine applied at each Impetus contact (N·s), summed over the engine's contact
  /// points on the same pair of bodies; empty when the engine exposes none (complementarity is NaN then).
  std::vector<double> impulses;
  /// The whole impulse (normal and friction, N·s, world frame) the engine applied to body b of each Impetus
  /// contact (−it to a; modules/contact.hpp's convention), summed like `impulses`; empty when the engine
  /// exposes no friction impulse (the natural-map error is NaN then).
  std::vector<Vec3> impulse_vectors;
  std::size_t engine_contacts = 0;      ///< contact points the engine generated and solved
  std::size_t matched = 0;              ///< Impetus contacts with at least one engine point on their pair
  std::size_t extra = 0;                ///< engine points on a pair the Impetus detector has no contact for
  double iterations = 0;                ///< solver iterations (setting, or what the engine reports; 0 = direct)
  double failures = 0;                  ///< the exact solver gave up (Bullet MLCP fallback, ODE LCP error messages)
  double solver_seconds = kNaN;         ///< the engine's solver alone in the last step, if it can be timed separately
};

/// What an engine keeps across reset(): `drop` forgets everything it learnt in earlier steps (contact
/// caches, warm-start impulses, Impetus's symbolic analyses), as a new world would; `keep` keeps it, as a
/// running simulation does from one step to the next.
enum class Carry { drop, keep };

/// One method of one engine, configured on one scene. The benchmark calls reset() untimed, step() timed,
/// and result() once at the end; on a dynamic scene, each timed step follows an untimed one from the
/// state a step earlier (main.cpp, run()).
class PeerStep {
 public:
  virtual ~PeerStep() = default;
  /// Puts the bodies in `state` (positions and velocities, the Impetus bodies' order: the scene's own
  /// bodies or a state of them a step earlier), keeping or dropping what the engine learnt (Carry).
  virtual void reset(std::span<const RigidBody> state, Carry carry) = 0;
  /// One engine step (contact generation + solve + integration), or the resolver alone for Impetus.
  virtual void step() = 0;
  /// The state after the last step().
  virtual StepResult result() = 0;
};

/// A benchmark row family: "bullet_si_10", "ode_worldstep_cfm0", …
struct Method {
  std::string name;
  /// false: skip the e = 1 line rows (the engine has no Newton restitution to compare).
  bool restitution = true;
  /// true: also run on the frictional scenes (main.cpp: the engine's friction with the scene's μ);
  /// friction_only: only there (a setting that differs from another method only in its friction).
  bool friction = false, friction_only = false;
  /// Largest scene (movable bodies) this method is run on; dense direct solvers grow as n³.
  std::size_t max_bodies = std::size_t(1) << 40;
  /// true: a whole Impetus step (detection, resolve, integration), run only on the rows under gravity.
  bool gravity_only = false;
  std::function<std::unique_ptr<PeerStep>(const bench::PreparedScene&, const StepSettings&)> make;
};

/// The methods each engine offers (defined in bullet.cpp, ode.cpp, mujoco.cpp, impetus_rows.cpp).
void add_bullet_methods(std::vector<Method>& out);
void add_ode_methods(std::vector<Method>& out);
void add_mujoco_methods(std::vector<Method>& out);
void add_impetus_methods(std::vector<Method>& out);
/// Engine name and version for the start-up banner.
std::string bullet_description();
std::string ode_description();
std::string mujoco_description();

/// Finds the Impetus contact on an unordered pair of Impetus bodies: the first of the pair's contacts
/// (a box or a capsule may touch another body at several points; report() in main.cpp judges such a
/// pair by the sum of the impulses on it).
class PairIndex {
 public:
  explicit PairIndex(const std::vector<Contact>& contacts) {
    for (std::size_t k = 0; k < contacts.size(); ++k) index_.emplace(key(contacts[k].a, contacts[k].b), k);
  }
  /// The contact index, or -1 when the pair has none.
  long find(std::size_t i, std::size_t j) const {
    const auto it = index_.find(key(i, j));
    return it == index_.end() ? -1 : static_cast<long>(it->second);
  }

 private:
  static std::uint64_t key(std::size_t i, std::size_t j) {
    if (i > j) std::swap(i, j);
    return (static_cast<std::uint64_t>(i) << 32) | static_cast<std::uint64_t>(j);
  }
  std::unordered_map<std::uint64_t, std::size_t> index_;
};

/// Collects an engine's contact points into a StepResult: each point on Impetus bodies (i, j) with the
/// normal impulse `impulse` (N·s; NaN when unknown), and if the engine reports it the whole impulse on j
/// (world frame), is added to the matching Impetus contact.
class ContactTally {
 public:
  ContactTally(const PairIndex& pairs, const std::vector<Contact>& contacts, bool impulses_known)
      : pairs_(pairs), contacts_(contacts), impulses_(contacts.size(), 0.0),
        vectors_(contacts.size(), Vec3::Zero()), hit_(contacts.size(), false), known_(impulses_known) {}

  void add(std::size_t i, std::size_t j, double impulse) {
    vectors_known_ = false;
    add_point(i, j, impulse);
  }
  /// With the whole impulse `on_j` the engine applied to body j at this point.
  void add(std::size_t i, std::size_t j, double impulse, const Vec3& on_j) {
    const long k = add_point(i, j, impulse);
    if (k < 0) return;
    const auto index = static_cast<std::size_t>(k);
    vectors_[index] += contacts_[index].b == j ? on_j : Vec3(-on_j);
  }

  /// Writes the counts and impulses into `out`.
  void finish(StepResult& out) {
    out.engine_contacts = points_;
    out.extra = extra_;
    out.matched = 0;  // every contact of a pair the engine touched (PairIndex marks the pair's first)
    for (const Contact& c : contacts_) out.matched += hit_[static_cast<std::size_t>(pairs_.find(c.a, c.b))] ? 1 : 0;
    if (known_) out.impulses = std::move(impulses_);
    if (known_ && vectors_known_) out.impulse_vectors = std::move(vectors_);
  }

 private:
  long add_point(std::size_t i, std::size_t j, double impulse) {
    ++points_;
    const long k = pairs_.find(i, j);
    if (k < 0) {
      ++extra_;
      return k;
    }
    hit_[static_cast<std::size_t>(k)] = true;
    impulses_[static_cast<std::size_t>(k)] += impulse;
    return k;
  }

  const PairIndex& pairs_;
  const std::vector<Contact>& contacts_;
  std::vector<double> impulses_;
  std::vector<Vec3> vectors_;
  std::vector<bool> hit_;
  bool known_, vectors_known_ = true;
  std::size_t points_ = 0, extra_ = 0;
};

/// The shapes the engines are given: a fixed body must be a plane, a movable one a sphere, a box, a capsule
/// or a cylinder (primitives every engine has with the same geometry: a capsule is a segment along body z
/// swept by a sphere). Throws std::invalid_argument naming the body otherwise.
inline void check_peer_shape(const RigidBody& b) {
  const bool ok = b.fixed ? std::holds_alternative<Plane>(b.shape)
                          : !std::holds_alternative<Plane>(b.shape) && !std::holds_alternative<MeshShape>(b.shape);
  if (!ok)
    throw std::invalid_argument("body '" + b.name +
                                "': the peers take fixed planes and movable spheres, boxes, capsules and cylinders");
}

/// The principal moments of inertia of a movable body (kg·m²): the body frame of every primitive is
/// principal, so each engine gets Impetus's own inertia rather than recomputing it.
inline Vec3 principal_inertia(const RigidBody& b) { return b.inertia_body.diagonal(); }

}  // namespace impetus::peers
