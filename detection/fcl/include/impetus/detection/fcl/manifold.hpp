#pragma once
/// \file
/// Contact manifolds, FCL-free: contacts between two supporting features (Sutherland–Hodgman clipping
/// of an incident face or segment against a reference face, segment–segment closest points), merging of
/// near-duplicate points, and reduction to at most four points spanning the largest area.
///
/// Convention (docs/conventions.md): `n` points out of body a into body b; depth > 0 is penetration,
/// < 0 a gap within the margin. A contact point lies midway between the two surfaces.

#include "impetus/detection/fcl/shapes.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace impetus::collision {

/// One contact point of a pair before it becomes an impetus::Contact.
struct ManifoldPoint {
  Vec3 point = Vec3::Zero();    ///< world (m), midway between the surfaces
  Vec3 normal = Vec3::UnitZ();  ///< unit, world, out of a into b
  double depth = 0.0;           ///< m: > 0 overlap, < 0 gap
  std::uint64_t feature = 0;    ///< stable key: feature on a (high 32 bits), feature on b (low 32 bits)
};

/// Packs the feature ids of a and b into a contact key.
inline std::uint64_t feature_key(std::uint32_t on_a, std::uint32_t on_b) {
  return (static_cast<std::uint64_t>(on_a) << 32) | on_b;
}

/// Appends the contacts between `fa`, the supporting feature of a along `n`, and `fb`, that of b along
/// −n. `overlap` is the pair's overlap along n (depth of a point contact). Face against face or segment:
/// the incident feature is clipped against the side planes of the reference face (the face more
/// aligned with n) and every clipped point deeper than −`margin` below it is kept; the normal becomes
/// the reference face's. Parallel segments: the overlapping part, up to 2 points. Otherwise 1 point.
/// Returns the number of points appended (0 only when clipping leaves nothing within the margin).
std::size_t feature_contacts(const Feature& fa, const Feature& fb, const Vec3& n, double overlap, double margin,
                             const FeatureTolerance& tol, std::vector<ManifoldPoint>& out);

/// Removes points closer than `distance` (m) to an earlier-kept point, keeping the deeper one of each
/// group. Returns the number removed.
std::size_t merge_duplicates(std::vector<ManifoldPoint>& points, double distance);

/// Keeps at most `max_points` (1…4) of `points`, spanning the largest area: an extreme point (farthest
/// from the centroid), the farthest from it, the one making the largest triangle with those, then the
/// one adding the most area outside that triangle; points collinear with those chosen are not added
/// (they would only make the contact set overdetermined). The deepest point is always kept: if it is
/// clearly deeper than the chosen point nearest to it, it replaces that one. With `max_points` = 1:
/// the deepest. Returns the number removed; the kept points keep their relative order.
std::size_t reduce_to_spanning(std::vector<ManifoldPoint>& points, std::size_t max_points);

/// Sutherland–Hodgman: clips the convex polygon `subject` against the side planes of the convex polygon
/// `clip` (normal `clip_normal`), both world frame. Each output point keeps its id, or gets a new one
/// from the clip edge and subject edge that made it. Exposed for the tests.
struct ClipPoint {
  Vec3 p;
  std::uint32_t id;
};
using ClipPolygon = SmallVec<ClipPoint, 64>;
void clip_polygon(ClipPolygon& subject, const SmallVec<Vec3, 32>& clip, const Vec3& clip_normal);

/// Closest points between segments [p0, p1] and [q0, q1] (m); parameters clamped to the segments.
void closest_points_segments(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, Vec3& on_p,
                             Vec3& on_q);

}  // namespace impetus::collision
