// The accuracy scenarios: scene, measures, criterion and the settings swept (accuracy.hpp).
#include "accuracy.hpp"
#include "probes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace impetus::accuracy {
namespace {

const std::vector<std::string> kAllResolvers{"ledas/complementary", "ledas/paper", "mirtich"};

std::string fmt(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

Scenario impact(std::string id, std::string group, std::string title, std::string scene) {
  Scenario s;
  s.id = std::move(id);
  s.group = std::move(group);
  s.title = std::move(title);
  s.scene = std::move(scene);
  s.kind = Kind::impact;
  s.resolvers = kAllResolvers;
  return s;
}

Scenario simulation(std::string id, std::string group, std::string title, std::string scene, double duration,
                    double reference_dt, std::vector<double> dts, bool quick) {
  Scenario s = impact(std::move(id), std::move(group), std::move(title), std::move(scene));
  s.kind = Kind::simulation;
  s.duration = duration;
  s.reference_dt = reference_dt;
  s.dts = quick ? std::vector<double>{reference_dt} : std::move(dts);
  return s;
}

const std::map<std::string, std::string> kRestingDoc{
    {"max_penetration", "largest contact depth over the run (m)"},
    {"rest_penetration", "largest contact depth over the last window (m)"},
    {"top_drift", "distance of the top body from its rest position at the end (m)"},
    {"rest_kinetic_energy", "largest total kinetic energy over the last window (J): jitter"}};

const std::map<std::string, std::string> kEnergyRiseDoc{
    {"energy_rise", "max over t of E(t) - min over s <= t of E(s), relative to E0"},
    {"max_penetration", "largest contact depth over the run (m)"}};

}  // namespace

bool Scenario::passes(const Errors& errors) const {
  for (const auto& [name, bound] : bounds) {
    const auto it = errors.find(name);
    if (it == errors.end() || !(it->second <= bound)) return false;
  }
  return true;
}

std::vector<Scenario> scenarios(bool quick) {
  std::vector<Scenario> out;
  const std::vector<double> resting_dts{1.0 / 30, 1.0 / 60, 1.0 / 120, 1.0 / 240};
  const std::vector<double> fine_dts{1.0 / 30, 1.0 / 60, 1.0 / 100, 1.0 / 250, 1.0 / 500, 1.0 / 1000};
  const std::vector<double> slope_dts{1.0 / 60, 1.0 / 240, 1.0 / 1000};  // the friction closed forms

  // 1. Two balls head on: the 1D formulas.
  for (const char* e : {"0", "0.5", "1"}) {
    Scenario s = impact(std::string("two_balls_e") + e, "two_balls",
                        std::string("Two balls head on, e = ") + e, "two_balls.yaml");
    s.overrides = {{"bodies.left.restitution", e}, {"bodies.right.restitution", e}};
    s.measures = "velocities after the impact against the 1D impact formulas";
    s.error_doc = {{"velocity_error", "max |v - v_1D| over the two balls (m/s)"}};
    s.primary = "velocity_error";
    s.criterion = "|v - v_1D| <= 1e-9 m/s";
    s.bounds = {{"velocity_error", 1e-9}};
    s.probe = [] { return two_balls_probe(); };
    out.push_back(std::move(s));
  }

  // 2. The paper's Figure 1.
  {
    Scenario s = impact("billiards", "billiards", "Three billiard balls (paper, Figure 1), e = 1", "billiards.yaml");
    s.measures = "symmetry between balls 2 and 3 after ball 1 hits both; momentum and energy";
    s.error_doc = {{"symmetry_error", "|v2 - mirror(v3)| (m/s)"},
                   {"momentum_error", "|P - P0| (kg m/s)"},
                   {"energy_error", "|E - E0| / E0"}};
    s.primary = "symmetry_error";
    s.criterion = "symmetry error <= 1e-9 m/s; momentum and energy conserved to 1e-9";
    s.bounds = {{"symmetry_error", 1e-9}, {"momentum_error", 1e-9}, {"energy_error", 1e-9}};
    s.probe = [] { return billiards_probe(); };
    out.push_back(std::move(s));
  }

  // 3. Newton's cradle.
  for (const int n : {5, 20}) {
    const std::string count = std::to_string(n);
    Scenario s = impact("cradle_" + count, "cradle", "Newton's cradle, " + count + " balls, e = 1",
                        "newtons_cradle_" + count + ".yaml");
    s.measures = "distance from the classic answer (only the last ball leaves); momentum and energy";
    s.error_doc = {{"classic_distance", "max |v - v_classic| over the balls (m/s)"},
                   {"momentum_error", "|P - P0| (kg m/s)"},
                   {"energy_error", "|E - E0| / E0"}};
    s.primary = "classic_distance";
    s.criterion = "classic answer to 1e-6 m/s; momentum and energy conserved to 1e-9";
    s.bounds = {{"classic_distance", 1e-6}, {"momentum_error", 1e-9}, {"energy_error", 1e-9}};
    s.probe = [n] { return cradle_probe(n); };
    out.push_back(std::move(s));
  }

  // 4. Pyramid drop, K = 3 … 20.
  const std::vector<int> rows = quick ? std::vector<int>{3, 10} : std::vector<int>{3, 4, 6, 10, 15, 20};
  for (const int k : rows) {
    const std::string count = std::to_string(k);
    Scenario s = impact("pyramid_drop_" + count, "pyramid_drop",
                        "Pyramid drop, K = " + count + " (" + std::to_string(k * (k + 1) / 2) +
                            " spheres moving down at 1 m/s), e = 0",
                        "pyramid_drop_10.yaml");
    s.overrides = {{"generators.0.pyramid.rows", count}};
    s.measures = "approach velocity left after one resolution (the inelastic impact stops every approach)";
    s.error_doc = {{"residual", "max over contacts of the approach velocity left (m/s)"},
                   {"energy_gain", "max(0, (E+ - E-) / E-)"},
                   {"horizontal_momentum", "|P_xy| (kg m/s; the ground pushes along z only)"}};
    s.primary = "residual";
    s.criterion = "residual approach <= 1e-6 m/s, no energy gain (1e-12), horizontal momentum <= 1e-9";
    s.bounds = {{"residual", 1e-6}, {"energy_gain", 1e-12}, {"horizontal_momentum", 1e-9}};
    s.probe = [] { return drop_probe(); };
    out.push_back(std::move(s));
  }

  // 5. Figure 2: a redundant (rank-deficient) contact set.
  {
    Scenario s = impact("figure2", "figure2", "Degenerate contact set (paper, Figure 2): plank lands flat, e = 0",
                        "figure2.yaml");
    s.measures = "impulse distribution against the minimum-norm one with the same effect; the plank stops; no NaN";
    s.error_doc = {{"min_norm_distance", "|p - p_min| / |p_min|"},
                   {"velocity_error", "|v| + |w| 0.5 m of the plank after the impact (m/s)"},
                   {"non_finite", "1 if any impulse or velocity is NaN or infinite"}};
    s.primary = "min_norm_distance";
    s.criterion = "impulses within 1e-6 (relative) of the minimum-norm ones; plank stopped to 1e-6 m/s; no NaN";
    s.bounds = {{"min_norm_distance", 1e-6}, {"velocity_error", 1e-6}, {"non_finite", 0.0}};
    s.probe = [] { return min_norm_probe("plank"); };
    out.push_back(std::move(s));
  }

  // 6. Resting: a pyramid between walls and a settling box stack, 60 s.
  const double long_run = quick ? 5.0 : 60.0;
  const double window = std::min(10.0, long_run / 4);
  {
    Scenario s = simulation("pyramid_walls", "resting", "Pyramid (K = 5) held between two fixed walls, 60 s",
                            "accuracy_pyramid_walls.yaml", long_run, 1.0 / 60, resting_dts, quick);
    s.sweep = IntegratorSweep::reference;
    s.measures = "penetration, drift of the top sphere, kinetic energy at rest";
    s.error_doc = kRestingDoc;
    s.primary = "top_drift";
    s.criterion = "top sphere within 1 mm of its start; penetration <= 1 mm; kinetic energy at rest <= 1e-6 J";
    s.bounds = {{"top_drift", 1e-3}, {"max_penetration", 1e-3}, {"rest_kinetic_energy", 1e-6}};
    s.probe = [window] { return resting_probe("pyramid_r4_0", std::nullopt, window); };
    out.push_back(std::move(s));
  }
  {
    Scenario s = simulation("box_stack_settle", "resting", "Five boxes dropped 1 cm onto each other, settling, 60 s",
                            "accuracy_box_stack_settle.yaml", long_run, 1.0 / 60, resting_dts, quick);
    s.sweep = IntegratorSweep::reference;
    s.measures = "penetration, drift of the top box from its rest position, kinetic energy at rest";
    s.error_doc = kRestingDoc;
    s.primary = "top_drift";
    s.criterion = "top box within 1 mm of (0, 0, 4.5); penetration at rest <= 1 mm; kinetic energy at rest <= 1e-6 J";
    s.bounds = {{"top_drift", 1e-3}, {"rest_penetration", 1e-3}, {"rest_kinetic_energy", 1e-6}};
    s.probe = [window] { return resting_probe("box5", Vec3(0, 0, 4.5), window); };
    out.push_back(std::move(s));
  }

  // 7. Tall stacks and mass ratios.
  const double stack_run = quick ? 3.0 : 10.0;
  const std::vector<double> stack_dts{1.0 / 30, 1.0 / 60, 1.0 / 120};  // mirtich: 7-12 ms per step
  const double stack_window = std::min(10.0, stack_run / 4);
  const std::vector<int> heights = quick ? std::vector<int>{10, 20} : std::vector<int>{10, 20, 40};
  for (const int n : heights) {
    const std::string count = std::to_string(n);
    Scenario s = simulation("box_stack_" + count, "box_stack", count + " stacked boxes at rest, " + fmt("%.0f s", stack_run),
                            n == 10 ? "box_stack_10.yaml" : "accuracy_box_stack_" + count + ".yaml", stack_run,
                            1.0 / 60, stack_dts, quick);
    s.sweep = IntegratorSweep::reference;
    s.measures = "does it stand (top box drift), penetration, kinetic energy at rest";
    s.error_doc = kRestingDoc;
    s.primary = "top_drift";
    s.criterion = "stands: top box within 1 cm of its start; penetration <= 1 mm";
    s.bounds = {{"top_drift", 1e-2}, {"max_penetration", 1e-3}};
    s.probe = [n, stack_window] { return resting_probe("box" + std::to_string(n), std::nullopt, stack_window); };
    out.push_back(std::move(s));
  }
  struct Ratio {
    const char* id;
    const char* title;
    const char* bottom;
    const char* top;
  };
  for (const Ratio& r : {Ratio{"heavy_on_light_100", "100 kg box on a 1 kg box", "1", "100"},
                         Ratio{"light_on_heavy_100", "1 kg box on a 100 kg box", "100", "1"},
                         Ratio{"heavy_on_light_1000", "1000 kg box on a 1 kg box", "1", "1000"}}) {
    Scenario s = simulation(r.id, "mass_ratio", std::string(r.title) + ", " + fmt("%.0f s", stack_run),
                            "accuracy_mass_ratio.yaml", stack_run, 1.0 / 60, stack_dts, quick);
    s.overrides = {{"bodies.bottom.mass", r.bottom}, {"bodies.top.mass", r.top}};
    s.sweep = IntegratorSweep::reference;
    s.measures = "does it stand (top box drift), penetration, kinetic energy at rest";
    s.error_doc = kRestingDoc;
    s.primary = "top_drift";
    s.criterion = "stands: top box within 1 mm of its start; penetration <= 1 mm";
    s.bounds = {{"top_drift", 1e-3}, {"max_penetration", 1e-3}};
    s.probe = [stack_window] { return resting_probe("top", std::nullopt, stack_window); };
    out.push_back(std::move(s));
  }

  // 8. Pendulum chain, joints at position and at velocity level.
  for (const char* level : {"position", "velocity"}) {
    Scenario s = simulation(std::string("pendulum_") + level, "pendulum",
                            std::string("Pendulum chain, point-point joints at ") + level + " level, " +
                                fmt("%.0f s", quick ? 5.0 : 20.0),
                            "pendulum_chain.yaml", quick ? 5.0 : 20.0, 1.0 / 100, fine_dts, quick);
    for (int i = 0; i < 3; ++i) s.overrides.push_back({"constraints." + std::to_string(i) + ".point_point.level", level});
    s.sweep = IntegratorSweep::every_dt;
    s.measures = "distance between joined points (joint gap)";
    s.error_doc = {{"gap_end", "largest joint gap at the end (m)"}, {"gap_max", "largest joint gap over the run (m)"}};
    s.primary = "gap_end";
    s.criterion = "joint gap at the end <= 1 cm";
    s.bounds = {{"gap_end", 1e-2}};
    s.probe = [] { return joint_gap_probe(); };
    out.push_back(std::move(s));
  }

  // 9. Tumbling T handle (no contacts: the resolver plays no part).
  {
    const double duration = quick ? 5.0 : 20.0;
    Scenario s = simulation("t_handle", "t_handle", "Tumbling T handle, torque-free, near its intermediate axis, " +
                                                        fmt("%.0f s", duration),
                            "accuracy_t_handle.yaml", duration, 1.0 / 1000, fine_dts, quick);
    s.resolvers = {"ledas/complementary"};
    s.sweep = IntegratorSweep::every_dt;
    s.measures = "angular momentum and kinetic energy drift";
    s.error_doc = {{"momentum_drift", "max |L - L0| / |L0|"}, {"energy_drift", "max |E - E0| / E0"}};
    s.primary = "momentum_drift";
    s.criterion = "angular momentum conserved to 1e-6 (relative); kinetic energy within 5 %";
    s.bounds = {{"momentum_drift", 1e-6}, {"energy_drift", 0.05}};
    s.probe = [] { return tumble_probe(); };
    out.push_back(std::move(s));
  }

  // 10. Friction (docs/conventions.md, "Friction"): closed forms and statics. The paper mode refuses
  // friction, so these run with the complementary mode and the sequential baseline.
  const std::vector<std::string> frictional{"ledas/complementary", "mirtich"};
  {
    // Kane's rod: an oblique, spinning impact with friction and restitution, where Newton's rule applied
    // to a frictional impulse can create energy.
    Scenario s = impact("friction_kane_rod", "friction",
                        "Kane's rod: spinning rod strikes the ground, μ = 0.8, e = 1", "kane_rod.yaml");
    s.resolvers = frictional;
    s.measures = "kinetic energy after the impact against before, approach left";
    s.error_doc = {{"energy_gain", "max(0, (E+ - E-) / E-) of the kinetic energy"},
                   {"residual", "largest approach velocity left at a contact (m/s)"}};
    s.primary = "energy_gain";
    s.criterion = "no energy gain (1e-12 relative), no approach left (1e-6 m/s)";
    s.bounds = {{"energy_gain", 1e-12}, {"residual", 1e-6}};
    s.probe = [] { return impact_energy_probe(); };
    out.push_back(std::move(s));
  }
  {
    // Painlevé's rod: sliding with μ = 1.5 at 63°, where Coulomb's law with forces has no solution.
    Scenario s = simulation("friction_painleve_rod", "friction", "Painlevé's rod: sliding at 63°, μ = 1.5, 0.2 s",
                            "painleve_rod.yaml", 0.2, 1.0 / 1000, slope_dts, quick);
    s.resolvers = frictional;
    s.sweep = IntegratorSweep::reference;
    s.measures = "rise of the total energy (kinetic + potential) at any time";
    s.error_doc = kEnergyRiseDoc;
    s.primary = "energy_rise";
    s.criterion = "total energy never rises by more than 1e-6 E0; penetration <= 1 mm";
    s.bounds = {{"energy_rise", 1e-6}, {"max_penetration", 1e-3}};
    s.probe = [] { return energy_rise_probe(); };
    out.push_back(std::move(s));
  }
  {
    Scenario s = simulation("friction_slope_slide", "friction", "Box sliding down a 30° slope, μ = 0.5, 1 s",
                            "friction_slope.yaml", 1.0, 1.0 / 1000, slope_dts, quick);
    s.resolvers = frictional;
    s.sweep = IntegratorSweep::reference;
    s.measures = "the box's velocity against a = g (sin 30° − μ cos 30°) t";
    s.error_doc = {{"velocity_error", "|v - a t| at the end (m/s)"}};
    s.primary = "velocity_error";
    s.criterion = "velocity within 1e-6 m/s of the closed form";
    s.bounds = {{"velocity_error", 1e-6}};
    const double a = 9.81 * (0.5 - 0.5 * std::sqrt(3.0) / 2.0);
    s.probe = [a] { return velocity_probe("box", [a](double t) { return Vec3(a * t, 0, 0); }); };
    out.push_back(std::move(s));
  }
  {
    // Isotropy: the same slope falling along the diagonal of x and y (gravity turned 45° about z), where
    // a friction law built from two tangent directions would not give Coulomb's answer.
    Scenario s = simulation("friction_slope_diagonal", "friction",
                            "Box sliding down a 30° slope along the x-y diagonal, μ = 0.5, 1 s", "friction_slope.yaml",
                            1.0, 1.0 / 1000, slope_dts, quick);
    s.overrides = {{"gravity", "[3.4683587617200149, 3.4683587617200149, -8.495709211125344]"}};
    s.resolvers = frictional;
    s.sweep = IntegratorSweep::reference;
    s.measures = "the box's velocity against a = g (sin 30° − μ cos 30°) t along (1, 1, 0)/√2";
    s.error_doc = {{"velocity_error", "|v - a t (1, 1, 0)/√2| at the end (m/s)"}};
    s.primary = "velocity_error";
    s.criterion = "velocity within 1e-6 m/s of the closed form";
    s.bounds = {{"velocity_error", 1e-6}};
    const double a = 9.81 * (0.5 - 0.5 * std::sqrt(3.0) / 2.0) / std::sqrt(2.0);  // per axis
    s.probe = [a] { return velocity_probe("box", [a](double t) { return Vec3(a * t, a * t, 0); }); };
    out.push_back(std::move(s));
  }
  {
    // The friction ramp (after Box2D's benchmark): five boxes on one 30° slope with contact μ = 0.1, 0.3,
    // 0.5 (slide), 0.6 and 0.8 (stick, tan 30° = 0.577).
    Scenario s = simulation("friction_ramp", "friction", "Friction ramp: five boxes on a 30° slope, μ = 0.1 to 0.8, 1 s",
                            "friction_ramp.yaml", 1.0, 1.0 / 1000, slope_dts, quick);
    s.resolvers = frictional;
    s.sweep = IntegratorSweep::reference;
    s.measures = "each box's velocity against max(0, g (sin 30° − μ cos 30°)) t down the slope";
    s.error_doc = {{"velocity_error", "largest |v - a_mu t| over the five boxes at the end (m/s)"}};
    s.primary = "velocity_error";
    s.criterion = "every box within 1e-6 m/s of its closed form";
    s.bounds = {{"velocity_error", 1e-6}};
    s.probe = [] {
      std::vector<ExpectedVelocity> boxes;
      for (const auto& [name, mu] : {std::pair{"box_mu01", 0.1}, std::pair{"box_mu03", 0.3}, std::pair{"box_mu05", 0.5},
                                     std::pair{"box_mu06", 0.6}, std::pair{"box_mu08", 0.8}}) {
        const double a = std::max(0.0, 9.81 * (0.5 - mu * std::sqrt(3.0) / 2.0));
        boxes.emplace_back(name, [a](double t) { return Vec3(a * t, 0, 0); });
      }
      return velocities_probe(std::move(boxes));
    };
    out.push_back(std::move(s));
  }
  {
    Scenario s = simulation("friction_slope_stick", "friction", "Box on a 30° slope, μ = 0.7 > tan 30°: sticks, 5 s",
                            "friction_slope.yaml", quick ? 1.0 : 5.0, 1.0 / 1000, slope_dts, quick);
    s.overrides = {{"bodies.box.friction", "0.7"}, {"bodies.ground.friction", "0.7"}};
    s.resolvers = frictional;
    s.sweep = IntegratorSweep::reference;
    s.measures = "creep of the box down the slope";
    s.error_doc = kRestingDoc;
    s.primary = "top_drift";
    s.criterion = "the box moves less than 1e-6 m";
    s.bounds = {{"top_drift", 1e-6}};
    s.probe = [] { return resting_probe("box", std::nullopt, 0.5); };
    out.push_back(std::move(s));
  }
  {
    Scenario s = simulation("friction_sphere_roll", "friction", "Sphere thrown sliding at 2 m/s, μ = 0.2: rolls at 5/7 v0, 1 s",
                            "friction_sphere.yaml", 1.0, 1.0 / 1000, slope_dts, quick);
    s.resolvers = frictional;
    s.sweep = IntegratorSweep::reference;
    s.measures = "final velocity against 5/7 v0, and the slip of the contact point";
    s.error_doc = {{"velocity_error", "|v - (5/7) v0| at the end (m/s)"},
                   {"rolling_error", "|v + w x (-r e_z)| at the end: slip left (m/s)"}};
    s.primary = "velocity_error";
    s.criterion = "velocity within 1e-6 m/s of 5/7 v0, slip below 1e-6 m/s";
    s.bounds = {{"velocity_error", 1e-6}, {"rolling_error", 1e-6}};
    s.probe = [] { return velocity_probe("ball", [](double) { return Vec3(10.0 / 7.0, 0, 0); }, 0.1); };
    out.push_back(std::move(s));
  }
  {
    Scenario s = simulation("friction_card_house", "friction", "Card house (two leaning cards and a plank), μ = 0.7: stands",
                            "friction_card_house.yaml", quick ? 1.0 : 5.0, 1.0 / 240, {1.0 / 60, 1.0 / 120, 1.0 / 240}, quick);
    s.resolvers = frictional;
    s.sweep = IntegratorSweep::reference;
    s.measures = "drift of the plank on top, penetration, kinetic energy at rest";
    s.error_doc = kRestingDoc;
    s.primary = "top_drift";
    s.criterion = "the plank within 1 mm of its start; penetration <= 1 mm";
    s.bounds = {{"top_drift", 1e-3}, {"max_penetration", 1e-3}};
    s.probe = [] { return resting_probe("plank", std::nullopt, 0.5); };
    out.push_back(std::move(s));
  }
  {
    Scenario s = simulation("friction_stack_10", "friction", "10 stacked boxes at rest, μ = 0.5: stand, 10 s",
                            "friction_stack_10.yaml", quick ? 1.0 : 10.0, 1.0 / 60, resting_dts, quick);
    s.resolvers = frictional;
    s.sweep = IntegratorSweep::reference;
    s.measures = "drift of the top box, penetration, kinetic energy at rest";
    s.error_doc = kRestingDoc;
    s.primary = "top_drift";
    s.criterion = "top box within 1 mm of its start; penetration <= 1 mm";
    s.bounds = {{"top_drift", 1e-3}, {"max_penetration", 1e-3}};
    s.probe = [] { return resting_probe("box10", std::nullopt, 0.5); };
    out.push_back(std::move(s));
  }
  {
    Scenario s = simulation("friction_pyramid_10", "friction", "Sphere pyramid K = 10 at rest, μ = 0.7: stands",
                            "friction_pyramid_10.yaml", quick ? 1.0 : 10.0, 1.0 / 60, resting_dts, quick);
    s.resolvers = frictional;
    s.sweep = IntegratorSweep::reference;
    s.measures = "drift of the top sphere, penetration, kinetic energy at rest";
    s.error_doc = kRestingDoc;
    s.primary = "top_drift";
    s.criterion = "top sphere within 1 mm of its start; penetration <= 1 mm";
    s.bounds = {{"top_drift", 1e-3}, {"max_penetration", 1e-3}};
    s.probe = [] { return resting_probe("pyramid_r9_0", std::nullopt, 0.5); };
    out.push_back(std::move(s));
  }

  // 11. A non-convex mesh bouncing with e = 0.5.
  {
    const double duration = quick ? 1.5 : 3.0;
    Scenario s = simulation("bracket_bounce", "bracket", "L bracket (triangle mesh) bouncing, e = 0.5, " +
                                                            fmt("%.1f s", duration),
                            "accuracy_bracket_bounce.yaml", duration, 1.0 / 1000, fine_dts, quick);
    s.sweep = IntegratorSweep::every_dt;
    s.measures = "rise of the total energy (kinetic + potential) at any time";
    s.error_doc = kEnergyRiseDoc;
    s.primary = "energy_rise";
    s.criterion = "total energy never rises by more than 1e-3 E0";
    s.bounds = {{"energy_rise", 1e-3}};
    s.probe = [] { return energy_rise_probe(); };
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace impetus::accuracy
