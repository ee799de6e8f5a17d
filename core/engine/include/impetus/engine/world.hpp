#pragma once
/// \file
/// The world: bodies, constraints, the three modules, and the step.

#include "impetus/core/body.hpp"
#include "impetus/modules/constraint.hpp"
#include "impetus/modules/contact.hpp"
#include "impetus/modules/detector.hpp"
#include "impetus/modules/integrator.hpp"
#include "impetus/modules/resolver.hpp"
#include "impetus/modules/step.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace impetus {

/// Order of the stages in a step (docs/conventions.md, "The step").
enum class StepOrder : std::uint8_t {
  /// velocities → detect → resolve → positions (default): resolved velocities move the bodies.
  split,
  /// The paper's order (sec. 2): velocities → positions → detect → resolve. Resting bodies sink by
  /// about g·dt² per step.
  paper
};

/// World-wide settings (the configuration part of a scene).
struct WorldSettings {
  double dt = 1e-3;                       ///< time step (s), > 0
  Vec3 gravity{0.0, 0.0, -9.81};          ///< m/s²
  StepOrder order = StepOrder::split;
};

/// Wall time of each stage of one step (seconds, steady clock).
struct StepProfile {
  double velocities = 0.0;  ///< integrator phase 1
  double detect = 0.0;
  double resolve = 0.0;
  double positions = 0.0;   ///< integrator phase 2
  double total = 0.0;
};

/// What one step did: timings, each module's counters, and whether the state is sound.
struct StepStatus {
  StepProfile profile;
  IntegratorCounters integrator;
  DetectorCounters detector;
  ResolverCounters resolver;
  /// Kinetic energy of the movable bodies after the resolve stage minus before it (J): the work of the
  /// contact and constraint impulses, < 0 when they dissipate. 0 when nothing was resolved.
  double resolve_kinetic_energy_change = 0.0;
  /// Potential energy of gravity and the applied forces, −Σ (m g + F)·x over the movable bodies, after
  /// the resolve stage minus before it (J): what a resolver's position correction (moving bodies out of
  /// penetration) adds. 0 when nothing was resolved or positions were not corrected.
  double resolve_potential_energy_change = 0.0;
  std::uint64_t nan_caught = 0;  ///< bodies whose state became non-finite (restored to before the step)
  bool ok = true;                ///< false when anything non-finite was caught
  std::string message;           ///< why not ok, naming the body and the stage
};

/// A simulation world. Not copyable (it owns module instances).
class World {
 public:
  explicit World(WorldSettings settings = {});
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Adds a body after validating it (finite state, positive mass and inertia for a movable body,
  /// unique name, planes only on fixed bodies). Throws Error naming the body otherwise.
  BodyIndex add_body(RigidBody body);
  /// Adds a constraint between two existing bodies. Throws Error for a bad index.
  void add_constraint(Constraint constraint);

  /// Sets the modules. The integrator is required before step(); detector and resolver may be null
  /// (no collisions). Setting a detector hands it the current bodies; throws Error if it refuses them.
  void set_integrator(std::shared_ptr<Integrator> integrator);
  void set_detector(std::shared_ptr<CollisionDetector> detector);
  void set_resolver(std::shared_ptr<CollisionResolver> resolver);

  /// Advances the world by one step of settings().dt. Returns the step's status (also kept as
  /// last_status()). A non-finite state is caught, reported, and rolled back to before the step.
  const StepStatus& step();

  /// One detection and one resolution at the current state, no integration (the paper's experiment,
  /// `impetus resolve`). Time does not advance.
  const StepStatus& detect_and_resolve();
  /// One detection at the current state and nothing else: contacts() are what the resolver would be
  /// given (`impetus fclib export`). Velocities and time do not change.
  const StepStatus& detect_contacts();

  std::span<RigidBody> bodies() { return bodies_; }
  std::span<const RigidBody> bodies() const { return bodies_; }
  std::span<const Constraint> constraints() const { return constraints_; }
  /// Contacts found by the last detection, with the impulses of the last resolution.
  const std::vector<Contact>& contacts() const { return contacts_; }
  const WorldSettings& settings() const { return settings_; }
  const StepStatus& last_status() const { return status_; }
  double time() const { return time_; }
  std::uint64_t step_count() const { return step_count_; }
  /// Index of the body named `name`, if any.
  std::optional<BodyIndex> find_body(const std::string& name) const;

  bool has_detector() const { return detector_ != nullptr; }
  bool has_resolver() const { return resolver_ != nullptr; }

 private:
  StepContext context() const;
  void detect(StepStatus& status);
  void resolve(StepStatus& status);
  void sync_detector();
  bool check_finite(StepStatus& status, const char* stage);
  void take_snapshot();
  void restore_snapshot();

  struct BodyState {
    Vec3 position;
    Mat3 rotation;
    Vec3 velocity;
    Vec3 angular_velocity;
  };

  WorldSettings settings_;
  std::vector<RigidBody> bodies_;
  std::vector<Constraint> constraints_;
  std::vector<Contact> contacts_;
  std::vector<BodyState> snapshot_;  // state before the step, for rollback on NaN
  std::shared_ptr<Integrator> integrator_;
  std::shared_ptr<CollisionDetector> detector_;
  std::shared_ptr<CollisionResolver> resolver_;
  StepStatus status_;
  double time_ = 0.0;
  std::uint64_t step_count_ = 0;
  bool detector_stale_ = true;
};

}  // namespace impetus
