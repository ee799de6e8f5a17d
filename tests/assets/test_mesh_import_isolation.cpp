// Isolated mesh import (assets/src/import_process.cpp): the importer process gives the same meshes as
// importing in this process, bit for bit; every way it can fail — a crash, running out of memory, CPU
// time or wall-clock time, a malformed reply, a missing program — becomes an Error naming the file and
// what happened; and no child process or descriptor is left behind, whatever happened. The failures are
// provoked by fake_mesh_importer.cpp, which sets the real limits and then misbehaves on purpose.
#include "asset_test_support.hpp"

#include "impetus/assets/mesh_import.hpp"
#include "impetus/core/error.hpp"

#include <dirent.h>
#include <sys/time.h>
#include <sys/wait.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <optional>
#include <thread>
#include <tuple>
#include <vector>

namespace impetus::test {
namespace {

using assets::import_mesh;
using assets::ImportedMesh;
using assets::ImportOptions;

/// Sets environment variables for one scope and restores what was there before.
class ScopedEnv {
 public:
  ScopedEnv(std::initializer_list<std::pair<const char*, std::string>> values) {
    for (const auto& [name, value] : values) {
      const char* old = std::getenv(name);
      saved_.emplace_back(name, old ? std::optional<std::string>(old) : std::nullopt);
      ::setenv(name, value.c_str(), 1);
    }
  }
  ~ScopedEnv() {
    for (const auto& [name, value] : saved_) {
      if (value) ::setenv(name, value->c_str(), 1);
      else ::unsetenv(name);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::vector<std::pair<const char*, std::optional<std::string>>> saved_;
};

// The message of importing the tetrahedron through the fake importer in `mode`, with `extra` settings.
std::string fake_import_error(const std::string& mode,
                              std::initializer_list<std::pair<const char*, std::string>> extra = {}) {
  ScopedEnv fake({{"IMPETUS_MESH_IMPORT_HELPER", IMPETUS_FAKE_IMPORTER}, {"IMPETUS_FAKE_IMPORTER", mode}});
  ScopedEnv limits(extra);
  return error_of([] { import_mesh(mesh_path("tetrahedron.obj")); });
}

std::size_t open_descriptors() {
  std::size_t count = 0;
  DIR* dir = ::opendir("/proc/self/fd");
  if (dir == nullptr) return 0;
  while (::readdir(dir) != nullptr) ++count;
  ::closedir(dir);
  return count;
}

bool has_children() {
  int status = 0;
  return !(::waitpid(-1, &status, WNOHANG) < 0 && errno == ECHILD);
}

void expect_same(const ImportedMesh& isolated, const ImportedMesh& in_process) {
  EXPECT_EQ(isolated.file, in_process.file);
  EXPECT_EQ(isolated.format, in_process.format);
  EXPECT_EQ(isolated.file_unit, in_process.file_unit);
  EXPECT_EQ(isolated.warnings, in_process.warnings);
  ASSERT_EQ(isolated.parts.size(), in_process.parts.size());
  for (std::size_t p = 0; p < isolated.parts.size(); ++p) {
    EXPECT_EQ(isolated.parts[p].name, in_process.parts[p].name);
    EXPECT_EQ(isolated.parts[p].mesh.triangles, in_process.parts[p].mesh.triangles);
    ASSERT_EQ(isolated.parts[p].mesh.vertices.size(), in_process.parts[p].mesh.vertices.size());
    const auto& a = isolated.parts[p].mesh.vertices;
    const auto& b = in_process.parts[p].mesh.vertices;
    for (std::size_t v = 0; v < a.size(); ++v)  // bits, so NaN compares too
      EXPECT_EQ(std::memcmp(a[v].data(), b[v].data(), sizeof(double) * 3), 0) << "vertex " << v;
  }
}

const std::string kTetrahedron = mesh_path("tetrahedron.obj");

// The reply carries doubles as bits: the importer process and this one compute the same numbers.
TEST(MeshImportIsolation, GivesTheInProcessMeshBitForBit) {
  struct Case {
    std::string file;
    ImportOptions options;
  };
  std::vector<Case> cases;
  for (const char* name : {"l_bracket.obj", "l_bracket.stl", "l_bracket_ascii.stl", "l_bracket.ply", "l_bracket_ascii.ply",
                           "l_bracket.off", "l_bracket.gltf", "l_bracket.glb", "l_bracket_cm.dae", "l_bracket_mm.stl",
                           "mirrored_box.gltf", "broken/nan_cube.obj"})
    cases.push_back({mesh_path(name), {}});
  cases.push_back({mesh_path("two_boxes.gltf"), {0.25, assets::PartMode::separate, assets::UnitMode::convert}});
  cases.push_back({mesh_path("l_bracket_cm.dae"), {1.0 / 3.0, assets::PartMode::merge, assets::UnitMode::as_written}});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const ImportedMesh isolated = import_mesh(c.file, c.options);
    ScopedEnv in_process({{"IMPETUS_MESH_IMPORT", "in-process"}});
    expect_same(isolated, import_mesh(c.file, c.options));
  }
}

TEST(MeshImportIsolation, AssimpErrorsComeBackAsTheyAre) {
  const std::string readme = std::string(IMPETUS_SOURCE_DIR) + "/README.md";
  EXPECT_EQ(error_of([&] { import_mesh(readme); }).rfind(readme + ": assimp cannot read it: ", 0), 0u);
  EXPECT_EQ(error_of([] { import_mesh(mesh_path("broken/no_triangles.obj")); }),
            mesh_path("broken/no_triangles.obj") + ": the file holds no triangles (only 2 points or lines)");
}

TEST(MeshImportIsolation, ACrashIsAnErrorNamingTheSignal) {
  EXPECT_EQ(fake_import_error("segv"),
            kTetrahedron +
                ": the mesh importer (assimp 5.2) crashed with signal 11 (SIGSEGV) while reading the file; the file is "
                "malformed (the crash stayed in the importer's own process)");
  // What the importer said last is kept (assimp prints its failed assertion before aborting).
  EXPECT_EQ(fake_import_error("abort"),
            kTetrahedron +
                ": the mesh importer (assimp 5.2) crashed with signal 6 (SIGABRT) while reading the file; the file is "
                "malformed (the crash stayed in the importer's own process); it said: 'fake importer: an assertion "
                "failed'");
}

TEST(MeshImportIsolation, RunningOutOfMemoryIsAnErrorNamingTheLimit) {
  EXPECT_EQ(fake_import_error("oom", {{"IMPETUS_MESH_IMPORT_MEMORY_MB", "64"}}),
            kTetrahedron +
                ": the mesh importer (assimp 5.2) ran out of memory while reading the file: it needed more than its "
                "limit of 64 MiB (IMPETUS_MESH_IMPORT_MEMORY_MB); the file is malformed, or too large for the limit");
}

TEST(MeshImportIsolation, RunningOutOfCpuTimeIsAnErrorNamingTheLimit) {
  EXPECT_EQ(fake_import_error("spin", {{"IMPETUS_MESH_IMPORT_CPU_SECONDS", "1"}}),
            kTetrahedron +
                ": the mesh importer (assimp 5.2) used up its CPU time limit of 1 s (IMPETUS_MESH_IMPORT_CPU_SECONDS) "
                "while reading the file and was stopped; the file is malformed, or too large for the limit");
}

TEST(MeshImportIsolation, TakingTooLongIsAnErrorNamingTheTimeout) {
  for (const char* mode : {"hang", "linger"}) {  // linger: replied, but never exits
    SCOPED_TRACE(mode);
    const auto start = std::chrono::steady_clock::now();
    EXPECT_EQ(fake_import_error(mode, {{"IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS", "0.3"}}),
              kTetrahedron +
                  ": the mesh importer (assimp 5.2) did not finish reading the file within 0.3 s "
                  "(IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS) and was stopped; the file is malformed, or too large for the "
                  "limit");
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  }
}

TEST(MeshImportIsolation, AMalformedReplyIsRefused) {
  const std::string prefix = kTetrahedron + ": the mesh importer (assimp 5.2) sent a malformed reply: ";
  const std::map<std::string, std::string> expected = {
      {"garbage", "no magic word where one belongs (at byte 0 of 19)"},
      {"truncated", "it announces 4 vertices, more than its remaining 45 bytes hold (at byte 58 of 103)"},
      {"bad-index", "a triangle index 7 beyond the part's 4 vertices (at byte 202 of 206)"},
      // Refused before anything is allocated for them.
      {"huge-count", "it announces 4000000000 vertices, more than its remaining 148 bytes hold (at byte 58 of 206)"},
  };
  for (const auto& [mode, why] : expected) {
    SCOPED_TRACE(mode);
    EXPECT_EQ(fake_import_error(mode), prefix + why);
  }
  EXPECT_EQ(fake_import_error("flood", {{"IMPETUS_MESH_IMPORT_MEMORY_MB", "8"}}),
            kTetrahedron + ": the mesh importer (assimp 5.2) sent a reply longer than 8 MiB and was stopped");
  EXPECT_EQ(fake_import_error("exit-7"),
            kTetrahedron + ": the mesh importer (assimp 5.2) exited with status 7 without a complete reply");
  EXPECT_EQ(fake_import_error("error"), kTetrahedron + ": something is wrong with it");
}

TEST(MeshImportIsolation, AMissingImporterNamesWhereItWasLookedFor) {
  ScopedEnv missing({{"IMPETUS_MESH_IMPORT_HELPER", "/nonexistent/impetus-mesh-import"}});
  EXPECT_EQ(error_of([] { import_mesh(kTetrahedron); }),
            kTetrahedron +
                ": cannot import the mesh: the mesh importer program '/nonexistent/impetus-mesh-import' does not exist "
                "(set by IMPETUS_MESH_IMPORT_HELPER); reinstall Impetus, point IMPETUS_MESH_IMPORT_HELPER at the "
                "program, or set IMPETUS_MESH_IMPORT=in-process to import without isolation");
}

TEST(MeshImportIsolation, SettingsAreChecked) {
  for (const auto& [name, value, expected] :
       std::vector<std::tuple<const char*, const char*, std::string>>{
           {"IMPETUS_MESH_IMPORT", "sandbox", "IMPETUS_MESH_IMPORT='sandbox' is neither 'isolated' (the default) nor 'in-process'"},
           {"IMPETUS_MESH_IMPORT_MEMORY_MB", "-5", "IMPETUS_MESH_IMPORT_MEMORY_MB='-5' is not a positive number of MiB"},
           {"IMPETUS_MESH_IMPORT_CPU_SECONDS", "soon", "IMPETUS_MESH_IMPORT_CPU_SECONDS='soon' is not a positive number of seconds"},
           {"IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS", "0", "IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS='0' is not a positive number of seconds"}}) {
    ScopedEnv bad({{name, value}});
    EXPECT_EQ(error_of([] { import_mesh(kTetrahedron); }), kTetrahedron + ": " + expected);
  }
}

// Whatever the importer did, no child process stays behind (not even a zombie) and no descriptor stays open.
TEST(MeshImportIsolation, LeavesNoProcessOrDescriptorBehind) {
  ASSERT_FALSE(has_children());
  const std::size_t before = open_descriptors();
  for (const char* mode : {"ok", "segv", "garbage", "exit-7", "linger", "flood"})
    fake_import_error(mode, {{"IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS", "0.2"}, {"IMPETUS_MESH_IMPORT_MEMORY_MB", "8"}});
  import_mesh(kTetrahedron);
  EXPECT_EQ(open_descriptors(), before);
  EXPECT_FALSE(has_children());
}

// A host whose signals interrupt system calls (a profiler's timer, say): the import resumes each one.
TEST(MeshImportIsolation, SignalsInTheHostDoNotDisturbTheImport) {
  struct sigaction action {}, old {};
  action.sa_handler = [](int) {};
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: poll, read and waitpid fail with EINTR
  ASSERT_EQ(::sigaction(SIGALRM, &action, &old), 0);
  itimerval every_ms{{0, 1000}, {0, 1000}}, off{};
  ::setitimer(ITIMER_REAL, &every_ms, nullptr);
  EXPECT_EQ(fake_import_error("slow-ok"), "(no error)");
  ::setitimer(ITIMER_REAL, &off, nullptr);
  ::sigaction(SIGALRM, &old, nullptr);
}

// A host that ignores SIGPIPE or SIGCHLD: the importer still gets default signals (a crash is still a
// crash), and with SIGCHLD ignored the system reaps it, so a complete reply is taken on its own.
TEST(MeshImportIsolation, HostSignalDispositionsDoNotLeakIntoTheImporter) {
  const auto old_pipe = std::signal(SIGPIPE, SIG_IGN);
  EXPECT_NE(fake_import_error("segv").find("crashed with signal 11 (SIGSEGV)"), std::string::npos);
  std::signal(SIGPIPE, old_pipe);
  const auto old_child = std::signal(SIGCHLD, SIG_IGN);
  EXPECT_EQ(import_mesh(kTetrahedron).parts.at(0).mesh.triangles.size(), 4u);
  EXPECT_NE(fake_import_error("garbage").find("sent a malformed reply"), std::string::npos);
  std::signal(SIGCHLD, old_child);
}

// posix_spawn, not fork: safe from a program with threads, and imports may run concurrently.
TEST(MeshImportIsolation, ThreadsImportConcurrently) {
  std::vector<std::size_t> triangles(4, 0);
  std::vector<std::thread> threads;
  for (std::size_t k = 0; k < triangles.size(); ++k)
    threads.emplace_back([&triangles, k] {
      for (int repeat = 0; repeat < 5; ++repeat) triangles[k] += import_mesh(mesh_path("icosphere_2.stl")).parts[0].mesh.triangles.size();
    });
  for (std::thread& thread : threads) thread.join();
  for (std::size_t count : triangles) EXPECT_EQ(count, 5u * 320u);
}

}  // namespace
}  // namespace impetus::test
