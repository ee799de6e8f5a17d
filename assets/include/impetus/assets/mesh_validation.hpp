#pragma once
/// \file
/// Validation of a triangle mesh before any physics: it must bound a solid. Checked, in order: it has
/// triangles, indices in range, finite vertices, no degenerate triangle (zero area), closed (every
/// edge shared by exactly two triangles), consistently oriented (the two triangles at an edge run it
/// in opposite directions), each closed shell outward (a shell wound inward is flipped, with a
/// warning; a shell inside another and wound inward is a cavity and kept), shells not nested in a way
/// that counts volume twice, and a positive volume.

#include "impetus/core/shape.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace impetus::assets {

/// The first defect found (validation stops there).
enum class MeshDefect : std::uint8_t {
  none,
  empty,               ///< no triangles
  bad_index,           ///< a triangle indexes a vertex that does not exist
  not_finite,          ///< a vertex coordinate is NaN or infinite
  degenerate,          ///< a triangle with a repeated vertex or (near) zero area
  not_closed,          ///< boundary edges: an edge with one triangle
  non_manifold,        ///< an edge shared by more than two triangles
  inconsistent,        ///< two triangles run a shared edge in the same direction
  overlapping_shells,  ///< closed shells inside each other that would count volume twice
  zero_volume          ///< closed and oriented, but it encloses no volume
};

/// What validation found.
struct ValidationResult {
  MeshDefect defect = MeshDefect::none;
  /// The defect for people, without the file name, e.g. "4 boundary edges: the mesh is not closed
  /// (one runs from (0, 0, 0) to (1, 0, 0))". Empty when there is none.
  std::string message;
  std::size_t flipped_shells = 0;     ///< shells that were wound inward and have been flipped
  std::vector<std::string> warnings;  ///< without the file name
  bool ok() const { return defect == MeshDefect::none; }
};

/// Twice a triangle's area below this fraction of the squared bounding-box diagonal counts as zero.
inline constexpr double kDegenerateArea = 1e-12;

/// Checks `mesh` and repairs the one thing safe to repair: shells wound inward are flipped (and
/// reported). Never throws.
ValidationResult validate_mesh(TriangleMesh& mesh);

/// validate_mesh, throwing Error("<label>: <message>") on a defect. Warnings are appended to
/// `warnings` as "<label>: <warning>".
void require_valid_mesh(TriangleMesh& mesh, const std::string& label, std::vector<std::string>& warnings);

/// Signed volume enclosed by a closed triangle mesh (positive when wound outward), by the divergence
/// theorem about the mesh's bounding-box center.
double signed_volume(const TriangleMesh& mesh);

}  // namespace impetus::assets
