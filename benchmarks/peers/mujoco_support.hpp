#pragma once
/// \file
/// MuJoCo set-up shared by bench_peers (mujoco.cpp) and bench_accuracy_peers (accuracy/mujoco_world.cpp):
/// a model compiled from an MJCF string through a virtual file system.

#include <mujoco/mujoco.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace impetus::peers {

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
