#pragma once
/// \file
/// Mass properties of a uniform-density polyhedron by Mirtich's algorithm (B. Mirtich, "Fast and
/// Accurate Computation of Polyhedral Mass Properties", journal of graphics tools 1(2), 1996): the ten
/// volume integrals ∫1, ∫x, ∫y, ∫z, ∫x², ∫y², ∫z², ∫xy, ∫yz, ∫zx are reduced to integrals over the faces
/// (divergence theorem), those to integrals over each face's projection onto a coordinate plane
/// (chosen per face: the one the face's normal is most nearly perpendicular to, for conditioning), and
/// those to integrals along the projected edges (Green's theorem). Coordinates are taken relative to
/// a point near the mesh (its bounding-box center) so a part far from the origin loses no accuracy.
///
/// The mesh must be closed and wound outward (mesh_validation.hpp); on anything else the results are
/// meaningless.

#include "impetus/core/shape.hpp"

namespace impetus::assets {

/// The ten volume integrals of a solid, coordinates relative to `origin` (m³, m⁴, m⁵).
struct VolumeIntegrals {
  Vec3 origin = Vec3::Zero();      ///< the point coordinates are taken relative to (mesh frame)
  double volume = 0.0;             ///< ∫ 1 dV
  Vec3 first = Vec3::Zero();       ///< ∫ x dV, ∫ y dV, ∫ z dV
  Vec3 squares = Vec3::Zero();     ///< ∫ x² dV, ∫ y² dV, ∫ z² dV
  Vec3 products = Vec3::Zero();    ///< ∫ xy dV, ∫ yz dV, ∫ zx dV
};

/// Mirtich's volume integrals of a closed, outward-wound triangle mesh about `origin`.
VolumeIntegrals volume_integrals(const TriangleMesh& mesh, const Vec3& origin);

/// Mass properties of a uniform solid, all in the mesh's frame.
struct MassProperties {
  double volume = 0.0;                  ///< m³
  double density = 0.0;                 ///< kg/m³
  double mass = 0.0;                    ///< kg
  Vec3 center_of_mass = Vec3::Zero();   ///< m, mesh frame
  Mat3 inertia = Mat3::Zero();          ///< kg·m², about the center of mass, mesh axes (symmetric)
  Vec3 principal_moments = Vec3::Zero();  ///< kg·m², eigenvalues of `inertia`, ascending
  /// Columns: the unit principal axes (mesh axes), column k for principal_moments[k]; a rotation
  /// (det +1), so inertia = axes · diag(moments) · axesᵀ.
  Mat3 principal_axes = Mat3::Identity();
};

/// Volume, mass, center of mass, inertia about it, principal moments and axes of the solid that
/// `mesh` bounds, for a uniform `density` (kg/m³, > 0).
MassProperties polyhedral_mass_properties(const TriangleMesh& mesh, double density = 1.0);

/// Mass properties from `integrals` (the density scales mass and inertia).
MassProperties mass_properties_from_integrals(const VolumeIntegrals& integrals, double density);

/// The same solid with the density that gives it `mass` (kg, > 0): mass and inertia rescaled.
MassProperties with_mass(const MassProperties& properties, double mass);

}  // namespace impetus::assets
