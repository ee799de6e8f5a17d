#include "impetus/engine/world.hpp"

#include "impetus/core/error.hpp"
#include "impetus/core/format.hpp"
#include "impetus/engine/metrics.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_set>
#include <utility>

namespace impetus {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool state_is_finite(const RigidBody& b) {
  return all_finite(b.position) && all_finite(b.rotation) && all_finite(b.velocity) &&
         all_finite(b.angular_velocity);
}

// What the run reports of a state must be finite too: a finite velocity of 1e200 m/s has an infinite
// kinetic energy. Adds a movable body's kinetic energy, momenta and load potential to the running sums
// and returns the name of the first of them (the body's own or the sum) that is not finite, else null.
struct MeasureSums {
  double kinetic = 0.0, potential = 0.0;
  Vec3 linear = Vec3::Zero(), angular = Vec3::Zero();
};
const char* measure_overflow(const RigidBody& b, const Vec3& gravity, MeasureSums& sums) {
  if (b.fixed) return nullptr;
  const Vec3 spin = b.rotation.transpose() * b.angular_velocity;  // ω in the body frame
  const double kinetic = 0.5 * b.mass * b.velocity.squaredNorm() + 0.5 * spin.dot(b.inertia_body * spin);
  const Vec3 linear = b.mass * b.velocity;
  const Vec3 angular = b.position.cross(linear) + b.rotation * (b.inertia_body * spin);
  const double potential = -(b.mass * gravity + b.force).dot(b.position);
  sums.kinetic += kinetic;
  sums.potential += potential;
  sums.linear += linear;
  sums.angular += angular;
  if (!std::isfinite(kinetic) || !std::isfinite(sums.kinetic)) return "kinetic energy";
  if (!all_finite(linear) || !all_finite(sums.linear)) return "linear momentum";
  if (!all_finite(angular) || !all_finite(sums.angular)) return "angular momentum";
  if (!std::isfinite(potential) || !std::isfinite(sums.potential)) return "potential energy";
  return nullptr;
}

// The world's own passes over the bodies (the state checks, the energies around the resolver, the
// snapshot) run on fixed chunks of bodies in parallel. The chunks do not depend on the thread count and
// their sums are combined in chunk order, so every result is the same for 1 or 64 threads.
constexpr std::size_t kChunk = 1024;

std::size_t chunk_count(std::size_t n) { return (n + kChunk - 1) / kChunk; }

/// fn(chunk, begin, end) for every chunk of [0, n), in parallel when there is more than one.
template <class Fn>
void for_each_chunk(std::size_t n, const Fn& fn) {
  const std::size_t chunks = chunk_count(n);
  if (chunks == 1) return fn(std::size_t{0}, std::size_t{0}, n);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) { fn(c, c * kChunk, std::min(n, (c + 1) * kChunk)); });
}

// One chunk's part of check_finite: its non-finite bodies, else the first body whose measure (or the
// chunk's running sum) overflows, and the chunk's sums.
struct ChunkCheck {
  std::size_t non_finite = 0, first_bad = SIZE_MAX, first_overflow = SIZE_MAX;
  const char* overflow = nullptr;
  MeasureSums sums;
};

// One chunk's kinetic energy and load potential (as total_kinetic_energy and load_potential_energy).
struct ChunkEnergy {
  double kinetic = 0.0, potential = 0.0;
};

std::string body_label(const RigidBody& body, std::size_t index) {
  return "body '" + (body.name.empty() ? "#" + std::to_string(index) : body.name) + "'";
}

// Loads act on movable bodies, prescribed motions on fixed ones (checked when a body is added and before
// every step, since bodies() is writable); null if the body is consistent.
const char* motion_problem(const RigidBody& body) {
  if (!body.fixed)
    return body.motion == PrescribedMotion::none
               ? nullptr
               : "a prescribed motion applies to fixed bodies only; this body is movable";
  if (body.loaded())
    return "a fixed body has infinite mass, so an applied force or torque would do nothing; give it a "
           "prescribed motion instead";
  if (body.motion == PrescribedMotion::none && !(body.velocity.isZero(0.0) && body.angular_velocity.isZero(0.0)))
    return "a fixed body with velocities needs a prescribed motion (moving or surface)";
  return nullptr;
}

// Physical validity of a body handed to the world. The scene loader checks the same values with file
// positions; this catches bodies built in code.
void validate_body(const RigidBody& body, std::size_t index) {
  if (has_control_character(body.name))
    throw Error("body #" + std::to_string(index) + ": its name holds a control character (a line break, tab or "
                "NUL); names go into CSV files and messages");
  const std::string label = body_label(body, index);
  if (!state_is_finite(body) || !all_finite(body.force) || !all_finite(body.torque))
    throw Error(label + ": position, rotation, velocities and loads must be finite");
  if (!((body.rotation.transpose() * body.rotation - Mat3::Identity()).norm() < 1e-9) ||
      !(body.rotation.determinant() > 0.0))
    throw Error(label + ": rotation is not a proper rotation matrix");
  if (!std::isfinite(body.material.friction) || body.material.friction < 0.0)
    throw Error(label + ": friction must be finite and >= 0, got " + format_number(body.material.friction));
  if (!std::isfinite(body.material.restitution) || body.material.restitution < 0.0)
    throw Error(label + ": restitution must be finite and >= 0, got " + format_number(body.material.restitution));
  if (std::holds_alternative<Plane>(body.shape) && !body.fixed)
    throw Error(label + ": a plane is an infinite half-space and must be fixed");
  if (!all_finite(body.force_body) || !all_finite(body.torque_body))
    throw Error(label + ": body-frame loads must be finite");
  if (const char* why = motion_problem(body)) throw Error(label + ": " + why);
  if (body.fixed) return;
  if (!(body.mass > 0.0) || !std::isfinite(body.mass) || !(std::abs(body.inv_mass * body.mass - 1.0) < 1e-9))
    throw Error(label + ": mass must be positive and finite with inv_mass = 1/mass, got mass " +
                format_number(body.mass));
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(body.inertia_body);
  if (!all_finite(body.inertia_body) || !(eig.eigenvalues().minCoeff() > 0.0) ||
      !((body.inertia_body * body.inv_inertia_body - Mat3::Identity()).norm() < 1e-6))
    throw Error(label + ": inertia must be symmetric positive definite with a matching inverse");
  MeasureSums own;  // this body alone: a finite state whose energy or momentum overflows is refused
  if (const char* what = measure_overflow(body, Vec3::Zero(), own))
    throw Error(label + ": its " + what + " is not finite (velocities, mass or inertia too large to measure)");
}

// The bodies a constraint joins and whether they still collide, whatever its kind.
struct ConstraintEnds {
  BodyIndex a, b;
  bool collide;
};
ConstraintEnds ends_of(const Constraint& constraint) {
  return std::visit([](const auto& c) { return ConstraintEnds{c.a, c.b, c.collide}; }, constraint);
}

// Refuses a resolver that does not model friction when `body` has friction (the resolver says why).
void check_friction(CollisionResolver& resolver, const RigidBody& body, std::size_t index) {
  if (!(body.material.friction > 0.0)) return;
  if (ModuleStatus s = resolver.accept_friction(); !s)
    throw Error("resolver: " + s.message + ", but " + body_label(body, index) + " has friction " +
                format_number(body.material.friction) +
                "; set its friction to 0 or choose a resolver (or mode) that models friction, such as ledas or mirtich");
}

// Contact convention (modules/contact.hpp): P = p n + p_t acts +P on b and −P on a. In the frame of a
// fixed body moving at u_f the contact only dissipates; back in the world frame the movable body's
// kinetic energy changes by that plus P_received·u_f, the work the prescribed motion does.
double prescribed_contact_work(std::span<const RigidBody> bodies, std::span<const Contact> contacts) {
  double work = 0.0;
  for (const Contact& c : contacts) {
    const RigidBody &a = bodies[c.a], &b = bodies[c.b];
    if (a.fixed == b.fixed) continue;
    const RigidBody& driver = a.fixed ? a : b;
    if (driver.motion == PrescribedMotion::none) continue;
    const Vec3 impulse = c.impulse * c.normal + c.tangent_impulse;
    const Vec3 received = a.fixed ? impulse : Vec3(-impulse);  // by the movable body
    work += received.dot(driver.velocity_at(c.point));
  }
  return work;
}

}  // namespace

World::World(WorldSettings settings) : settings_(std::move(settings)) {
  if (!(settings_.dt > 0.0) || !std::isfinite(settings_.dt))
    throw Error("world: dt must be positive and finite, got " + format_number(settings_.dt));
  if (!all_finite(settings_.gravity)) throw Error("world: gravity must be finite");
  const SleepSettings& sleep = settings_.sleep;
  if (!(sleep.linear_velocity >= 0.0) || !std::isfinite(sleep.linear_velocity))
    throw Error("world: sleep linear_velocity must be finite and >= 0, got " + format_number(sleep.linear_velocity));
  if (!(sleep.angular_velocity >= 0.0) || !std::isfinite(sleep.angular_velocity))
    throw Error("world: sleep angular_velocity must be finite and >= 0, got " + format_number(sleep.angular_velocity));
  if (!(sleep.time > 0.0) || !std::isfinite(sleep.time))
    throw Error("world: sleep time must be positive and finite, got " + format_number(sleep.time));
  set_threads(settings_.threads);
}

World::~World() = default;

// The arena every module call of a step runs in: the modules' parallel loops (tbb::parallel_for) take
// their threads from it, so `threads` bounds them all; its results never depend on how many there are.
struct World::Threads {
  explicit Threads(std::uint32_t n) : arena(n == 0 ? tbb::task_arena::automatic : static_cast<int>(n)) {}
  tbb::task_arena arena;
  std::vector<ChunkCheck> checks;    // per chunk, reused every step
  std::vector<ChunkEnergy> energies;

  /// Kinetic energy and load potential of the movable bodies, chunk by chunk (see for_each_chunk).
  ChunkEnergy energy(std::span<const RigidBody> bodies, const Vec3& g) {
    energies.assign(chunk_count(bodies.size()), ChunkEnergy{});
    for_each_chunk(bodies.size(), [&](std::size_t c, std::size_t begin, std::size_t end) {
      energies[c] = {total_kinetic_energy(bodies.subspan(begin, end - begin)),
                     load_potential_energy(bodies.subspan(begin, end - begin), g)};
    });
    ChunkEnergy total;
    for (const ChunkEnergy& e : energies) total.kinetic += e.kinetic, total.potential += e.potential;
    return total;
  }
};

void World::set_threads(std::uint32_t threads) {
  if (threads > kMaxThreads)
    throw Error("world: threads must be at most " + std::to_string(kMaxThreads) + " (0: every core), got " +
                std::to_string(threads));
  settings_.threads = threads;
  threads_ = std::make_unique<Threads>(threads);
}

std::uint32_t World::threads() const { return static_cast<std::uint32_t>(threads_->arena.max_concurrency()); }

void World::check_new_body(const RigidBody& body, std::size_t index) const {
  validate_body(body, index);
  if (resolver_) check_friction(*resolver_, body, index);
  if (body.asleep) throw Error(body_label(body, index) + ": 'asleep' is the world's to set; add bodies awake");
}

void World::append_body(RigidBody body) {
  if (body.fixed) make_fixed(body);
  bodies_.push_back(std::move(body));
  handles_.push_back(BodyHandle{next_handle_++});
  still_time_.push_back(0.0);
  sleep_group_.push_back(static_cast<std::uint32_t>(bodies_.size() - 1));
  detector_stale_ = true;
}

BodyIndex World::add_body(RigidBody body) {
  check_new_body(body, bodies_.size());
  if (!body.name.empty() && find_body(body.name))
    throw Error("body '" + body.name + "': a body with this name already exists");
  append_body(std::move(body));
  return static_cast<BodyIndex>(bodies_.size() - 1);
}

BodyIndex World::add_bodies(std::vector<RigidBody> bodies) {
  std::unordered_set<std::string_view> names;
  names.reserve(bodies_.size() + bodies.size());
  for (const RigidBody& b : bodies_)
    if (!b.name.empty()) names.insert(b.name);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    check_new_body(bodies[i], bodies_.size() + i);
    if (!bodies[i].name.empty() && !names.insert(bodies[i].name).second)
      throw Error("body '" + bodies[i].name + "': a body with this name already exists");
  }
  const auto first = static_cast<BodyIndex>(bodies_.size());
  bodies_.reserve(bodies_.size() + bodies.size());
  for (RigidBody& b : bodies) append_body(std::move(b));
  return first;
}

BodyHandle World::handle(BodyIndex index) const {
  if (index >= handles_.size())
    throw Error("world: no body has index " + std::to_string(index) + " (there are " +
                std::to_string(bodies_.size()) + ")");
  return handles_[index];
}

std::optional<BodyIndex> World::index_of(BodyHandle handle) const {
  const auto it = std::lower_bound(handles_.begin(), handles_.end(), handle);
  if (it == handles_.end() || *it != handle) return std::nullopt;
  return static_cast<BodyIndex>(it - handles_.begin());
}

std::size_t World::remove_body(BodyHandle handle) {
  const std::optional<BodyIndex> index = index_of(handle);
  if (!index)
    throw Error("world: no body has handle " + std::to_string(handle.value) +
                (handle.value > 0 && handle.value < next_handle_ ? " (it was removed)" : " (it was never added)"));
  return remove_at(*index);
}

std::size_t World::remove_body(const std::string& name) {
  const std::optional<BodyIndex> index = find_body(name);
  if (!index) throw Error("world: no body named '" + name + "' (never added, or already removed)");
  return remove_at(*index);
}

std::size_t World::remove_at(BodyIndex index) {
  if (bodies_[index].asleep) wake_group(sleep_group_[index], nullptr);  // its neighbours lose its support
  std::vector<std::int64_t> new_index(bodies_.size());
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    new_index[i] = i < index ? static_cast<std::int64_t>(i) : i == index ? -1 : static_cast<std::int64_t>(i) - 1;
  const std::size_t before = constraints_.size();
  std::erase_if(constraints_, [&](const Constraint& c) {
    const ConstraintEnds pp = ends_of(c);
    return pp.a == index || pp.b == index;
  });
  for (Constraint& constraint : constraints_)
    std::visit(
        [&](auto& c) {
          c.a = static_cast<BodyIndex>(new_index[c.a]);
          c.b = static_cast<BodyIndex>(new_index[c.b]);
        },
        constraint);
  bodies_.erase(bodies_.begin() + index);
  handles_.erase(handles_.begin() + index);
  still_time_.erase(still_time_.begin() + index);
  sleep_group_.erase(sleep_group_.begin() + index);
  for (std::uint32_t& group : sleep_group_)  // a group is named by its lowest body, never the removed one now
    if (new_index[group] >= 0) group = static_cast<std::uint32_t>(new_index[group]);
  contacts_.clear();  // they name bodies by their old indices
  detector_stale_ = true;
  if (resolver_) resolver_->bodies_removed(new_index);
  return before - constraints_.size();
}

void World::add_constraint(Constraint constraint) {
  const ConstraintEnds pp = ends_of(constraint);
  if (pp.a >= bodies_.size() || pp.b >= bodies_.size() || pp.a == pp.b)
    throw Error("constraint: bodies must be two different existing bodies, got indices " +
                std::to_string(pp.a) + " and " + std::to_string(pp.b));
  if (bodies_[pp.a].fixed && bodies_[pp.b].fixed)
    throw Error("constraint between '" + bodies_[pp.a].name + "' and '" + bodies_[pp.b].name +
                "': both bodies are fixed");
  if (resolver_) {
    const Constraint one[] = {constraint};
    if (ModuleStatus s = resolver_->accept_constraints(one); !s) throw Error("resolver: " + s.message);
  }
  constraints_.push_back(constraint);
  detector_stale_ = true;
}

void World::set_integrator(std::shared_ptr<Integrator> integrator) { integrator_ = std::move(integrator); }

void World::set_detector(std::shared_ptr<CollisionDetector> detector) {
  detector_ = std::move(detector);
  detector_stale_ = true;
  sync_detector();
}

void World::set_resolver(std::shared_ptr<CollisionResolver> resolver) {
  if (resolver) {
    if (ModuleStatus s = resolver->accept_constraints(constraints_); !s) throw Error("resolver: " + s.message);
    for (std::size_t i = 0; i < bodies_.size(); ++i) check_friction(*resolver, bodies_[i], i);
  }
  resolver_ = std::move(resolver);
}

std::optional<BodyIndex> World::find_body(const std::string& name) const {
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].name == name) return static_cast<BodyIndex>(i);
  return std::nullopt;
}

StepContext World::context() const {
  return StepContext{settings_.dt, settings_.gravity, step_count_, time_};
}

// Hands the detector the current bodies and the pairs joined by non-colliding constraints.
void World::sync_detector() {
  if (!detector_ || !detector_stale_) return;
  std::vector<BodyPair> excluded;
  for (const Constraint& c : constraints_) {
    const ConstraintEnds pp = ends_of(c);
    if (!pp.collide) excluded.emplace_back(std::min(pp.a, pp.b), std::max(pp.a, pp.b));
  }
  std::sort(excluded.begin(), excluded.end());
  excluded.erase(std::unique(excluded.begin(), excluded.end()), excluded.end());
  if (ModuleStatus s = detector_->set_bodies(bodies_, excluded); !s) throw Error("detector: " + s.message);
  detector_stale_ = false;
}

void World::detect(StepStatus& status) {
  const auto start = Clock::now();
  contacts_.clear();
  if (detector_) {
    sync_detector();
    detector_->detect(bodies_, context(), contacts_, status.detector);
    if (refused_detection(status)) {
      status.profile.detect = seconds_since(start);
      return;
    }
    if (settings_.sleep.enabled) {
      // Touching a sleeping group wakes it; its own contacts were skipped while it slept, so detect again
      // (until no more groups wake: a woken group may touch another).
      woken_now_.clear();
      while (wake_touched(status)) {
        contacts_.clear();
        detector_->detect(bodies_, context(), contacts_, status.detector);
        if (refused_detection(status)) {
          status.profile.detect = seconds_since(start);
          return;
        }
      }
      if (stepping_ && !woken_now_.empty()) kick_woken(status);
      // Whatever detector is in use, contacts between quiet bodies (asleep, or fixed at rest) go nowhere.
      std::erase_if(contacts_, [&](const Contact& c) {
        const auto quiet = [](const RigidBody& b) { return b.asleep || (b.fixed && b.motion == PrescribedMotion::none); };
        return quiet(bodies_[c.a]) && quiet(bodies_[c.b]);
      });
    }
  }
  status.profile.detect = seconds_since(start);
}

// A detector that refused the detection (more candidate pairs than its limit: many bodies at one point)
// fails the step, naming the most crowded body; nothing is resolved and the state is not changed by it.
bool World::refused_detection(StepStatus& status) {
  const DetectorCounters& d = status.detector;
  if (d.pair_limit == 0) return false;
  contacts_.clear();
  status.ok = false;
  const auto body = static_cast<std::size_t>(d.crowded_body);
  const std::string who = body < bodies_.size() ? body_label(bodies_[body], body) : "body #" + std::to_string(body);
  status.message = "detector: " + std::to_string(d.pair_limit) + " candidate pairs and more at step " +
                   std::to_string(step_count_) + " (its pair limit; " + who + " overlaps at least " +
                   std::to_string(d.crowded_pairs) +
                   " others): detection refused, state restored to before the step";
  return true;
}

void World::resolve(StepStatus& status) {
  const auto start = Clock::now();
  if (resolver_ && (!contacts_.empty() || !constraints_.empty())) {
    // Measured around the resolver so that a run can tell energy lost in impacts from energy the
    // integrator gains or loses (the run summary's energy balance).
    const ChunkEnergy before = threads_->energy(bodies_, settings_.gravity);
    resolver_->resolve(bodies_, contacts_, constraints_, context(), status.resolver);
    const ChunkEnergy after = threads_->energy(bodies_, settings_.gravity);
    status.resolve_kinetic_energy_change = after.kinetic - before.kinetic;
    status.prescribed_work = prescribed_contact_work(bodies_, contacts_);
    status.resolve_potential_energy_change = after.potential - before.potential;
  }
  status.profile.resolve = seconds_since(start);
}

// A non-finite state never propagates: every body is rolled back to its state before the step and the
// status names the first offender and the stage that produced it.
bool World::check_finite(StepStatus& status, const char* stage) {
  std::vector<ChunkCheck>& checks = threads_->checks;
  checks.assign(chunk_count(bodies_.size()), ChunkCheck{});
  for_each_chunk(bodies_.size(), [&](std::size_t c, std::size_t begin, std::size_t end) {
    ChunkCheck& check = checks[c];
    for (std::size_t i = begin; i < end; ++i) {
      if (!state_is_finite(bodies_[i])) {
        if (check.non_finite++ == 0) check.first_bad = i;
      } else if (check.non_finite == 0 && !check.overflow) {
        if ((check.overflow = measure_overflow(bodies_[i], settings_.gravity, check.sums))) check.first_overflow = i;
      }
    }
  });
  std::size_t first_bad = SIZE_MAX;
  for (const ChunkCheck& check : checks) {
    status.nan_caught += check.non_finite;
    first_bad = std::min(first_bad, check.first_bad);
  }
  if (first_bad != SIZE_MAX) {
    status.ok = false;
    status.message = body_label(bodies_[first_bad], first_bad) + " became non-finite during " + stage +
                     " at step " + std::to_string(step_count_) + "; state restored to before the step";
    restore_snapshot();
    return false;
  }
  // A finite but absurd state (1e200 m/s, dt = 1e300 s) whose energy or momentum overflows is stopped
  // the same way: the run's summary would otherwise report inf or nan. A body's own measure or its
  // chunk's sum first, then the world's total, summed chunk by chunk.
  MeasureSums total;
  for (std::size_t c = 0; c < checks.size(); ++c) {
    const ChunkCheck& check = checks[c];
    std::size_t at = check.first_overflow;
    const char* what = check.overflow;
    if (!what) {
      total.kinetic += check.sums.kinetic;
      total.potential += check.sums.potential;
      total.linear += check.sums.linear;
      total.angular += check.sums.angular;
      at = std::min(bodies_.size(), (c + 1) * kChunk) - 1;  // the chunk's last body
      what = !std::isfinite(total.kinetic) ? "kinetic energy"
             : !all_finite(total.linear)   ? "linear momentum"
             : !all_finite(total.angular)  ? "angular momentum"
             : !std::isfinite(total.potential) ? "potential energy"
                                               : nullptr;
    }
    if (!what) continue;
    ++status.nan_caught;
    status.ok = false;
    status.message = body_label(bodies_[at], at) + ": its " + what + " (or the world's total) overflowed during " +
                     stage + " at step " + std::to_string(step_count_) +
                     " (a finite state too large to measure); state restored to before the step";
    restore_snapshot();
    return false;
  }
  return true;
}

// Only the state is saved (not names or shapes): this runs every step.
void World::take_snapshot() {
  snapshot_.resize(bodies_.size());
  for_each_chunk(bodies_.size(), [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const RigidBody& b = bodies_[i];
      snapshot_[i] = {b.position, b.rotation, b.velocity, b.angular_velocity};
    }
  });
}

void World::restore_snapshot() {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    RigidBody& b = bodies_[i];
    const BodyState& s = snapshot_[i];
    b.position = s.position;
    b.rotation = s.rotation;
    b.velocity = s.velocity;
    b.angular_velocity = s.angular_velocity;
  }
}

// Fixed bodies that move do so exactly: x += dt v, R ← Q(ω dt) R with Rodrigues' matrix (rigid motion
// at constant world-frame velocities), re-orthonormalized so that rounding cannot accumulate over a
// long run. The integrator plugins never see them (they skip fixed bodies).
void World::move_prescribed() {
  const double dt = settings_.dt;
  for (RigidBody& body : bodies_) {
    if (!body.fixed || body.motion != PrescribedMotion::moving) continue;
    body.position += dt * body.velocity;
    if (!body.angular_velocity.isZero(0.0))
      body.rotation = orthonormalized(rotation_from_vector(dt * body.angular_velocity) * body.rotation);
  }
}

const StepStatus& World::step() {
  threads_->arena.execute([this] { step_now(); });
  return status_;
}

void World::step_now() {
  if (!integrator_) throw Error("world: no integrator set");
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (const char* why = motion_problem(bodies_[i])) throw Error(body_label(bodies_[i], i) + ": " + why);
  const auto start = Clock::now();
  status_ = StepStatus{};
  // A sleeping body the program gave a velocity or a load wakes with its group.
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const RigidBody& b = bodies_[i];
    if (b.asleep && (!b.velocity.isZero(0.0) || !b.angular_velocity.isZero(0.0) || b.loaded()))
      wake_group(sleep_group_[i], &status_);
  }
  take_snapshot();
  const StepContext ctx = context();
  stepping_ = true;
  const auto timed = [](double& slot, auto&& stage) {
    const auto t0 = Clock::now();
    stage();
    slot = seconds_since(t0);
  };

  bool ok = true;
  if (settings_.order == StepOrder::split) {
    // 1. velocities: gravity and applied loads over dt (sleeping bodies keep zero)
    timed(status_.profile.velocities, [&] {
      integrator_->integrate_velocities(bodies_, ctx, status_.integrator);
      hold_sleepers();
    });
    ok = check_finite(status_, "velocity integration");
    // 2. detect contacts at the current positions (a refused detection fails the step)
    if (ok) {
      detect(status_);
      ok = status_.ok;
      if (!ok) restore_snapshot();
    }
    // 3. resolve: impulses make the predicted velocities admissible
    if (ok) {
      resolve(status_);
      ok = check_finite(status_, "resolution");
    }
    // 4. positions: move with the resolved velocities; fixed bodies with their prescribed motion
    if (ok) {
      timed(status_.profile.positions, [&] {
        integrator_->integrate_positions(bodies_, ctx, status_.integrator);
        move_prescribed();
      });
      ok = check_finite(status_, "position integration");
    }
  } else {
    // The paper's order (sec. 2): integrate fully, then detect and resolve at the new positions.
    timed(status_.profile.velocities, [&] {
      integrator_->integrate_velocities(bodies_, ctx, status_.integrator);
      hold_sleepers();
    });
    timed(status_.profile.positions, [&] {
      integrator_->integrate_positions(bodies_, ctx, status_.integrator);
      move_prescribed();
    });
    ok = check_finite(status_, "integration");
    if (ok) {
      detect(status_);
      ok = status_.ok;
      if (!ok) restore_snapshot();
    }
    if (ok) {
      resolve(status_);
      ok = check_finite(status_, "resolution");
    }
  }

  if (ok) {
    ++step_count_;
    time_ = static_cast<double>(step_count_) * settings_.dt;  // no accumulated rounding in time
    if (settings_.sleep.enabled) settle();
  }
  stepping_ = false;
  for (const RigidBody& b : bodies_)
    if (!b.fixed) ++(b.asleep ? status_.sleeping_bodies : status_.awake_bodies);
  status_.profile.total = seconds_since(start);
}

// Sleeping bodies keep zero velocities: the velocity stage's kick from gravity is taken back before
// anything sees it, so their poses do not change.
void World::hold_sleepers() {
  if (!settings_.sleep.enabled) return;
  for (RigidBody& b : bodies_)
    if (b.asleep) {
      b.velocity.setZero();
      b.angular_velocity.setZero();
    }
}

// Bodies woken by this step's detection slept through its velocity stage: they get it now, from the
// integrator itself (its velocity phase is per body), so that they feel this step's gravity and loads
// exactly as if they had been awake.
void World::kick_woken(StepStatus& status) {
  std::vector<RigidBody> woken;
  woken.reserve(woken_now_.size());
  for (BodyIndex i : woken_now_) woken.push_back(bodies_[i]);
  integrator_->integrate_velocities(woken, context(), status.integrator);
  for (std::size_t k = 0; k < woken_now_.size(); ++k) {
    bodies_[woken_now_[k]].velocity = woken[k].velocity;
    bodies_[woken_now_[k]].angular_velocity = woken[k].angular_velocity;
  }
}

void World::wake(BodyIndex index) {
  if (index >= bodies_.size())
    throw Error("world: no body has index " + std::to_string(index) + " (there are " +
                std::to_string(bodies_.size()) + ")");
  if (bodies_[index].asleep) wake_group(sleep_group_[index], nullptr);
}

void World::wake_group(std::uint32_t group, StepStatus* status) {
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].asleep && sleep_group_[i] == group) {
      bodies_[i].asleep = false;
      still_time_[i] = 0.0;  // it must be still for the whole time again before it sleeps
      if (status) {
        ++status->woken_bodies;
        woken_now_.push_back(static_cast<BodyIndex>(i));
      }
    }
}

// After a detection: wakes every sleeping group something that is not quiet touches (an awake movable
// body, a fixed body with a prescribed motion) or that a constraint joins to an awake body. True if any
// woke (their own contacts were not detected while they slept: the caller detects again).
bool World::wake_touched(StepStatus& status) {
  const std::uint64_t before = status.woken_bodies;
  const auto active = [](const RigidBody& b) { return !b.asleep && !(b.fixed && b.motion == PrescribedMotion::none); };
  for (const Contact& c : contacts_) {
    if (bodies_[c.a].asleep && active(bodies_[c.b])) wake_group(sleep_group_[c.a], &status);
    if (bodies_[c.b].asleep && active(bodies_[c.a])) wake_group(sleep_group_[c.b], &status);
  }
  for (const Constraint& constraint : constraints_) {
    const ConstraintEnds pp = ends_of(constraint);
    if (bodies_[pp.a].asleep && active(bodies_[pp.b])) wake_group(sleep_group_[pp.a], &status);
    if (bodies_[pp.b].asleep && active(bodies_[pp.a])) wake_group(sleep_group_[pp.b], &status);
  }
  return status.woken_bodies != before;
}

// End of a step: each awake movable body's still time grows while it is slower than the thresholds. The
// awake bodies joined by this step's contacts and constraints form groups; a group falls asleep when all
// its bodies have been still for settings().sleep.time, none carries a load and none touches a fixed body
// that moves (a belt keeps what it carries awake). Union-find over body indices: deterministic.
void World::settle() {
  if (std::all_of(bodies_.begin(), bodies_.end(), [](const RigidBody& b) { return b.fixed || b.asleep; })) return;
  const SleepSettings& sleep = settings_.sleep;
  const double v2 = sleep.linear_velocity * sleep.linear_velocity, w2 = sleep.angular_velocity * sleep.angular_velocity;
  const std::size_t n = bodies_.size();
  std::vector<std::uint32_t> parent(n);
  for (std::size_t i = 0; i < n; ++i) parent[i] = static_cast<std::uint32_t>(i);
  const auto root = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const auto join = [&](BodyIndex a, BodyIndex b) {
    if (bodies_[a].fixed || bodies_[b].fixed) return;  // fixed bodies do not connect groups
    const std::uint32_t ra = root(a), rb = root(b);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);  // the root is the group's lowest index
  };
  std::vector<char> restless(n, 0);  // a group with one of these never sleeps
  for (std::size_t i = 0; i < n; ++i) {
    RigidBody& b = bodies_[i];
    if (b.fixed || b.asleep) continue;
    const bool still = b.velocity.squaredNorm() <= v2 && b.angular_velocity.squaredNorm() <= w2;
    still_time_[i] = still ? still_time_[i] + settings_.dt : 0.0;
    restless[i] = still_time_[i] < sleep.time || b.loaded();
  }
  for (const Contact& c : contacts_) {
    join(c.a, c.b);
    const RigidBody &a = bodies_[c.a], &b = bodies_[c.b];
    if (a.fixed && a.motion != PrescribedMotion::none) restless[c.b] = 1;
    if (b.fixed && b.motion != PrescribedMotion::none) restless[c.a] = 1;
  }
  for (const Constraint& constraint : constraints_) {
    const ConstraintEnds pp = ends_of(constraint);
    join(pp.a, pp.b);
  }
  std::vector<char> group_restless(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (!bodies_[i].fixed && !bodies_[i].asleep && restless[i]) group_restless[root(static_cast<std::uint32_t>(i))] = 1;
  for (std::size_t i = 0; i < n; ++i) {
    RigidBody& b = bodies_[i];
    if (b.fixed || b.asleep) continue;
    const std::uint32_t group = root(static_cast<std::uint32_t>(i));
    if (group_restless[group]) continue;
    b.asleep = true;
    b.velocity.setZero();
    b.angular_velocity.setZero();
    sleep_group_[i] = group;
  }
}

const StepStatus& World::detect_and_resolve() {
  const auto start = Clock::now();
  status_ = StepStatus{};
  take_snapshot();
  threads_->arena.execute([this] {
    detect(status_);
    resolve(status_);
  });
  check_finite(status_, "resolution");
  status_.profile.total = seconds_since(start);
  return status_;
}

const StepStatus& World::detect_contacts() {
  const auto start = Clock::now();
  status_ = StepStatus{};
  threads_->arena.execute([this] { detect(status_); });
  status_.profile.total = seconds_since(start);
  return status_;
}

}  // namespace impetus
