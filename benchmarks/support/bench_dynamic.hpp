#pragma once
/// \file
/// The dynamic benchmark scenes: scenes whose contact pattern changes almost every step, where a
/// resolver cannot live on what it analysed the step before. Each is built here, then stepped by Impetus
/// (momentum integrator, fcl, ledas) for a fixed number of steps from its start, and that state — the
/// snapshot — is what the `step` and `peers` families time from. Deterministic: a fixed-seed generator
/// whose bits do not depend on the standard library's distributions.
///
/// - pile_N: N mixed primitives (spheres, boxes and capsules in turn, 1000 kg/m³) in a 10 × 10 grid of
///   columns, layer over layer, with jittered positions, random orientations and a downward velocity,
///   poured into a bin (ground and four walls, 3.2 m square); the snapshot at 0.4 s has the lower layers
///   landed and piling up and the upper ones still falling onto them.
/// - heap_N: N spheres (r = 5 cm, 1000 kg/m³) in a square grid of columns, layer over layer, jittered,
///   falling onto open ground; the snapshot at 0.3 s has the first layers spreading over the ground and
///   the rest landing on them. Spheres and one plane only, so Bullet, ODE and MuJoCo run it too.
/// - knocked_wall_N: a wall of N bricks (0.4 × 0.2 × 0.2 m, 25 per course, running bond, as
///   benchmarks/step.cpp's walls) on the ground, hit at a quarter of its height by a 200 kg ball
///   (r = 0.4 m) at 8 m/s; the snapshot at 0.02 s has the impact spreading through the wall.
/// - pyramid_K: the paper's pyramid of K rows (K(K+1)/2 unit spheres of r = 0.5 m, core's generator)
///   placed at rest on the ground; the snapshot at 0.02 s. One island whose contacts all persist, the
///   large single system of the set (K = 100: 5,050 spheres, 14,950 contacts).
///
/// With friction μ (…_mu0.5, …_mu0.7) every body, ground and wall included, gets μ.

#include "support/bench_resolvers.hpp"

#include "impetus/core/body.hpp"
#include "impetus/core/mass.hpp"
#include "impetus/detection/fcl/fcl_detector.hpp"
#include "impetus/engine/generators.hpp"
#include "impetus/engine/world.hpp"
#include "impetus/integrators/momentum/momentum.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace impetus::bench {

/// splitmix64: a small generator whose sequence is fixed by its definition, on every platform.
class SceneRandom {
 public:
  explicit SceneRandom(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// A uniformly distributed rotation matrix (Shoemake's method).
  Mat3 rotation() {
    const double u1 = uniform(0, 1), u2 = uniform(0, 2 * std::numbers::pi), u3 = uniform(0, 2 * std::numbers::pi);
    const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
    return Quat(a * std::sin(u2), a * std::cos(u2), b * std::sin(u3), b * std::cos(u3)).normalized().toRotationMatrix();
  }

 private:
  std::uint64_t state_;
};

/// A fixed plane, the solid half-space n·p ≤ offset, with friction μ.
inline RigidBody fixed_plane(const std::string& name, const Vec3& normal, double offset, double mu) {
  RigidBody plane;
  plane.name = name;
  plane.shape = Plane{normal, offset};
  make_fixed(plane);
  plane.material.friction = mu;
  return plane;
}

/// A movable body of `shape` at `position`, 1000 kg/m³ (its mass from `volume`), friction μ.
inline RigidBody solid(const std::string& name, Shape shape, double volume, const Vec3& position, double mu) {
  RigidBody body;
  body.name = name;
  body.shape = std::move(shape);
  set_primitive_mass(body, 1000.0 * volume);
  body.position = position;
  body.material.friction = mu;
  return body;
}

inline std::vector<RigidBody> make_pile(int count, double mu) {
  constexpr double kPi = std::numbers::pi;
  constexpr int kSide = 10;          // columns per side
  constexpr double kSpacing = 0.3;   // m, between columns and between layers
  const double half = 0.5 * kSide * kSpacing + 0.1;
  SceneRandom random(0x5EED0001);
  std::vector<RigidBody> bodies;
  for (int i = 0; i < count; ++i) {
    const int layer = i / (kSide * kSide), column = i % (kSide * kSide);
    const Vec3 at((column % kSide - 0.5 * (kSide - 1)) * kSpacing + random.uniform(-0.03, 0.03),
                  (column / kSide - 0.5 * (kSide - 1)) * kSpacing + random.uniform(-0.03, 0.03),
                  0.2 + layer * kSpacing + random.uniform(0.0, 0.05));
    const std::string name = "pile_" + std::to_string(i);
    RigidBody body = i % 3 == 0   ? solid(name, Sphere{0.1}, 4.0 / 3.0 * kPi * 1e-3, at, mu)
                     : i % 3 == 1 ? solid(name, Box{Vec3(0.2, 0.15, 0.1)}, 0.2 * 0.15 * 0.1, at, mu)
                                  : solid(name, Capsule{0.06, 0.15}, kPi * 0.06 * 0.06 * (0.15 + 4.0 / 3.0 * 0.06), at, mu);
    body.rotation = random.rotation();
    body.velocity = Vec3(random.uniform(-0.2, 0.2), random.uniform(-0.2, 0.2), -1.0);
    body.angular_velocity = Vec3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1));
    bodies.push_back(std::move(body));
  }
  bodies.push_back(fixed_plane("wall_x0", Vec3(1, 0, 0), -half, mu));
  bodies.push_back(fixed_plane("wall_x1", Vec3(-1, 0, 0), -half, mu));
  bodies.push_back(fixed_plane("wall_y0", Vec3(0, 1, 0), -half, mu));
  bodies.push_back(fixed_plane("wall_y1", Vec3(0, -1, 0), -half, mu));
  bodies.push_back(fixed_plane("ground", Vec3(0, 0, 1), 0.0, mu));
  return bodies;
}

inline std::vector<RigidBody> make_heap(int count, double mu) {
  constexpr double kRadius = 0.05, kSpacing = 0.12;
  const int side = std::max(1, static_cast<int>(std::lround(std::cbrt(count * 0.4))));  // layers ≈ 6/10 of the side
  SceneRandom random(0x5EED0002);
  std::vector<RigidBody> bodies;
  for (int i = 0; i < count; ++i) {
    const int layer = i / (side * side), column = i % (side * side);
    const Vec3 at((column % side - 0.5 * (side - 1)) * kSpacing + random.uniform(-0.01, 0.01),
                  (column / side - 0.5 * (side - 1)) * kSpacing + random.uniform(-0.01, 0.01),
                  kRadius + 0.01 + layer * kSpacing + random.uniform(0.0, 0.01));
    RigidBody sphere = solid("heap_" + std::to_string(i), Sphere{kRadius},
                             4.0 / 3.0 * std::numbers::pi * kRadius * kRadius * kRadius, at, mu);
    sphere.velocity = Vec3(random.uniform(-0.1, 0.1), random.uniform(-0.1, 0.1), 0.0);
    bodies.push_back(std::move(sphere));
  }
  bodies.push_back(fixed_plane("ground", Vec3(0, 0, 1), 0.0, mu));
  return bodies;
}

inline std::vector<RigidBody> make_knocked_wall(int bricks, double mu) {
  constexpr int kPerCourse = 25;
  const Vec3 size(0.4, 0.2, 0.2);
  const int courses = std::max(1, bricks / kPerCourse);
  std::vector<RigidBody> bodies;
  for (int c = 0; c < courses; ++c)
    for (int i = 0; i < kPerCourse; ++i) {
      const Vec3 at((i + 0.5 * (c % 2)) * size.x(), 0.0, 0.5 * size.z() + c * (size.z() - 1e-5) - 1e-5);
      bodies.push_back(solid("brick_" + std::to_string(c) + "_" + std::to_string(i), Box{size}, size.prod(), at, mu));
    }
  constexpr double kBall = 0.4;  // m; its mass, 200 kg, passed as 0.2 m³ of 1000 kg/m³
  RigidBody ball = solid("ball", Sphere{kBall}, 0.2, Vec3(0.5 * kPerCourse * size.x(), -0.5 * size.y() - kBall - 0.005,
                                                          std::max(kBall, 0.25 * courses * size.z())), mu);
  ball.velocity = Vec3(0, 8.0, 0);
  bodies.push_back(std::move(ball));
  bodies.push_back(fixed_plane("ground", Vec3(0, 0, 1), 0.0, mu));
  return bodies;
}

/// A dynamic scene by key ("pile_1000", "heap_10000_mu0.5", "knocked_wall_1000") and how many steps of
/// 1 ms lead from its start to its snapshot.
struct DynamicScene {
  std::vector<RigidBody> start;
  int lead_steps = 0;
};

inline DynamicScene dynamic_scene(const std::string& family, int n, double mu) {
  if (family == "pile") return {make_pile(n, mu), 400};
  // The same pile later, as its upper layers land on the lower ones: with friction its large islands are
  // the frictional solver's hardest problems (resolution/ledas/README.md, "Where it fails").
  if (family == "pile_late") return {make_pile(n, mu), 600};
  if (family == "heap") return {make_heap(n, mu), 300};
  if (family == "knocked_wall") return {make_knocked_wall(n, mu), 20};
  if (family == "pyramid") return {make_pyramid(PyramidParams{.rows = n, .velocity = Vec3::Zero(), .friction = mu}), 20};
  throw std::invalid_argument("no dynamic scene family '" + family + "'");
}

/// A world stepping `bodies` as the benchmarks do: dt 1 ms, gravity −9.81 m/s² along z, the momentum
/// integrator, fcl with its defaults and ledas with its defaults (position correction and warm starts on).
inline void set_up_world(World& world, const std::vector<RigidBody>& bodies) {
  world.add_bodies(bodies);
  world.set_integrator(std::make_shared<MomentumIntegrator>(ModuleOptions{}));
  world.set_detector(std::make_shared<FclDetector>(FclDetectorSettings{}));
  world.set_resolver(make_resolver("ledas", /*velocity_only=*/false));
}

/// The scene's state one step before its snapshot (`before`) and the snapshot itself (`at`): its start
/// stepped `lead_steps` − 1 and `lead_steps` times by Impetus. A benchmark that times one step from the
/// snapshot, as a running simulation would take it, first steps the engine from `before` untimed, so that
/// what the engine carries from step to step (warm starts, contact caches) comes from a previous step,
/// not from nothing and not from the timed step's own answer. Throws if a step fails.
/// The lead-in itself is measured too (one thread): its resolver's time, and ledas's frictional island
/// problems and those left above their tolerance, summed over its steps; and the steps that left at least
/// one such problem, with their share of the resolver's time (on the frictional pile a few steps with one
/// hard island hold most of it).
struct DynamicStates {
  std::vector<RigidBody> before, at;
  int lead_steps = 0;
  double lead_resolve_s = 0.0;
  std::uint64_t lead_friction_problems = 0, lead_friction_non_converged = 0;
  std::uint64_t lead_unconverged_steps = 0;
  double lead_unconverged_resolve_s = 0.0;  ///< the resolver's seconds in those steps
};

inline DynamicStates dynamic_states(const DynamicScene& scene) {
  World world;
  set_up_world(world, scene.start);
  world.set_threads(1);
  const std::shared_ptr<CollisionResolver> resolver = make_resolver("ledas", /*velocity_only=*/false);
  const auto* ledas = dynamic_cast<const LedasResolver*>(resolver.get());
  world.set_resolver(resolver);
  DynamicStates out;
  for (int i = 0; i < scene.lead_steps; ++i) {
    if (i + 1 == scene.lead_steps) out.before.assign(world.bodies().begin(), world.bodies().end());
    const StepStatus& s = world.step();
    if (!s.ok) throw std::runtime_error("the lead-in failed: " + s.message);
    out.lead_resolve_s += s.profile.resolve;
    if (ledas != nullptr) {
      const ledas::FrictionalStats& friction = ledas->last_stats().friction;
      out.lead_friction_problems += friction.problems;
      out.lead_friction_non_converged += friction.non_converged;
      if (friction.non_converged > 0) {
        ++out.lead_unconverged_steps;
        out.lead_unconverged_resolve_s += s.profile.resolve;
      }
    }
  }
  out.lead_steps = scene.lead_steps;
  out.at.assign(world.bodies().begin(), world.bodies().end());
  return out;
}

/// The scene's snapshot: its start stepped `lead_steps` times by Impetus. Throws if a step fails.
inline std::vector<RigidBody> dynamic_snapshot(const DynamicScene& scene) { return dynamic_states(scene).at; }

}  // namespace impetus::bench
