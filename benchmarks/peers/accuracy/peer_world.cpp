// Helpers shared by the three engines' translations of an Impetus scene (peer_world.hpp).
#include "peer_world.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <variant>

namespace impetus::peers::accuracy {

std::pair<Mat3, Vec3> principal_axes(const Mat3& inertia_body) {
  // Already diagonal (spheres, boxes, cylinders): keep the body frame as it is.
  const Mat3 off = inertia_body - Mat3(inertia_body.diagonal().asDiagonal());
  if (off.cwiseAbs().maxCoeff() <= 1e-14 * inertia_body.diagonal().cwiseAbs().maxCoeff())
    return {Mat3::Identity(), inertia_body.diagonal()};
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(0.5 * (inertia_body + inertia_body.transpose()));
  Mat3 v = solver.eigenvectors();
  if (v.determinant() < 0) v.col(2) = -v.col(2);
  return {v, solver.eigenvalues()};
}

double scene_restitution(std::span<const RigidBody> bodies) {
  double e = 0.0;
  for (const RigidBody& b : bodies) e = std::max(e, b.material.restitution);
  return e;
}

bool contact_free(const PeerScene& scene) { return scene.bodies.size() < 2; }

bool may_collide(const PeerScene& scene, std::size_t i, std::size_t j) {
  const RigidBody& a = scene.bodies[i];
  const RigidBody& b = scene.bodies[j];
  if (a.fixed && b.fixed) return false;
  if (!(a.collision_group & b.collision_mask) || !(b.collision_group & a.collision_mask)) return false;
  for (const Constraint& c : scene.constraints) {
    const bool joined = std::visit(
        [&](const auto& k) {
          return !k.collide && ((k.a == i && k.b == j) || (k.a == j && k.b == i));
        },
        c);
    if (joined) return false;
  }
  return true;
}

double pair_friction(std::span<const RigidBody> bodies, std::size_t i, std::size_t j) {
  return std::sqrt(bodies[i].material.friction * bodies[j].material.friction);
}

bool has_friction(const PeerScene& scene) {
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    for (std::size_t j = i + 1; j < scene.bodies.size(); ++j)
      if (pair_friction(scene.bodies, i, j) > 0.0 && may_collide(scene, i, j)) return true;
  return false;
}

std::string first_mesh(const PeerScene& scene) {
  for (const RigidBody& b : scene.bodies)
    if (std::holds_alternative<MeshShape>(b.shape)) return b.name;
  return "";
}

}  // namespace impetus::peers::accuracy
