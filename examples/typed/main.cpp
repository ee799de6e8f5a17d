// The two ways to embed Impetus, on one experiment: a 1 kg box thrown at 2 m/s along level ground with
// Coulomb friction μ = 0.5 stops after v0²/(2 μ g) = 0.4077 m.
//  1. In code: bodies made by hand, each module configured by its typed settings (impetus/settings/),
//     so a misspelt option is a compile error.
//  2. From a scene (here YAML text; a file works the same), with the resolver swapped by an override,
//     as `impetus run --set modules.resolver=mirtich` does.
//
//   typed      exit status 0 when both worlds stop the box within 1 mm of the closed form
#include <impetus/core/error.hpp>
#include <impetus/core/mass.hpp>
#include <impetus/engine/scene.hpp>
#include <impetus/engine/world.hpp>
#include <impetus/plugins/host.hpp>
#include <impetus/settings/fcl.hpp>
#include <impetus/settings/integrators.hpp>
#include <impetus/settings/ledas.hpp>

#include <cmath>
#include <cstdio>

namespace {

constexpr double kG = 9.81, kMu = 0.5, kV0 = 2.0;

// Steps until the box stops (or 2 s) and returns how far it slid.
double slide(impetus::World& world, impetus::BodyIndex box) {
  const double start = world.bodies()[box].position.x();
  for (int i = 0; i < 2000 && !(i > 0 && world.bodies()[box].velocity.norm() < 1e-9); ++i) {
    const impetus::StepStatus& status = world.step();
    if (!status.ok) throw impetus::Error(status.message);
  }
  return world.bodies()[box].position.x() - start;
}

}  // namespace

int main() {
  try {
    impetus::PluginHost host;
    const double expected = kV0 * kV0 / (2.0 * kMu * kG);

    // 1. In code, with typed settings.
    impetus::World world;  // dt 1 ms, gravity −9.81 m/s² along z
    impetus::RigidBody ground;
    ground.name = "ground";
    ground.fixed = true;
    ground.shape = impetus::Plane{impetus::Vec3::UnitZ(), 0.0};
    ground.material.friction = kMu;
    world.add_body(ground);
    impetus::RigidBody box;
    box.name = "box";
    box.shape = impetus::Box{impetus::Vec3(0.2, 0.2, 0.2)};
    impetus::set_primitive_mass(box, 1.0);
    box.position = {0, 0, 0.1};
    box.velocity = {kV0, 0, 0};
    box.material.friction = kMu;
    const impetus::BodyIndex index = world.add_body(box);

    impetus::FclDetectorSettings detector;
    detector.margin = 1e-3;
    impetus::LedasSettings resolver;  // the defaults: complementary mode, exact frictional contact
    world.set_integrator(host.create_integrator(impetus::MomentumSettings{}));
    world.set_detector(host.create_detector(detector));
    world.set_resolver(host.create_resolver(resolver));
    const double in_code = slide(world, index);
    std::printf("in code (ledas, typed settings): slid %.6f m (closed form %.6f m)\n", in_code, expected);

    // 2. The same world from a scene, the resolver swapped by an override.
    const char* scene_text = R"(
dt: 0.001
gravity: [0, 0, -9.81]
modules:
  integrator: momentum
  detector: {plugin: fcl, margin: 1.0e-3}
  resolver: ledas
bodies:
  - {name: ground, fixed: true, friction: 0.5, shape: {plane: {normal: [0, 0, 1]}}}
  - {name: box, shape: {box: {size: [0.2, 0.2, 0.2]}}, mass: 1, friction: 0.5, position: [0, 0, 0.1], velocity: [2, 0, 0]}
)";
    const impetus::Scene scene =
        impetus::load_scene_text(scene_text, "slide.yaml", ".", {{"modules.resolver", "mirtich"}});
    const auto scene_world = impetus::build_world(scene, host);
    const double from_scene = slide(*scene_world, *scene_world->find_body("box"));
    std::printf("from a scene (resolver swapped to mirtich): slid %.6f m\n", from_scene);

    // The split step's velocity is exact; the position is first order in dt (v0 dt = 2 mm at most).
    for (const double d : {in_code, from_scene})
      if (std::abs(d - expected) > 1e-3 * 2.0) {
        std::fprintf(stderr, "typed: slid %.6f m, expected %.6f m\n", d, expected);
        return 1;
      }
  } catch (const impetus::Error& e) {
    std::fprintf(stderr, "typed: %s\n", e.what());
    return 1;
  }
  return 0;
}
