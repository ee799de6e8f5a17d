#include "impetus/integrators/splitting/splitting.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>

namespace impetus {
namespace {

/// The body's principal frame: J_body = P diag(moments) Pᵀ with P a proper rotation (det +1).
struct PrincipalFrame {
  Mat3 axes;     ///< P: columns are the principal axes in the body frame
  Vec3 moments;  ///< principal moments of inertia (kg·m²)
};

PrincipalFrame principal_frame(const Mat3& inertia_body) {
  // A diagonal J (every primitive, and meshes imported in their principal frame) needs no solver, and
  // skipping it keeps such bodies free of the solver's rounding.
  if (inertia_body(0, 1) == 0.0 && inertia_body(0, 2) == 0.0 && inertia_body(1, 2) == 0.0)
    return {Mat3::Identity(), inertia_body.diagonal()};
  // The iterative solver (not computeDirect): its axes stay accurate when two moments are close.
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(inertia_body);
  PrincipalFrame frame{solver.eigenvectors(), solver.eigenvalues()};
  if (frame.axes.determinant() < 0.0) frame.axes.col(2) = -frame.axes.col(2);
  return frame;
}

/// Φᵢ(h): the exact flow of lᵢ²/(2 Jᵢ). The body turns about its principal axis i by θ = h lᵢ / Jᵢ,
/// so the principal-to-world map Q becomes Q Rᵢ(θ) and l = Qᵀ L (L fixed) becomes Rᵢ(θ)ᵀ l.
void rotate_about_principal_axis(int i, double h, const Vec3& moments, Mat3& q, Vec3& l) {
  const double angle = h * l[i] / moments[i];
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const int j = (i + 1) % 3;
  const int k = (i + 2) % 3;
  // Rᵢ(θ) rotates e_j towards e_k: columns j and k of Q turn, components j and k of l turn back.
  const Vec3 qj = q.col(j);
  const Vec3 qk = q.col(k);
  q.col(j) = c * qj + s * qk;
  q.col(k) = c * qk - s * qj;
  const double lj = l[j];
  const double lk = l[k];
  l[j] = c * lj + s * lk;
  l[k] = c * lk - s * lj;
}

}  // namespace

SplittingIntegrator::SplittingIntegrator(const ModuleOptions& options)
    : settings_(integrators::RotationSettings::from_options(options)) {}

void SplittingIntegrator::integrate_velocities(std::span<RigidBody> bodies, const StepContext& ctx,
                                               IntegratorCounters& /*counters*/) noexcept {
  IntegratorCounters unused;
  integrators::for_each_moving_body(bodies, unused, [&](RigidBody& body, IntegratorCounters&) {
    integrators::integrate_velocity(body, ctx);
  });
}

void SplittingIntegrator::integrate_positions(std::span<RigidBody> bodies, const StepContext& ctx,
                                              IntegratorCounters& counters) noexcept {
  const double dt = ctx.dt;
  integrators::for_each_moving_body(bodies, counters, [&](RigidBody& body, IntegratorCounters& count) {
    // eq. (2), row 3, with the velocity already updated (and resolved): symplectic Euler.
    body.position += dt * body.velocity;

    const PrincipalFrame frame = principal_frame(body.inertia_body);
    Mat3 q = body.rotation * frame.axes;  // principal frame -> world
    const Vec3 angular_momentum =
        body.rotation * (body.inertia_body * (body.rotation.transpose() * body.angular_velocity));
    Vec3 l = q.transpose() * angular_momentum;
    // Strang splitting: any order of the three axes is symmetric and second order; this one is fixed.
    rotate_about_principal_axis(0, 0.5 * dt, frame.moments, q, l);
    rotate_about_principal_axis(1, 0.5 * dt, frame.moments, q, l);
    rotate_about_principal_axis(2, dt, frame.moments, q, l);
    rotate_about_principal_axis(1, 0.5 * dt, frame.moments, q, l);
    rotate_about_principal_axis(0, 0.5 * dt, frame.moments, q, l);

    body.rotation = q * frame.axes.transpose();
    if (settings_.orthonormalize) {
      body.rotation = orthonormalized(body.rotation);
      ++count.orthonormalized;
    }
    // ω = J_world(R')⁻¹ L, right to left as in MomentumIntegrator.
    body.angular_velocity =
        body.rotation * (body.inv_inertia_body * (body.rotation.transpose() * angular_momentum));
    ++count.bodies;
  });
}

}  // namespace impetus
