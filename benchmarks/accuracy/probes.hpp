#pragma once
/// \file
/// The error measures of the accuracy scenarios, each a Probe that watches one run. Every measure is
/// computed from the bodies' state (and the detector's contacts), never from what a resolver reports
/// about itself.

#include "accuracy.hpp"

#include "impetus/core/math.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace impetus::accuracy {

/// Two balls head on (two_balls.yaml): `velocity_error` = the larger of the two balls' |v − v_1D| (m/s),
/// v_1D from the 1D impact formulas with the contact's restitution.
std::unique_ptr<Probe> two_balls_probe();

/// Figure 1 (billiards.yaml): `symmetry_error` = |v2 − mirror(v3)| (m/s, mirror: y → −y),
/// `momentum_error` = |P − P0| (kg·m/s), `energy_error` = |E − E0| / E0.
std::unique_ptr<Probe> billiards_probe();

/// Newton's cradle of `balls` balls named ball1…ballN, the first moving: `classic_distance` = max over
/// balls of |v − v_classic| (m/s; classic: only the last ball moves, with the first one's velocity),
/// `momentum_error` (kg·m/s) and `energy_error` (relative) as for the billiards.
std::unique_ptr<Probe> cradle_probe(int balls);

/// An inelastic drop (pyramid): `residual` = max over contacts of the approach left, max(0, −v_n −
/// gap/dt) (m/s), `energy_gain` = max(0, (E⁺ − E⁻) / E⁻), `horizontal_momentum` = |P_xy| (kg·m/s).
std::unique_ptr<Probe> drop_probe();
/// An impact against fixed ground (friction may take momentum): `residual` and `energy_gain` as drop_probe,
/// without the horizontal momentum.
std::unique_ptr<Probe> impact_energy_probe();

/// Figure 2 (figure2.yaml, body `body` landing flat on a fixed beam): `min_norm_distance` = |p − p⁺| / |p⁺|
/// where p are the contact impulses and p⁺ = (Gᵀ)⁺ Gᵀ p the minimum-norm impulses with the same effect
/// on the bodies; `velocity_error` = |v| + |ω| ℓ (m/s, ℓ = 0.5 m: the plank should stop);
/// `non_finite` = 1 if any impulse or velocity is not finite.
std::unique_ptr<Probe> min_norm_probe(const std::string& body);

/// Bodies that should come to rest: `max_penetration` (m, whole run), `rest_penetration` (m, over the
/// last `window` seconds), `top_drift` = |x_top(end) − rest| (m; rest = the top body's initial position
/// unless given), `rest_kinetic_energy` = the largest total kinetic energy over the last `window` s (J).
std::unique_ptr<Probe> resting_probe(const std::string& top, std::optional<Vec3> rest, double window);

/// Joints (point-point constraints): `gap_end` = the largest distance between joined points at the end
/// (m), `gap_max` = the largest over the run (m).
std::unique_ptr<Probe> joint_gap_probe();

/// A torque-free body: `momentum_drift` = max |L − L0| / |L0|, `energy_drift` = max |E − E0| / E0 over
/// the run (L about the world origin; the body does not translate).
std::unique_ptr<Probe> tumble_probe();

/// One body's velocity against a closed form: `velocity_error` = |v(end) − expected(t_end)| (m/s), and
/// `rolling_error` = |v + ω × (−radius e_z)| at the end (m/s; the slip of a sphere's contact point on
/// flat ground, reported when `radius` > 0).
std::unique_ptr<Probe> velocity_probe(const std::string& body, std::function<Vec3(double)> expected,
                                      double radius = 0.0);

/// Several bodies' velocities against their closed forms: `velocity_error` = the largest |v(end) −
/// expected(t_end)| among them (m/s).
using ExpectedVelocity = std::pair<std::string, std::function<Vec3(double)>>;
std::unique_ptr<Probe> velocities_probe(std::vector<ExpectedVelocity> bodies);

/// Total energy (kinetic + potential, zero at z = 0) should never increase: `energy_rise` = max over t of
/// E(t) − min_{s ≤ t} E(s), relative to E0; `max_penetration` (m).
std::unique_ptr<Probe> energy_rise_probe();

}  // namespace impetus::accuracy
