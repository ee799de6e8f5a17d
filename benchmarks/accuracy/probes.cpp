// Error measures of the accuracy scenarios (probes.hpp says what each one means).
#include "probes.hpp"

#include "impetus/engine/metrics.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

namespace impetus::accuracy {
namespace {

const RigidBody& body_named(const World& world, const std::string& name) {
  const auto index = world.find_body(name);
  if (!index) throw std::runtime_error("accuracy: the scene has no body named '" + name + "'");
  return world.bodies()[*index];
}

// Velocities of the movable bodies, in order (v then ω for each).
std::vector<Vec3> velocities(const World& world) {
  std::vector<Vec3> out;
  for (const RigidBody& b : world.bodies()) {
    if (b.fixed) continue;
    out.push_back(b.velocity);
    out.push_back(b.angular_velocity);
  }
  return out;
}

class TwoBalls final : public Probe {
 public:
  void start(const World& world) override {
    const RigidBody& l = body_named(world, "left");
    const RigidBody& r = body_named(world, "right");
    const double m1 = l.mass, m2 = r.mass, u1 = l.velocity.x(), u2 = r.velocity.x();
    const double e = combined_restitution(l, r);
    expected_left_ = Vec3((m1 * u1 + m2 * u2 + m2 * e * (u2 - u1)) / (m1 + m2), 0, 0);
    expected_right_ = Vec3((m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2), 0, 0);
  }
  Errors finish(const World& world, double) override {
    const double left = (body_named(world, "left").velocity - expected_left_).norm();
    const double right = (body_named(world, "right").velocity - expected_right_).norm();
    return {{"velocity_error", std::max(left, right)}};
  }

 private:
  Vec3 expected_left_, expected_right_;
};

// Momentum and energy before the impact, shared by the billiards and the cradle.
class Conserving : public Probe {
 public:
  void start(const World& world) override {
    const WorldMetrics m = measure(world);
    p0_ = m.linear_momentum;
    e0_ = m.kinetic_energy;
  }

 protected:
  void add_conservation(const World& world, Errors& errors) const {
    const WorldMetrics m = measure(world);
    errors["momentum_error"] = (m.linear_momentum - p0_).norm();
    errors["energy_error"] = std::abs(m.kinetic_energy - e0_) / e0_;
  }

 private:
  Vec3 p0_ = Vec3::Zero();
  double e0_ = 0.0;
};

class Billiards final : public Conserving {
 public:
  Errors finish(const World& world, double) override {
    const Vec3 v2 = body_named(world, "ball2").velocity;
    const Vec3 v3 = body_named(world, "ball3").velocity;
    Errors errors{{"symmetry_error", (v2 - Vec3(v3.x(), -v3.y(), v3.z())).norm()}};
    add_conservation(world, errors);
    return errors;
  }
};

class Cradle final : public Conserving {
 public:
  explicit Cradle(int balls) : balls_(balls) {}
  void start(const World& world) override {
    Conserving::start(world);
    first_ = body_named(world, "ball1").velocity;
  }
  Errors finish(const World& world, double) override {
    double distance = 0.0;
    for (int i = 1; i <= balls_; ++i) {
      const Vec3 classic = i == balls_ ? first_ : Vec3::Zero();
      distance = std::max(distance, (body_named(world, "ball" + std::to_string(i)).velocity - classic).norm());
    }
    Errors errors{{"classic_distance", distance}};
    add_conservation(world, errors);
    return errors;
  }

 private:
  int balls_;
  Vec3 first_ = Vec3::Zero();
};

class Drop final : public Probe {
 public:
  explicit Drop(bool horizontal) : horizontal_(horizontal) {}
  void start(const World& world) override { e0_ = measure(world).kinetic_energy; }
  Errors finish(const World& world, double) override {
    const double dt = world.settings().dt;
    double residual = 0.0;
    for (const Contact& c : world.contacts()) {
      const double vn = normal_velocity(c, world.bodies()[c.a], world.bodies()[c.b]);
      const double gap = std::max(0.0, -c.depth);
      residual = std::max(residual, -vn - gap / dt);
    }
    const WorldMetrics m = measure(world);
    Errors out{{"residual", std::max(0.0, residual)}, {"energy_gain", std::max(0.0, (m.kinetic_energy - e0_) / e0_)}};
    if (horizontal_) out["horizontal_momentum"] = m.linear_momentum.head<2>().norm();
    return out;
  }

 private:
  bool horizontal_;
  double e0_ = 0.0;
};

class MinNorm final : public Probe {
 public:
  explicit MinNorm(std::string body) : body_(std::move(body)) {}
  Errors finish(const World& world, double) override {
    // Columns of Gᵀ: six per movable body (force, then moment about its center of mass).
    std::map<BodyIndex, Eigen::Index> column;
    for (BodyIndex i = 0; i < world.bodies().size(); ++i)
      if (!world.bodies()[i].fixed) column.emplace(i, static_cast<Eigen::Index>(6 * column.size()));
    const auto& contacts = world.contacts();
    const auto m = static_cast<Eigen::Index>(contacts.size());
    Eigen::MatrixXd gt = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(6 * column.size()), m);
    Eigen::VectorXd p(m);
    bool finite = true;
    for (Eigen::Index k = 0; k < m; ++k) {
      const Contact& c = contacts[static_cast<std::size_t>(k)];
      p(k) = c.impulse;
      finite = finite && std::isfinite(c.impulse);
      for (const auto& [index, sign] : {std::pair{c.a, -1.0}, std::pair{c.b, 1.0}}) {
        const auto it = column.find(index);
        if (it == column.end()) continue;
        const Vec3 r = c.point - world.bodies()[index].position;
        gt.block<3, 1>(it->second, k) = sign * c.normal;
        gt.block<3, 1>(it->second + 3, k) = sign * r.cross(c.normal);
      }
    }
    const Eigen::VectorXd minimum = gt.completeOrthogonalDecomposition().solve(gt * p);
    const RigidBody& plank = body_named(world, body_);
    for (const Vec3& v : velocities(world)) finite = finite && all_finite(v);
    const double distance = minimum.norm() > 0 ? (p - minimum).norm() / minimum.norm() : p.norm();
    return {{"min_norm_distance", finite ? distance : std::numeric_limits<double>::infinity()},
            {"velocity_error", plank.velocity.norm() + plank.angular_velocity.norm() * 0.5},
            {"non_finite", finite ? 0.0 : 1.0}};
  }

 private:
  std::string body_;
};

class Resting final : public Probe {
 public:
  Resting(std::string top, std::optional<Vec3> rest, double window)
      : top_(std::move(top)), rest_(rest), window_(window) {}
  void start(const World& world) override {
    if (!rest_) rest_ = body_named(world, top_).position;
  }
  void after_step(const World& world, const StepStatus&) override {
    const WorldMetrics m = measure(world);
    max_penetration_ = std::max(max_penetration_, m.max_penetration);
    // Time from the probe's own step count (as World::time() computes it): a peer engine's run judged
    // through a world that does not step (bench_accuracy_peers) sees the same clock.
    ++steps_;
    history_.push_back({static_cast<double>(steps_) * world.settings().dt, m.kinetic_energy, m.max_penetration});
  }
  Errors finish(const World& world, double simulated) override {
    double rest_energy = 0.0, rest_penetration = 0.0;
    for (const Sample& s : history_) {
      if (s.time < simulated - window_) continue;
      rest_energy = std::max(rest_energy, s.kinetic_energy);
      rest_penetration = std::max(rest_penetration, s.penetration);
    }
    return {{"max_penetration", max_penetration_},
            {"rest_penetration", rest_penetration},
            {"top_drift", (body_named(world, top_).position - *rest_).norm()},
            {"rest_kinetic_energy", rest_energy}};
  }

 private:
  struct Sample {
    double time, kinetic_energy, penetration;
  };
  std::string top_;
  std::optional<Vec3> rest_;
  double window_;
  double max_penetration_ = 0.0;
  unsigned long long steps_ = 0;
  std::vector<Sample> history_;
};

class JointGap final : public Probe {
 public:
  void after_step(const World& world, const StepStatus&) override { gap_max_ = std::max(gap_max_, gap(world)); }
  Errors finish(const World& world, double) override { return {{"gap_end", gap(world)}, {"gap_max", gap_max_}}; }

 private:
  static double gap(const World& world) {
    double out = 0.0;
    for (const Constraint& constraint : world.constraints()) {
      const auto* pp = std::get_if<PointPointConstraint>(&constraint);
      if (!pp) continue;
      const RigidBody& a = world.bodies()[pp->a];
      const RigidBody& b = world.bodies()[pp->b];
      out = std::max(out, ((a.position + a.rotation * pp->anchor_a) - (b.position + b.rotation * pp->anchor_b)).norm());
    }
    return out;
  }
  double gap_max_ = 0.0;
};

class Tumble final : public Probe {
 public:
  void start(const World& world) override {
    const WorldMetrics m = measure(world);
    l0_ = m.angular_momentum;
    e0_ = m.kinetic_energy;
  }
  void after_step(const World& world, const StepStatus&) override {
    const WorldMetrics m = measure(world);
    momentum_ = std::max(momentum_, (m.angular_momentum - l0_).norm() / l0_.norm());
    energy_ = std::max(energy_, std::abs(m.kinetic_energy - e0_) / e0_);
  }
  Errors finish(const World&, double) override { return {{"momentum_drift", momentum_}, {"energy_drift", energy_}}; }

 private:
  Vec3 l0_ = Vec3::Zero();
  double e0_ = 0.0, momentum_ = 0.0, energy_ = 0.0;
};

class EnergyRise final : public Probe {
 public:
  void start(const World& world) override {
    e0_ = total_energy(measure(world));
    lowest_ = e0_;
  }
  void after_step(const World& world, const StepStatus&) override {
    const WorldMetrics m = measure(world);
    const double e = total_energy(m);
    rise_ = std::max(rise_, e - lowest_);
    lowest_ = std::min(lowest_, e);
    penetration_ = std::max(penetration_, m.max_penetration);
  }
  Errors finish(const World&, double) override {
    return {{"energy_rise", rise_ / std::abs(e0_)}, {"max_penetration", penetration_}};
  }

 private:
  double e0_ = 0.0, lowest_ = 0.0, rise_ = 0.0, penetration_ = 0.0;
};

}  // namespace

std::unique_ptr<Probe> two_balls_probe() { return std::make_unique<TwoBalls>(); }
std::unique_ptr<Probe> billiards_probe() { return std::make_unique<Billiards>(); }
std::unique_ptr<Probe> cradle_probe(int balls) { return std::make_unique<Cradle>(balls); }
std::unique_ptr<Probe> drop_probe() { return std::make_unique<Drop>(true); }
std::unique_ptr<Probe> impact_energy_probe() { return std::make_unique<Drop>(false); }
std::unique_ptr<Probe> min_norm_probe(const std::string& body) { return std::make_unique<MinNorm>(body); }
std::unique_ptr<Probe> resting_probe(const std::string& top, std::optional<Vec3> rest, double window) {
  return std::make_unique<Resting>(top, rest, window);
}
std::unique_ptr<Probe> joint_gap_probe() { return std::make_unique<JointGap>(); }
class Velocity final : public Probe {
 public:
  Velocity(std::vector<ExpectedVelocity> bodies, double radius) : bodies_(std::move(bodies)), radius_(radius) {}
  Errors finish(const World& world, double simulated) override {
    double error = 0.0;
    for (const auto& [name, expected] : bodies_)
      error = std::max(error, (body_named(world, name).velocity - expected(simulated)).norm());
    Errors out{{"velocity_error", error}};
    if (radius_ > 0.0) {
      const RigidBody& b = body_named(world, bodies_.front().first);
      out["rolling_error"] = (b.velocity + b.angular_velocity.cross(Vec3(0, 0, -radius_))).norm();
    }
    return out;
  }

 private:
  std::vector<ExpectedVelocity> bodies_;
  double radius_;
};

std::unique_ptr<Probe> tumble_probe() { return std::make_unique<Tumble>(); }
std::unique_ptr<Probe> velocity_probe(const std::string& body, std::function<Vec3(double)> expected, double radius) {
  return std::make_unique<Velocity>(std::vector<ExpectedVelocity>{{body, std::move(expected)}}, radius);
}
std::unique_ptr<Probe> velocities_probe(std::vector<ExpectedVelocity> bodies) {
  return std::make_unique<Velocity>(std::move(bodies), 0.0);
}
std::unique_ptr<Probe> energy_rise_probe() { return std::make_unique<EnergyRise>(); }

}  // namespace impetus::accuracy
