// One frictional collision integrated in the normal impulse p_n (Mirtich 1996, ch. 4); the header and
// resolution/mirtich/README.md give the model. Contact coordinates: (t1, t2, n) from tangent_basis, so
// u = (u_t, u_n) with u_t ∈ R² and K splits into K_tt (2×2), K_tn, K_nt (2) and K_nn.
#include "impetus/resolution/mirtich/friction.hpp"

#include "impetus/modules/contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace impetus::mirtich {
namespace {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;
// The integrated state: slip u_t (2), normal velocity u_n, tangential impulse p_t (2), normal impulse
// p_n, normal work W_n = ∫ u_n dp_n and friction work W_t = ∫ u_t·dp_t.
using State = Eigen::Matrix<double, 8, 1>;
enum Slot : int { kUt = 0, kUn = 2, kPt = 3, kPn = 5, kWn = 6, kWt = 7 };

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// A slip direction whose rate of turning |û × du_t/dp_n| is below this fraction of ‖du_t/dp_n‖ is
// constant: the segment is advanced in closed form (rounding-level turning, e.g. a sphere or a
// symmetric corner).
constexpr double kStraight = 1e-13;
// Below this fraction of the impact speed the remaining slip is closed to zero by one straight segment
// (its direction has converged to an invariant ray by then; the error is of this order in velocity).
constexpr double kSlipSnap = 1e-12;
// slip_stalls(): a slip below this fraction of the impact speed that does not halve in kStallSteps
// accepted RK4 steps is closed to zero.
constexpr double kSlipStall = 1e-9;
constexpr int kStallSteps = 64;
// Angles sampled when searching the invariant slip directions after a reversal (then bisected).
constexpr int kRaySamples = 720;

Mat3 cross_matrix(const Vec3& r) {
  Mat3 m;
  m << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
  return m;
}

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

enum class Phase { compression, restitution, done };
enum class SlipState { sliding, sticking, ray };

// The integration of one collision (thesis ch. 4): run() calls step() until the collision ends, each
// step one closed-form segment or one (possibly rejected) RK4 step.
class ImpactIntegrator {
 public:
  ImpactIntegrator(const Mat3& k_local, const Vec3& u_local, double mu, double e, const FrictionalImpactLimits& limits)
      : k_(k_local), mu_(mu), e_(e), limits_(limits) {
    ktt_ = k_.topLeftCorner<2, 2>();
    ktn_ = k_.topRightCorner<2, 1>();
    y_.setZero();
    y_.head<3>() = u_local;
    speed_ = u_local.norm();
    impulse_scale_ = -u_local.z() / k_(2, 2);  // the frictionless compression impulse
    h_ = impulse_scale_ / 32.0;
  }

  FrictionalImpact run() {
    FrictionalImpact out;
    if (!(y_(kUn) < 0.0)) return out;  // not approaching: no collision
    if (!std::isfinite(impulse_scale_) || !(impulse_scale_ > 0.0)) {
      out.finite = false;
      return out;
    }
    if (mu_ > 0.0 && slip().norm() == 0.0) on_slip_zero();
    while (phase_ != Phase::done) {
      if (steps_ >= limits_.max_steps || !y_.allFinite()) {
        converged_ = false;
        break;
      }
      ++steps_;
      step();
    }
    out.finite = y_.allFinite();
    out.converged = converged_;
    out.steps = steps_;
    out.stuck = slip_state_ == SlipState::sticking;
    out.reversed = reversed_;
    out.compression_work = compression_ended_ ? compression_work_ : y_(kWn);
    out.restitution_work = y_(kWn) - out.compression_work;
    out.friction_work = y_(kWt);
    out.normal_impulse = y_(kPn);
    // Stored in contact coordinates for now; integrate_frictional_impact turns them to world.
    out.tangent_impulse = Vec3(y_(kPt), y_(kPt + 1), 0.0);
    out.velocity_after = y_.head<3>();
    return out;
  }

 private:
  Vec2 slip() const { return y_.segment<2>(kUt); }

  // One step of the current slip state: a closed-form straight segment where the impulse direction
  // is constant (sticking, an invariant ray, or a slip direction that does not turn), RK4 otherwise.
  void step() {
    if (slip_state_ == SlipState::sticking) return straight_segment(stick_direction_, false);
    if (slip_state_ == SlipState::ray) return straight_segment(-mu_ * ray_, true);
    const Vec2 ut = slip();
    const double slip_speed = ut.norm();
    if (mu_ == 0.0) return straight_segment(Vec2::Zero(), false);  // the rate does not depend on û
    if (slip_speed == 0.0) return on_slip_zero();
    const Vec2 dir = ut / slip_speed;
    const Vec2 dut = ktn_ - mu_ * ktt_ * dir;  // du_t/dp_n while sliding along û (thesis ch. 4)
    if (std::abs(cross2(dir, dut)) <= kStraight * dut.norm() || slip_speed <= kSlipSnap * speed_)
      return straight_segment(-mu_ * dir, true);
    rk4_step();
  }

  // The derivative of the state in p_n while sliding (Mirtich's sliding equations, thesis ch. 4):
  // du/dp_n = K (n − μ û), dp_t/dp_n = −μ û, dW_n/dp_n = u_n, dW_t/dp_n = u_t·dp_t/dp_n = −μ ‖u_t‖.
  State rate(const State& y) const {
    const Vec2 ut = y.segment<2>(kUt);
    const double slip_speed = ut.norm();
    const Vec2 dir = slip_speed > 0.0 ? Vec2(ut / slip_speed) : Vec2::Zero();
    State r;
    r.head<3>() = k_ * Vec3(-mu_ * dir.x(), -mu_ * dir.y(), 1.0);
    r.segment<2>(kPt) = -mu_ * dir;
    r(kPn) = 1.0;
    r(kWn) = y(kUn);
    r(kWt) = -mu_ * slip_speed;
    return r;
  }

  State rk4(const State& y, double h) const {
    const State k1 = rate(y);
    const State k2 = rate(y + 0.5 * h * k1);
    const State k3 = rate(y + 0.5 * h * k2);
    const State k4 = rate(y + h * k3);
    return y + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }

  // Two RK4 half steps (the accepted solution of a step of size h).
  State rk4_twice(const State& y, double h) const { return rk4(rk4(y, 0.5 * h), 0.5 * h); }

  // The current phase's end condition g ≥ 0: u_n ≥ 0 ends compression; W_n ≥ (1 − e²) W_c ends
  // restitution (Stronge: the restitution work is e² times minus the compression work W_c).
  double phase_gap(const State& y) const {
    return phase_ == Phase::compression ? y(kUn) : y(kWn) - restitution_target_;
  }

  // An adaptive RK4 step while the slip direction turns (step doubling, local error below
  // relative_tolerance × ‖u⁻‖ in velocity and × the impulse scale in impulse). The step never goes
  // more than halfway to where the slip would vanish if its direction froze, so the slip reaches zero
  // geometrically and is closed by a straight segment below kSlipSnap; a phase end inside the step is
  // located by regula falsi on the step size.
  void rk4_step() {
    const Vec2 ut = slip();
    const double slip_speed = ut.norm();
    const Vec2 dir = ut / slip_speed;
    const double closing = dir.dot(ktn_ - mu_ * ktt_ * dir);  // d‖u_t‖/dp_n now
    double h = h_;
    if (closing < 0.0) h = std::min(h, 0.5 * slip_speed / -closing);
    const State coarse = rk4(y_, h);
    const State fine = rk4_twice(y_, h);
    const double error = std::max((fine.head<3>() - coarse.head<3>()).norm() / speed_,
                                  (fine.segment<3>(kPt) - coarse.segment<3>(kPt)).norm() / impulse_scale_) /
                         15.0;
    const double tolerance = limits_.relative_tolerance;
    const bool reversed_through_zero = fine.segment<2>(kUt).dot(ut) <= 0.0;
    if (!(error <= tolerance) || reversed_through_zero) {  // reject (also a NaN error): retry smaller
      h_ = h * (reversed_through_zero ? 0.25 : std::max(0.1, 0.9 * std::pow(tolerance / error, 0.2)));
      return;
    }
    h_ = h * std::min(4.0, 0.9 * std::pow(tolerance / std::max(error, 1e-300), 0.2));
    if (phase_gap(fine) < 0.0) {
      y_ = fine;
      if (slip_stalls()) {  // spiralling into zero at rounding level: close it (see slip_stalls)
        y_.segment<2>(kUt).setZero();
        on_slip_zero();
      }
      return;
    }
    y_ = locate_phase_end(h);
    end_phase();
  }

  // Near zero the slip can spiral in (its direction turning ever faster as it shrinks) instead of
  // reaching zero along a ray: each turn takes RK4 steps of the slip's own size, and once the slip is at
  // the rounding level of the state it stops shrinking and the steps run out (a pile of boxes and
  // capsules at μ = 0.5: slips stuck at 3e-12 of the impact speed for 20,000 steps). A slip below
  // kSlipStall of the impact speed that has not halved in kStallSteps accepted steps is taken as zero
  // (an error of that order in velocity).
  bool slip_stalls() {
    const double slip_speed = slip().norm();
    if (!(slip_speed <= kSlipStall * speed_)) return false;
    if (!(slip_speed >= 0.5 * stall_mark_)) {
      stall_mark_ = slip_speed;
      stall_steps_ = 0;
      return false;
    }
    return ++stall_steps_ >= kStallSteps;
  }

  // The state at the step size in (0, h] where the phase ends (Illinois regula falsi on g(h′)).
  State locate_phase_end(double h) const {
    double lo = 0.0, hi = h, g_lo = phase_gap(y_);
    State at_hi = rk4_twice(y_, h);
    double g_hi = phase_gap(at_hi);
    for (int i = 0; i < 100 && g_hi != 0.0 && hi - lo > 1e-16 * hi; ++i) {
      const double mid = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
      const State at_mid = rk4_twice(y_, mid);
      const double g_mid = phase_gap(at_mid);
      if (g_mid >= 0.0) {
        hi = mid;
        at_hi = at_mid;
        g_hi = g_mid;
        g_lo *= 0.5;  // Illinois: keep the retained end from stalling the interpolation
      } else {
        lo = mid;
        g_lo = g_mid;
        g_hi *= 0.5;
      }
    }
    return at_hi;
  }

  // Advances along a constant impulse direction dP/dp_n = (d_t, 1) (contact coordinates) to the first
  // event: the end of the phase or the slip reaching zero. u is then linear in p_n and W_n quadratic,
  // so both events are found exactly. `sliding`: the friction work is −μ ∫ ‖u_t‖ dp_n with ‖u_t‖ linear
  // in p_n (the slip keeps its direction); otherwise (sticking, or μ = 0) no tangential work is done.
  void straight_segment(const Vec2& d_t, bool sliding) {
    Vec3 du = k_ * Vec3(d_t.x(), d_t.y(), 1.0);
    if (slip_state_ == SlipState::sticking) du.head<2>().setZero();  // u_t ≡ 0 by construction of d_t
    const Vec2 ut = slip();
    const double slip_speed = ut.norm();
    const double un = y_(kUn), dun = du.z();
    // The slip's rate of change along its own direction (for a ray: λ, from a zero slip).
    const Vec2 dir = slip_state_ == SlipState::ray ? ray_ : (slip_speed > 0.0 ? Vec2(ut / slip_speed) : Vec2::Zero());
    const double closing = dir.dot(du.head<2>());

    const double to_phase_end = straight_phase_end(un, dun);
    double to_slip_zero = kInfinity;
    if (mu_ > 0.0 && slip_state_ == SlipState::sliding && closing < 0.0) to_slip_zero = slip_speed / -closing;
    const double h = std::min(to_phase_end, to_slip_zero);
    if (!std::isfinite(h)) {  // the collision cannot end along this direction (e.g. u_n falls while sliding)
      converged_ = false;
      phase_ = Phase::done;
      return;
    }
    y_.segment<2>(kUt) += h * du.head<2>();
    y_(kUn) += h * dun;
    y_.segment<2>(kPt) += h * d_t;
    y_(kPn) += h;
    y_(kWn) += un * h + 0.5 * dun * h * h;
    if (sliding) y_(kWt) += -mu_ * (slip_speed * h + 0.5 * closing * h * h);
    if (h == to_slip_zero) {
      y_.segment<2>(kUt).setZero();
      on_slip_zero();
    }
    if (h == to_phase_end) {
      if (phase_ == Phase::compression) y_(kUn) = 0.0;
      end_phase();
    }
  }

  // The p_n increment at which the phase ends when u_n = un + dun h (and W_n quadratic): kInfinity if
  // it never does along this direction.
  double straight_phase_end(double un, double dun) const {
    if (phase_ == Phase::compression) {
      if (un >= 0.0) return 0.0;
      return dun > 0.0 ? -un / dun : kInfinity;
    }
    const double gap = y_(kWn) - restitution_target_;  // < 0 until the end
    if (gap >= 0.0) return 0.0;
    const double disc = un * un - 2.0 * dun * gap;  // of gap + un h + dun h²/2 = 0
    if (disc < 0.0) return kInfinity;
    const double q = un + std::sqrt(disc);
    if (q > 0.0) return -2.0 * gap / q;  // the positive root, without cancellation
    return kInfinity;
  }

  void end_phase() {
    if (phase_ == Phase::restitution) {
      phase_ = Phase::done;
      return;
    }
    compression_work_ = y_(kWn);
    compression_ended_ = true;
    restitution_target_ = (1.0 - e_ * e_) * compression_work_;
    phase_ = e_ > 0.0 && compression_work_ < 0.0 ? Phase::restitution : Phase::done;
  }

  // The slip has reached zero (thesis ch. 4). Sticking holds if the impulse direction that keeps
  // u_t ≡ 0, (d_t, 1) with K_tt d_t + K_tn = 0, is inside the cone; then du_n/dp_n = 1/(nᵀK⁻¹n) > 0 and
  // it holds to the end of the collision. Otherwise the slip restarts along the invariant direction
  // that diverges from zero.
  void on_slip_zero() {
    stall_mark_ = kInfinity;  // a slip that restarts is watched afresh (slip_stalls)
    stall_steps_ = 0;
    const double det = ktt_.determinant();
    const Vec2 d_t = -Vec2(ktt_(1, 1) * ktn_.x() - ktt_(0, 1) * ktn_.y(),
                           -ktt_(1, 0) * ktn_.x() + ktt_(0, 0) * ktn_.y()) / det;
    if (d_t.allFinite() && d_t.norm() <= mu_) {
      slip_state_ = SlipState::sticking;
      stick_direction_ = d_t;
      return;
    }
    if (!find_diverging_ray()) {
      converged_ = false;
      phase_ = Phase::done;
      return;
    }
    slip_state_ = SlipState::ray;
    reversed_ = true;
  }

  // The unit û with K_tn − μ K_tt û = λ û, λ > 0: a slip started from zero along û stays along û and
  // grows (the slip-reversal direction of thesis ch. 4). The roots of û × (K_tn − μ K_tt û) over the angle
  // are bracketed on kRaySamples angles and bisected; of several, the one with the largest λ (the
  // fastest-growing, deterministic).
  bool find_diverging_ray() {
    const auto unit = [](double angle) { return Vec2(std::cos(angle), std::sin(angle)); };
    const auto turning = [&](double angle) {
      const Vec2 u = unit(angle);
      return cross2(u, ktn_ - mu_ * ktt_ * u);
    };
    double best_lambda = 0.0;
    bool found = false;
    const double step = 2.0 * std::numbers::pi / kRaySamples;
    for (int i = 0; i < kRaySamples; ++i) {
      double lo = i * step, hi = (i + 1) * step;
      double f_lo = turning(lo);
      const double f_hi = turning(hi);
      if (f_lo == 0.0) hi = lo;
      else if ((f_lo < 0.0) == (f_hi < 0.0)) continue;
      for (int j = 0; j < 200 && lo < hi; ++j) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        const double f_mid = turning(mid);
        if ((f_mid < 0.0) == (f_lo < 0.0)) {
          lo = mid;
          f_lo = f_mid;
        } else {
          hi = mid;
        }
      }
      const Vec2 u = unit(hi);
      const double lambda = u.dot(ktn_ - mu_ * ktt_ * u);
      if (lambda > best_lambda) {
        best_lambda = lambda;
        ray_ = u;
        found = true;
      }
    }
    return found;
  }

  Mat3 k_;
  Mat2 ktt_;
  Vec2 ktn_;
  double mu_, e_;
  FrictionalImpactLimits limits_;
  State y_;
  double speed_ = 0.0, impulse_scale_ = 0.0, h_ = 0.0;
  double stall_mark_ = kInfinity;  // slip_stalls(): the slip when it last halved, and steps since
  int stall_steps_ = 0;
  Phase phase_ = Phase::compression;
  SlipState slip_state_ = SlipState::sliding;
  Vec2 stick_direction_ = Vec2::Zero(), ray_ = Vec2::Zero();
  double compression_work_ = 0.0, restitution_target_ = 0.0;
  std::uint32_t steps_ = 0;
  bool converged_ = true, reversed_ = false, compression_ended_ = false;
};

}  // namespace

Mat3 collision_matrix(const RigidBody& a, const RigidBody& b, const Vec3& point) {
  // An impulse P at r = point − x changes u = v + ω × r by P/m + (J⁻¹ (r × P)) × r = (1/m − [r]ₓ J⁻¹ [r]ₓ) P
  // (thesis ch. 4); body a receives −P and enters u = u_b − u_a with a minus sign, so both add.
  Mat3 k = Mat3::Zero();
  for (const RigidBody* body : {&a, &b}) {
    if (body->fixed) continue;
    const Mat3 r = cross_matrix(point - body->position);
    k += body->inv_mass * Mat3::Identity() - r * body->inv_inertia_world() * r;
  }
  return k;
}

FrictionalImpact integrate_frictional_impact(const Mat3& k, const Vec3& u, const Vec3& normal, double mu, double e,
                                             const FrictionalImpactLimits& limits) {
  Vec3 t1, t2;
  tangent_basis(normal, t1, t2);
  Mat3 basis;
  basis << t1, t2, normal;  // columns: contact coordinates → world
  ImpactIntegrator integrator(basis.transpose() * k * basis, basis.transpose() * u, mu, e, limits);
  FrictionalImpact out = integrator.run();
  out.tangent_impulse = basis * out.tangent_impulse;
  out.velocity_after = basis * out.velocity_after;
  return out;
}

}  // namespace impetus::mirtich
