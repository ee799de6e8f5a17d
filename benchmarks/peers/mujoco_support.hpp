#pragma once
/// \file
/// MuJoCo set-up shared by bench_peers (mujoco.cpp) and bench_accuracy_peers (accuracy/mujoco_world.cpp):
/// a model compiled from an MJCF string through a virtual file system, and the MJCF of a body's pose and
/// shape.

#include "impetus/core/body.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>

namespace impetus::peers {

/// A vector as MJCF writes it: three numbers, every digit.
inline std::string mjcf_vec(const Vec3& v) {
  std::ostringstream s;
  s.precision(17);
  s << v.x() << ' ' << v.y() << ' ' << v.z();
  return s.str();
}

/// A rotation as MJCF's quat="w x y z".
inline std::string mjcf_quat(const Mat3& r) {
  const Quat q = Quat(r).normalized();
  std::ostringstream s;
  s.precision(17);
  s << q.w() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z();
  return s.str();
}

/// The geom of a body as MJCF attributes (type, size; a plane's pose), in the body frame: a box's size is
/// its half extents, a capsule's and a cylinder's the radius and half the length (along local z, as
/// Impetus's). A mesh is refused before (the callers check the shapes).
inline std::string mjcf_geom(const RigidBody& b) {
  std::ostringstream x;
  x.precision(17);
  if (const auto* s = std::get_if<Sphere>(&b.shape)) {
    x << "type=\"sphere\" size=\"" << s->radius << "\"";
  } else if (const auto* s = std::get_if<Box>(&b.shape)) {
    x << "type=\"box\" size=\"" << mjcf_vec(0.5 * s->size) << "\"";
  } else if (const auto* s = std::get_if<Capsule>(&b.shape)) {
    x << "type=\"capsule\" size=\"" << s->radius << ' ' << 0.5 * s->length << "\"";
  } else if (const auto* s = std::get_if<Cylinder>(&b.shape)) {
    x << "type=\"cylinder\" size=\"" << s->radius << ' ' << 0.5 * s->length << "\"";
  } else {
    const Plane& p = std::get<Plane>(b.shape);
    // MuJoCo's plane is the solid below its local z = 0: zaxis = n, through the point offset·n.
    x << "type=\"plane\" size=\"0 0 1\" pos=\"" << mjcf_vec(p.offset * p.normal) << "\" zaxis=\"" << mjcf_vec(p.normal) << "\"";
  }
  return x.str();
}

/// Compiles `xml` (MJCF); throws std::runtime_error with MuJoCo's message if it does not compile.
inline mjModel* load_mjcf(const std::string& xml) {
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  const char* name = "peers.xml";
  if (mj_makeEmptyFileVFS(&vfs, name, static_cast<int>(xml.size())) != 0) throw std::runtime_error("MuJoCo VFS full");
  const int file = mj_findFileVFS(&vfs, name);
  std::copy(xml.begin(), xml.end(), static_cast<char*>(vfs.filedata[file]));
  char error[1000] = "";
  mjModel* model = mj_loadXML(name, &vfs, error, sizeof error);
  mj_deleteVFS(&vfs);
  if (!model) throw std::runtime_error(std::string("MuJoCo: ") + error);
  return model;
}

}  // namespace impetus::peers
