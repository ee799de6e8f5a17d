#pragma once
/// \file
/// Procedurally built benchmark scenes (docs/conventions.md, "Benchmark scenes"): the paper's sphere
/// pyramid and sphere line. Scene files reach them through `generators:`; benchmarks and tests call
/// them directly. The bodies come out complete (mass properties set), in a fixed, documented order.

#include "impetus/core/body.hpp"
#include "impetus/core/error.hpp"

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace impetus {

/// A pyramid of equal spheres in the x–z plane resting on a fixed ground plane z = 0.
///
/// Row j (0 = bottom) holds `rows − j` spheres; with spacing s = 2r(1 − overlap), sphere i of row j is
/// at x = (j/2 + i)·s, y = 0, z = r(1 − overlap) + j·(√3/2)·s. So each sphere overlaps its row
/// neighbours and its two supporters by 2r·overlap and the bottom row overlaps the ground by r·overlap:
/// every contact exists from the first detection. rows = 3, 4, 10, 20 gives 6, 10, 55, 210 spheres.
struct PyramidParams {
  int rows = 3;                      ///< K, 1 … 1000
  double radius = 0.5;               ///< r (m), > 0
  double mass = 1.0;                 ///< of each sphere (kg), > 0
  Vec3 velocity{0.0, 0.0, -1.0};     ///< initial velocity of every sphere (m/s), the paper's "drop"
  double restitution = 0.0;          ///< of every sphere, in [0, 1]
  double friction = 0.0;             ///< Coulomb μ of every sphere and of the fixed plane, finite, ≥ 0
  double overlap = 1e-4;             ///< penetration relative to the radius, in [0, 1)
  bool ground = true;                ///< add the fixed ground plane
};

/// A row of equal spheres on the x axis, the first one moving, with a fixed wall after the last one.
///
/// Sphere i is at x = i·s, y = z = 0 with s = 2r(1 − overlap); the wall is the solid half-space
/// x ≥ x_last + r(1 − overlap) (a plane with normal (−1, 0, 0), offset −x_wall). So N spheres give N
/// contacts: N − 1 between spheres and 1 with the wall, each overlapping like the pyramid's.
struct LineParams {
  int count = 10;                    ///< N, 1 … 1 000 000
  double radius = 0.5;               ///< r (m), > 0
  double mass = 1.0;                 ///< of each sphere (kg), > 0
  bool wall = true;                  ///< add the fixed wall plane
  Vec3 velocity{1.0, 0.0, 0.0};      ///< initial velocity of the first sphere (m/s), the paper's "push"
  double restitution = 0.0;          ///< of every sphere, in [0, 1]
  double friction = 0.0;             ///< Coulomb μ of every sphere and of the fixed plane, finite, ≥ 0
  double overlap = 1e-4;             ///< penetration relative to the radius, in [0, 1)
};

/// A generator parameter out of range; `field()` names it ("rows", "radius", …) so a scene loader can
/// point at the line that set it.
class GeneratorError : public Error {
 public:
  GeneratorError(std::string field, const std::string& message) : Error(message), field_(std::move(field)) {}
  /// The parameter's key as written in a scene file.
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

/// How many bodies make_pyramid / make_line return (the ground or wall included), computed without
/// making them, so that a loader can refuse a scene too large first. Throws GeneratorError if `rows`
/// or `count` is out of range.
std::size_t body_count(const PyramidParams& params);
std::size_t body_count(const LineParams& params);

/// The pyramid's bodies: spheres row by row from the bottom, left to right, named "pyramid_r{row}_{i}",
/// then (if `ground`) the fixed plane "ground". Throws GeneratorError for a parameter out of range.
std::vector<RigidBody> make_pyramid(const PyramidParams& params);

/// The line's bodies: spheres "line_{i}" from x = 0 upwards, then (if `wall`) the fixed plane "wall".
/// Throws GeneratorError for a parameter out of range.
std::vector<RigidBody> make_line(const LineParams& params);

}  // namespace impetus
