#pragma once
/// \file
/// Math types used throughout Impetus (Eigen, double precision) and small rotation helpers.
/// Conventions: SI units, right-handed world frame; a rotation matrix R maps body coordinates to world
/// coordinates (p_world = x + R p_body). See docs/conventions.md.

#include <Eigen/Dense>

#include <cmath>

namespace impetus {

using Vec3 = Eigen::Vector3d;     ///< 3-vector (metres, m/s, rad/s, newtons … as named)
using Mat3 = Eigen::Matrix3d;     ///< 3×3 matrix (rotations, inertia tensors)
using Quat = Eigen::Quaterniond;  ///< unit quaternion (w, x, y, z) used only at the API boundary

/// Rotation by angle `|rotation_vector|` about its direction (Rodrigues' formula; the paper's eq. 2
/// matrix Q with its diagonal typo corrected: Q_ii = cos φ + n_i² (1 − cos φ)).
/// Returns the identity for a zero vector.
inline Mat3 rotation_from_vector(const Vec3& rotation_vector) {
  const double phi = rotation_vector.norm();
  if (phi == 0.0) return Mat3::Identity();
  const Vec3 n = rotation_vector / phi;
  const double c = std::cos(phi), s = std::sin(phi), t = 1.0 - c;
  Mat3 q;
  q << c + n.x() * n.x() * t, t * n.x() * n.y() - n.z() * s, t * n.x() * n.z() + n.y() * s,
      t * n.x() * n.y() + n.z() * s, c + n.y() * n.y() * t, t * n.y() * n.z() - n.x() * s,
      t * n.x() * n.z() - n.y() * s, t * n.y() * n.z() + n.x() * s, c + n.z() * n.z() * t;
  return q;
}

/// Nearest rotation matrix to `r` (Gram–Schmidt on the columns, x first): removes the drift that
/// repeated products of rotations accumulate. Deterministic and cheap.
inline Mat3 orthonormalized(const Mat3& r) {
  Vec3 c0 = r.col(0).normalized();
  Vec3 c1 = (r.col(1) - c0.dot(r.col(1)) * c0).normalized();
  Mat3 out;
  out.col(0) = c0;
  out.col(1) = c1;
  out.col(2) = c0.cross(c1);
  return out;
}

/// True when every coefficient is finite (no NaN, no infinity).
template <typename Derived>
inline bool all_finite(const Eigen::MatrixBase<Derived>& m) {
  return m.allFinite();
}

}  // namespace impetus
