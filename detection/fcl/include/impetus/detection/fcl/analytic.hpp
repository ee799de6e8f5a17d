#pragma once
/// \file
/// FCL-free narrowphase pieces: exact contacts for the pairs that have a closed form (sphere and capsule
/// pairs, sphere–box, anything against a plane), the box–box separating-axis test, and the separating
/// axis refinement that turns an approximate normal (from FCL's GJK and MPR) into the exact face normal
/// when the contact is face-based, and checks its orientation.
///
/// Every function appends contacts with the normal out of `a` into `b` (docs/conventions.md) and a depth
/// > 0 for overlap, < 0 for a gap of at most `margin`.

#include "impetus/detection/fcl/manifold.hpp"
#include "impetus/detection/fcl/shapes.hpp"

#include <span>
#include <vector>

namespace impetus::collision {

/// What every pair test needs to know.
struct PairSettings {
  double margin = 1e-4;    ///< gaps up to this produce contacts (m)
  FeatureTolerance tol;    ///< supporting-feature angle tolerance
};

/// An axis of least overlap, oriented out of a into b.
struct AxisResult {
  Vec3 normal = Vec3::UnitZ();
  double overlap = 0.0;  ///< max over a of n·p − min over b of n·q (m); < 0: separated along n
  bool valid = false;
};

/// Overlap of a and b along the unit axis n (a → b): max_a n·p − min_b n·q (m). The penetration depth
/// of two convex shapes is the minimum of this over all directions, their distance minus its maximum.
double overlap_along(const Placed& a, const Placed& b, const Vec3& n);

/// The candidate axis, in either orientation, with the least overlap: this is the explicit orientation
/// check (the wrong orientation overlaps by about the shapes' combined width). A later candidate
/// replaces an earlier one only when smaller by more than `tie` (m); non-unit candidates are skipped.
/// An orientation n is allowed only if n·h ≥ 0 for every h in `half_spaces` (one-sided triangles: the
/// normal out of a mesh triangle must leave on its outer side).
AxisResult least_overlap_axis(const Placed& a, const Placed& b, std::span<const Vec3> candidates, double tie,
                              std::span<const Vec3> half_spaces = {});

/// Box–box separating-axis test over the 15 axes (3 + 3 face normals, 9 edge cross products); a face
/// axis is preferred unless an edge axis overlaps clearly less. Exact for penetration; for a gap it
/// gives the largest separation along those axes.
AxisResult box_box_axis(const Placed& a, const Placed& b);

/// Capsule–box (either order), without FCL: the least overlap over the box's face normals, the capsule
/// axis crossed with them and the direction between the closest points of the capsule's core segment and
/// the box (found by a golden-section search, the squared distance being convex along the segment).
/// Exact for penetration and for a gap.
AxisResult capsule_box_axis(const Placed& a, const Placed& b);

/// Spheres and capsules: exact, from the closest points of their cores (point or segment). Parallel
/// capsules lying side by side get two points.
void rounded_contacts(const Placed& a, const Placed& b, const PairSettings& s, std::vector<ManifoldPoint>& out);

/// Sphere–box (either order): exact, from the closest point of the box to the sphere's center.
void sphere_box_contacts(const Placed& a, const Placed& b, const PairSettings& s, std::vector<ManifoldPoint>& out);

/// A plane (the solid half-space, either a or b) against any other shape: every polytope or mesh vertex
/// within the margin, both capsule end caps, the cylinder's supporting rim feature, the sphere's lowest
/// point. Exact; at most 4 of them are kept later.
void halfspace_contacts(const Placed& a, const Placed& b, const PairSettings& s, std::vector<ManifoldPoint>& out);

/// A convex pair with a known axis: supporting features of a along n and of b along −n, then
/// feature_contacts(). If clipping leaves nothing within the margin (features that do not face each
/// other, e.g. a gap across a corner) and `fallback` is set, one point midway between the features.
void convex_contacts(const Placed& a, const Placed& b, const AxisResult& axis, const PairSettings& s,
                     std::vector<ManifoldPoint>& out, bool fallback = true);

}  // namespace impetus::collision
