#pragma once
/// \file
/// The benchmark scenes of docs/conventions.md ("Benchmark scenes") prepared once for every family and for
/// the peers: bodies in their initial state and the contacts the `fcl` detector finds there. Resolver
/// benchmarks restore `bodies` before every iteration and hand the same contact list to each resolver,
/// so every method (and every peer engine) starts from the identical state.

#include "impetus/detection/fcl/fcl_detector.hpp"
#include "impetus/engine/generators.hpp"
#include "impetus/resolution/common/impulse_rows.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace impetus::bench {

/// A scene's initial state and its contacts.
struct PreparedScene {
  std::string name;                ///< "pyramid_20", "line_100_e1", …
  std::vector<RigidBody> bodies;   ///< initial state (fixed ground or wall last)
  std::vector<Contact> contacts;   ///< detected once at the initial state
  std::size_t movable = 0;         ///< movable bodies
};

/// Detects the contacts of `bodies` at their current poses with a default `fcl` detector.
inline std::vector<Contact> detect_once(std::span<const RigidBody> bodies) {
  FclDetector detector;
  if (const ModuleStatus s = detector.set_bodies(bodies, {}); !s) throw std::runtime_error(s.message);
  std::vector<Contact> contacts;
  DetectorCounters counters;
  detector.detect(bodies, StepContext{}, contacts, counters);
  return contacts;
}

inline PreparedScene prepare(std::string name, std::vector<RigidBody> bodies) {
  PreparedScene scene;
  scene.name = std::move(name);
  scene.bodies = std::move(bodies);
  scene.contacts = detect_once(scene.bodies);
  scene.movable = static_cast<std::size_t>(
      std::count_if(scene.bodies.begin(), scene.bodies.end(), [](const RigidBody& b) { return !b.fixed; }));
  return scene;
}

/// The paper's pyramid drop: K rows (K(K+1)/2 spheres), every sphere moving at (0, 0, −1) m/s, e = 0.
inline PreparedScene pyramid_drop(int rows, double restitution = 0.0) {
  PyramidParams p;
  p.rows = rows;
  p.restitution = restitution;
  return prepare("pyramid_" + std::to_string(rows), make_pyramid(p));
}

/// The paper's line push: N spheres and a wall, the first moving at (1, 0, 0) m/s.
inline PreparedScene line_push(int count, double restitution) {
  LineParams p;
  p.count = count;
  p.restitution = restitution;
  return prepare("line_" + std::to_string(count) + (restitution > 0 ? "_e1" : "_e0"), make_line(p));
}

/// The friction coefficient a scene key ends with ("pyramid_20_mu0.5" → 0.5), or 0.
inline double key_friction(const std::string& key) {
  const auto at = key.rfind("_mu");
  return at == std::string::npos ? 0.0 : std::stod(key.substr(at + 3));
}

/// The scene named "pyramid_K", "line_N_e0" or "line_N_e1", with "_muX" after it every body's friction X
/// (so every contact's μ is X), prepared once per process.
inline const PreparedScene& prepared_scene(const std::string& key) {
  static std::map<std::string, PreparedScene> cache;
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  const auto underscore = key.find('_');
  const std::string family = key.substr(0, underscore);
  const int n = std::stoi(key.substr(underscore + 1));
  const std::string base = key.substr(0, key.rfind("_mu") == std::string::npos ? key.size() : key.rfind("_mu"));
  PreparedScene s = family == "pyramid" ? pyramid_drop(n) : line_push(n, base.ends_with("_e1") ? 1.0 : 0.0);
  s.name = key;
  for (RigidBody& b : s.bodies) b.material.friction = key_friction(key);
  return cache.emplace(key, std::move(s)).first->second;
}

/// Copies the state (pose and velocities) back from `initial`, body by body.
inline void restore_state(std::span<RigidBody> bodies, std::span<const RigidBody> initial) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    bodies[i].position = initial[i].position;
    bodies[i].rotation = initial[i].rotation;
    bodies[i].velocity = initial[i].velocity;
    bodies[i].angular_velocity = initial[i].angular_velocity;
  }
}

/// Copies velocities (and nothing else) back from the initial state: what a resolver changes.
inline void restore_velocities(std::span<RigidBody> bodies, std::span<const RigidBody> initial) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    bodies[i].velocity = initial[i].velocity;
    bodies[i].angular_velocity = initial[i].angular_velocity;
  }
}

/// Quality of a resolution judged from the bodies' velocities alone (independent of what a resolver
/// reports about itself): `approach` = max over contacts of max(0, −v_n⁺) (m/s); `complementarity` =
/// max |p_k · v_n,k⁺| with p_k the impulse each contact carried (N·m/s; meaningful for e = 0, where the
/// exact answer has zero); `energy_change` = (E⁺ − E⁻)/E⁻ of the kinetic energy.
struct Quality {
  double approach = 0.0;
  double complementarity = 0.0;
  double energy_change = 0.0;
};

inline double kinetic_energy(std::span<const RigidBody> bodies) {
  double e = 0.0;
  for (const RigidBody& b : bodies) {
    if (b.fixed) continue;
    e += 0.5 * b.mass * b.velocity.squaredNorm();
    e += 0.5 * b.angular_velocity.dot(b.inertia_world() * b.angular_velocity);
  }
  return e;
}

/// `impulses[k]` is the impulse contact k carried (N·s); pass an empty span to skip complementarity.
inline Quality measure_quality(std::span<const RigidBody> after, std::span<const RigidBody> before,
                               std::span<const Contact> contacts, std::span<const double> impulses) {
  Quality q;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const resolution::ImpulseRow row = resolution::make_contact_row(after, contacts[k]);
    const double v = resolution::row_velocity(row, after);
    q.approach = std::max(q.approach, -v);
    if (!impulses.empty()) q.complementarity = std::max(q.complementarity, std::abs(impulses[k] * v));
  }
  const double e0 = kinetic_energy(before);
  q.energy_change = e0 > 0 ? (kinetic_energy(after) - e0) / e0 : 0.0;
  return q;
}

}  // namespace impetus::bench
