// Embedding Impetus: build a world in code, load an integrator plugin by name, step it, and check the
// result against the analytic answer. Then load a scene file the same way `impetus run` does.
//
//   embed [SCENE]     exit status 0 when the simulated free fall matches ½ g t² (with the step's
//                     known first-order error) to 1e-9
#include <impetus/core/error.hpp>
#include <impetus/core/mass.hpp>
#include <impetus/engine/metrics.hpp>
#include <impetus/engine/scene.hpp>
#include <impetus/engine/world.hpp>
#include <impetus/plugins/host.hpp>

#include <cmath>
#include <cstdio>

int main(int argc, char** argv) {
  try {
    impetus::PluginHost host;  // finds the plugins installed next to libimpetus_plugin_host.so

    // A world made in code: one 2 kg ball dropped from rest.
    impetus::WorldSettings settings;
    settings.dt = 1e-3;
    impetus::World world(settings);
    impetus::RigidBody ball;
    ball.name = "ball";
    ball.shape = impetus::Sphere{0.1};
    impetus::set_primitive_mass(ball, 2.0);  // a uniform solid sphere of 2 kg
    ball.position = {0, 0, 100};
    world.add_body(ball);

    impetus::PluginRequest request;
    request.kind = impetus::ModuleKind::integrator;
    request.name = "euler";
    world.set_integrator(host.create_integrator(request));

    const int steps = 1000;
    for (int i = 0; i < steps; ++i) world.step();
    // Velocities first, then positions (docs/conventions.md, "The step"): z_n = z0 − ½ g t² − ½ g dt t exactly.
    const double t = world.time(), g = 9.81;
    const double expected = 100.0 - 0.5 * g * t * t - 0.5 * g * settings.dt * t;
    const double z = world.bodies()[0].position.z();
    std::printf("ball after %.3f s: z = %.12f m (expected %.12f)\n", t, z, expected);
    if (std::abs(z - expected) > 1e-9 * 100.0) {
      std::fprintf(stderr, "embed: free fall is off by %g m\n", z - expected);
      return 1;
    }

    if (argc > 1) {  // a scene file, built exactly as the command-line tool builds it
      const impetus::Scene scene = impetus::load_scene(argv[1]);
      auto scene_world = impetus::build_world(scene, host);
      for (int i = 0; i < 100; ++i) scene_world->step();
      const auto m = impetus::measure(*scene_world);
      std::printf("%s: %zu bodies, t = %.3f s, kinetic energy %.6f J\n", argv[1],
                  scene_world->bodies().size(), scene_world->time(), m.kinetic_energy);
    }
  } catch (const impetus::Error& e) {
    std::fprintf(stderr, "embed: %s\n", e.what());
    return 1;
  }
  return 0;
}
