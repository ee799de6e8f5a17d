// my_integrator.cpp: a complete Impetus plugin in one file (see README.md next to it).
//
// Symplectic Euler with optional linear damping. Velocities: v += dt (g + F/m), ω += dt J⁻¹ τ, both
// then divided by (1 + damping·dt). Positions: x += dt v, R = Q(ω dt) R.
// Ignores the gyroscopic term, like the paper's eq. (2).
#include "impetus/plugins/export.hpp"

namespace my_plugin {  // your own namespace; with hidden visibility nothing here leaves the library

/// The module: a class derived from the interface of its kind.
class MyIntegrator final : public impetus::Integrator {
 public:
  // Read every option here. A bad value throws impetus::OptionError, which the IMPETUS_PLUGIN factory
  // turns into an error message; an option the scene gives but this never reads is reported by the host.
  explicit MyIntegrator(const impetus::ModuleOptions& options)
      : damping_(options.number("damping", 0.0, 0.0, 1.0e3)) {}

  void integrate_velocities(std::span<impetus::RigidBody> bodies, const impetus::StepContext& ctx,
                            impetus::IntegratorCounters& counters) noexcept override {
    // Implicit in the damping term, so any damping·dt is stable.
    const double keep = 1.0 / (1.0 + damping_ * ctx.dt);
    for (impetus::RigidBody& body : bodies) {
      if (body.fixed || body.asleep) continue;
      body.velocity = keep * (body.velocity + ctx.dt * (ctx.gravity + body.inv_mass * body.applied_force()));
      body.angular_velocity =
          keep * (body.angular_velocity + ctx.dt * (body.inv_inertia_world() * body.applied_torque()));
      ++counters.bodies;
    }
  }

  void integrate_positions(std::span<impetus::RigidBody> bodies, const impetus::StepContext& ctx,
                           impetus::IntegratorCounters& counters) noexcept override {
    for (impetus::RigidBody& body : bodies) {
      if (body.fixed || body.asleep) continue;
      body.position += ctx.dt * body.velocity;
      // Products of rotations drift from orthonormal; re-project every step (cheap).
      body.rotation = impetus::orthonormalized(
          impetus::rotation_from_vector(ctx.dt * body.angular_velocity) * body.rotation);
      ++counters.orthonormalized;
    }
  }

 private:
  double damping_;  ///< 1/s, ≥ 0
};

}  // namespace my_plugin

// The one exported symbol. Scenes name this plugin `my_integrator`; the file must be
// impetus_integrator_my_integrator.so, which impetus_add_plugin(integrator my_integrator ...) produces.
IMPETUS_PLUGIN(impetus::Integrator, my_plugin::MyIntegrator, "my_integrator", "0.1.0",
               "example: symplectic Euler with linear damping")
