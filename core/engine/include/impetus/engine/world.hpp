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

/// Sleeping islands (docs/conventions.md, "Sleeping"): a group of movable bodies joined by contacts and
/// constraints whose every body has moved slower than the thresholds for `time` goes to sleep: its
/// velocities are set to zero and it costs no integration, detection or resolution until something
/// touches it, a load or velocity is given to one of its bodies, or the program wakes it.
struct SleepSettings {
  bool enabled = false;            ///< off by default: a scene opts in (`sleep: {enabled: true}`)
  double linear_velocity = 0.01;   ///< m/s: a body is still below this speed …
  double angular_velocity = 0.05;  ///< rad/s: … and this spin
  double time = 0.5;               ///< s: how long every body of a group must have been still
};

/// World-wide settings (the configuration part of a scene).
struct WorldSettings {
  double dt = 1e-3;                       ///< time step (s), > 0
  Vec3 gravity{0.0, 0.0, -9.81};          ///< m/s²
  StepOrder order = StepOrder::split;
  SleepSettings sleep;
  /// Threads the modules may use within a step (docs/conventions.md, "Threads"): 0 (default) for every
  /// core of the machine (as many as the process may run on), 1 for none but the caller's. The
  /// trajectories are bit-identical for every value.
  std::uint32_t threads = 0;
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
  /// Work of the contact impulses that fixed bodies with a prescribed motion exert, Σ P·u_fixed(point)
  /// over their contacts with movable bodies (J): energy such a body puts in (a pusher) or takes out. It is
  /// part of resolve_kinetic_energy_change, so the contacts' own dissipation is that change minus this.
  double prescribed_work = 0.0;
  std::uint64_t awake_bodies = 0;     ///< movable bodies awake at the end of the step
  std::uint64_t sleeping_bodies = 0;  ///< movable bodies asleep at the end of the step
  std::uint64_t woken_bodies = 0;     ///< bodies woken during the step
  /// Bodies whose state became non-finite, or whose kinetic energy or momenta overflowed (restored to
  /// before the step).
  std::uint64_t nan_caught = 0;
  /// False when anything non-finite was caught, or the detector refused the detection (more candidate
  /// pairs than its limit, DetectorCounters::pair_limit): the state is restored to before the step.
  bool ok = true;
  std::string message;           ///< why not ok, naming the body and the stage
};

/// A body's handle: stable for the world's lifetime, never reused, unlike its index (which shifts down
/// when an earlier body is removed). 0 is no body.
struct BodyHandle {
  std::uint64_t value = 0;
  auto operator<=>(const BodyHandle&) const = default;
};

/// A simulation world. Not copyable (it owns module instances).
class World {
 public:
  explicit World(WorldSettings settings = {});
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Adds a body after validating it (finite state, positive mass and inertia for a movable body,
  /// unique name, planes only on fixed bodies, loads only on movable ones, a prescribed motion only on
  /// fixed ones and velocities on a fixed body only with one). Throws Error naming the body otherwise.
  /// The body's index is bodies().size() before the call; handle(index) gives its stable handle. May be
  /// called between steps: the detector is told before the next detection.
  /// Checking the name against the bodies already in the world is a scan, so adding n bodies one by
  /// one costs O(n²): use add_bodies for many.
  BodyIndex add_body(RigidBody body);
  /// Adds many bodies at once, checked as add_body checks one (names against the world and each other
  /// with a hash set, so the cost is linear); all or nothing: if one is refused, none is added. Returns
  /// the index of the first (the others follow in order).
  BodyIndex add_bodies(std::vector<RigidBody> bodies);
  /// Removes a body between steps, with the constraints that join it (returns how many). Later bodies'
  /// indices shift down by one, constraints are renumbered, the last contacts are cleared, the detector
  /// is told before the next detection and the resolver at once (CollisionResolver::bodies_removed).
  /// Throws Error if the handle or name names no body (never added, or already removed).
  std::size_t remove_body(BodyHandle handle);
  std::size_t remove_body(const std::string& name);
  /// The stable handle of the body at `index` (which must be < bodies().size()).
  BodyHandle handle(BodyIndex index) const;
  /// The current index of the body with `handle`, if it is still in the world.
  std::optional<BodyIndex> index_of(BodyHandle handle) const;
  /// Wakes the sleeping group of the body at `index` (nothing if it is awake or fixed). A program that
  /// moves a sleeping body's pose should call it; a velocity or load given to one wakes it by itself.
  void wake(BodyIndex index);
  /// Adds a constraint between two existing bodies. Throws Error for a bad index.
  void add_constraint(Constraint constraint);

  /// Sets the modules. The integrator is required before step(); detector and resolver may be null
  /// (no collisions). Setting a detector hands it the current bodies; throws Error if it refuses them.
  void set_integrator(std::shared_ptr<Integrator> integrator);
  void set_detector(std::shared_ptr<CollisionDetector> detector);
  void set_resolver(std::shared_ptr<CollisionResolver> resolver);

  /// Advances the world by one step of settings().dt. Fixed bodies with PrescribedMotion::moving move
  /// with their velocities in the positions stage. Throws Error if a body's loads or motion became
  /// inconsistent (see add_body) since it was added. Returns the step's status (also kept as
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
  /// Sets how many threads the modules may use from the next step on (0: every core; see
  /// WorldSettings::threads); the trajectory does not change.
  void set_threads(std::uint32_t threads);
  /// How many threads the modules may use (WorldSettings::threads with 0 replaced by the core count).
  std::uint32_t threads() const;
  const StepStatus& last_status() const { return status_; }
  double time() const { return time_; }
  std::uint64_t step_count() const { return step_count_; }
  /// Index of the body named `name`, if any.
  std::optional<BodyIndex> find_body(const std::string& name) const;

  bool has_detector() const { return detector_ != nullptr; }
  bool has_resolver() const { return resolver_ != nullptr; }

  /// The most threads a world may be given.
  static constexpr std::uint32_t kMaxThreads = 4096;

 private:
  void step_now();  // step() inside the thread arena
  StepContext context() const;
  void detect(StepStatus& status);
  void resolve(StepStatus& status);
  void sync_detector();
  bool check_finite(StepStatus& status, const char* stage);
  bool refused_detection(StepStatus& status);
  void take_snapshot();
  void restore_snapshot();
  void move_prescribed();
  bool wake_touched(StepStatus& status);
  void wake_group(std::uint32_t group, StepStatus* status);
  void settle();
  void kick_woken(StepStatus& status);
  void hold_sleepers();
  std::size_t remove_at(BodyIndex index);
  void check_new_body(const RigidBody& body, std::size_t index) const;  // all add_body checks but the name
  void append_body(RigidBody body);

  struct BodyState {
    Vec3 position;
    Mat3 rotation;
    Vec3 velocity;
    Vec3 angular_velocity;
  };

  struct Threads;  // the thread arena the modules' parallel loops run in (world.cpp, oneTBB)

  WorldSettings settings_;
  std::unique_ptr<Threads> threads_;
  std::vector<RigidBody> bodies_;
  std::vector<BodyHandle> handles_;  // per body, increasing (removal keeps the order)
  std::uint64_t next_handle_ = 1;
  // Sleeping islands: per body, how long it has been still (s) and its sleeping group (the lowest index
  // of the group it fell asleep with; meaningless while awake).
  std::vector<double> still_time_;
  std::vector<std::uint32_t> sleep_group_;
  std::vector<BodyIndex> woken_now_;  // woken by the current detection (they missed its velocity stage)
  bool stepping_ = false;             // inside step() (detect() is also called by detect_and_resolve())
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
