#pragma once
/// \file
/// Bullet set-up shared by bench_peers (bullet.cpp) and bench_accuracy_peers (accuracy/bullet_world.cpp):
/// vectors to and from Bullet's, and the collision shape of a body.

#include "impetus/core/body.hpp"

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <memory>
#include <variant>

static_assert(sizeof(btScalar) == sizeof(double), "the peers need Bullet's double-precision build");

namespace impetus::peers {

inline btVector3 to_bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
inline Vec3 from_bt(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

/// The collision shape of a body, in its body frame (a capsule and a cylinder along local z, as Impetus's).
/// Bullet keeps a box's margin inside its half extents (so the geometry is Impetus's) and rounds its
/// corners by it: a thin box (a plank) gets a margin of at most a fifth of its half thickness instead of
/// the default 4 cm. A mesh is refused before (the callers check the shapes).
inline std::unique_ptr<btCollisionShape> make_bullet_shape(const RigidBody& b) {
  if (const auto* s = std::get_if<Sphere>(&b.shape)) return std::make_unique<btSphereShape>(s->radius);
  if (const auto* s = std::get_if<Box>(&b.shape)) {
    auto box = std::make_unique<btBoxShape>(to_bt(Vec3(0.5 * s->size)));
    box->setMargin(std::min(box->getMargin(), 0.2 * 0.5 * s->size.minCoeff()));
    return box;
  }
  if (const auto* s = std::get_if<Capsule>(&b.shape)) return std::make_unique<btCapsuleShapeZ>(s->radius, s->length);
  if (const auto* s = std::get_if<Cylinder>(&b.shape))
    return std::make_unique<btCylinderShapeZ>(btVector3(s->radius, s->radius, 0.5 * s->length));
  const Plane& p = std::get<Plane>(b.shape);
  // Both mean the solid n·x ≤ offset with the normal pointing out of it.
  return std::make_unique<btStaticPlaneShape>(to_bt(p.normal), p.offset);
}

}  // namespace impetus::peers
