// Isolated mesh import: the library starts impetus-mesh-import (assets/tools/mesh_import_helper.cpp) with
// posix_spawn, never fork, because the program embedding the engine may have threads; reads its reply
// and its standard error; and judges the outcome by how the process ended. POSIX only.

#include "import_process.hpp"

#include "assimp_reader.hpp"
#include "impetus/core/error.hpp"
#include "text.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

extern char** environ;  // POSIX leaves the declaration to the program

#ifndef IMPETUS_MESH_IMPORTER_SUBPATH
#error "IMPETUS_MESH_IMPORTER_SUBPATH must be defined by the build (see assets/CMakeLists.txt)"
#endif

namespace impetus::assets::detail {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
// Default memory limit (address space): a base for the program, assimp and a small scene, plus room
// proportional to the file, several times what a binary STL needs (its bytes, assimp's float vertices and
// normals, our double vertices before welding, the reply). A 228-byte glb that asked assimp for 1.5 GB
// (fuzz/regressions/mesh_glb) is stopped by the base.
constexpr std::uint64_t kBaseMemoryBytes = 1024 * kMiB;
constexpr std::uint64_t kMemoryPerFileByte = 16;
constexpr std::uint64_t kDefaultCpuSeconds = 60;
constexpr double kDefaultWallSeconds = 120.0;
constexpr std::size_t kStderrKept = 4096;  // bytes of the importer's standard error kept for messages

std::string what_importer() { return "the mesh importer (" + assimp_version() + ")"; }

// --- settings --------------------------------------------------------------------------------------

std::optional<double> positive_number(const fs::path& file, const char* variable, const char* unit) {
  const char* text = std::getenv(variable);
  if (text == nullptr || *text == '\0') return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(value > 0.0) || !std::isfinite(value))
    throw Error(file.string() + ": " + variable + "='" + text + "' is not a positive number of " + unit);
  return value;
}

// Its address locates libimpetus_assets.so for dladdr.
const char kLocator = 0;

// `<directory of libimpetus_assets.so>/impetus/libexec/impetus-mesh-import`: relative to this library, as
// the plugin host finds its plugins relative to its own, so it works in the build tree and in an
// installed, relocated prefix alike (canonical, so a symlinked library still finds the real folder).
fs::path default_importer() {
  Dl_info info{};
  if (dladdr(&kLocator, &info) == 0 || info.dli_fname == nullptr || info.dli_fname[0] == '\0') return {};
  std::error_code ec;
  const fs::path library = fs::canonical(info.dli_fname, ec);
  return (ec ? fs::absolute(info.dli_fname) : library).parent_path() / IMPETUS_MESH_IMPORTER_SUBPATH;
}

// --- descriptors and the process, each released on every path -----------------------------------

class Fd {
 public:
  Fd() = default;
  explicit Fd(int fd) : fd_(fd) {}
  Fd(Fd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  Fd& operator=(Fd&& other) noexcept {
    if (this != &other) {
      reset();
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() { reset(); }
  int get() const { return fd_; }
  void reset() {
    if (fd_ >= 0) ::close(fd_);  // not retried on EINTR: on Linux the descriptor is closed regardless
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

struct Pipe {
  Fd read, write;
};

// A close-on-exec pipe whose ends are not 0, 1 or 2 (a host may have closed its standard streams), so
// the child's dup2 onto its descriptors 1 and 2 cannot clobber one end with the other.
Pipe make_pipe(const std::string& label) {
  int ends[2];
  if (::pipe2(ends, O_CLOEXEC) != 0)
    throw Error(label + ": cannot start the mesh importer: pipe: " + std::strerror(errno));
  Pipe pipe{Fd(ends[0]), Fd(ends[1])};
  for (Fd* end : {&pipe.read, &pipe.write}) {
    if (end->get() > STDERR_FILENO) continue;
    const int moved = ::fcntl(end->get(), F_DUPFD_CLOEXEC, STDERR_FILENO + 1);
    if (moved < 0) throw Error(label + ": cannot start the mesh importer: fcntl: " + std::strerror(errno));
    *end = Fd(moved);
  }
  return pipe;
}

// The importer process: killed and reaped by the destructor unless reaped before.
class Child {
 public:
  explicit Child(pid_t pid) : pid_(pid) {}
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    wait(nullptr);
  }
  void kill() { ::kill(pid_, SIGKILL); }
  /// Blocks until the process ends. False when the status is not available (ECHILD: the host
  /// ignores SIGCHLD, so the system reaped it).
  bool wait(int* status) {
    int ignored = 0;
    for (;;) {
      const pid_t got = ::waitpid(pid_, status ? status : &ignored, 0);
      if (got == pid_) break;
      if (got < 0 && errno == EINTR) continue;
      pid_ = -1;
      return false;
    }
    pid_ = -1;
    return true;
  }
  /// Polls until the process ends or `deadline` passes; nullopt if still running.
  std::optional<bool> wait_until(Clock::time_point deadline, int* status) {
    auto pause = std::chrono::microseconds(50);
    for (;;) {
      const pid_t got = ::waitpid(pid_, status, WNOHANG);
      if (got == pid_) {
        pid_ = -1;
        return true;
      }
      if (got < 0 && errno != EINTR) {
        pid_ = -1;
        return false;
      }
      if (Clock::now() >= deadline) return std::nullopt;
      std::this_thread::sleep_for(pause);
      pause = std::min(pause * 2, std::chrono::microseconds(10000));
    }
  }

 private:
  pid_t pid_;
};

class SpawnSetup {
 public:
  SpawnSetup() {
    ::posix_spawn_file_actions_init(&actions);
    ::posix_spawnattr_init(&attributes);
  }
  ~SpawnSetup() {
    ::posix_spawn_file_actions_destroy(&actions);
    ::posix_spawnattr_destroy(&attributes);
  }
  SpawnSetup(const SpawnSetup&) = delete;
  SpawnSetup& operator=(const SpawnSetup&) = delete;
  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attributes;
};

pid_t spawn_importer(const IsolationSettings& settings, const std::vector<std::string>& arguments,
                     const Pipe& reply, const Pipe& errors, const std::string& label) {
  SpawnSetup setup;
  // stdin from /dev/null, stdout the reply pipe, stderr the error pipe.
  int failed = ::posix_spawn_file_actions_addopen(&setup.actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  failed = failed ? failed : ::posix_spawn_file_actions_adddup2(&setup.actions, reply.write.get(), STDOUT_FILENO);
  failed = failed ? failed : ::posix_spawn_file_actions_adddup2(&setup.actions, errors.write.get(), STDERR_FILENO);
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 34))
  // Nothing else: a descriptor the host forgot to mark close-on-exec stays out of the importer.
  failed = failed ? failed : ::posix_spawn_file_actions_addclosefrom_np(&setup.actions, STDERR_FILENO + 1);
#endif
  // Signals the host ignores or blocks (SIGPIPE, often) must not be ignored or blocked in the importer.
  sigset_t all, none;
  sigfillset(&all);
  sigdelset(&all, SIGKILL);
  sigdelset(&all, SIGSTOP);
  sigemptyset(&none);
  failed = failed ? failed : ::posix_spawnattr_setsigdefault(&setup.attributes, &all);
  failed = failed ? failed : ::posix_spawnattr_setsigmask(&setup.attributes, &none);
  failed = failed ? failed
                  : ::posix_spawnattr_setflags(&setup.attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  if (failed) throw Error(label + ": cannot start the mesh importer: posix_spawn setup: " + std::strerror(failed));

  const std::string program = settings.importer.string();
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(program.c_str()));
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  // The host's environment, plus transparent huge pages for malloc unless the host tunes glibc itself:
  // assimp's OBJ reader zero-fills a 16 MB stream buffer per import, which in a fresh process is 4096
  // page faults, half the cost of importing a small OBJ; with huge pages it is a handful.
  std::vector<char*> envp;
  for (char** entry = environ; *entry != nullptr; ++entry) envp.push_back(*entry);
  static char tunables[] = "GLIBC_TUNABLES=glibc.malloc.hugetlb=1";
  if (std::getenv("GLIBC_TUNABLES") == nullptr) envp.push_back(tunables);
  envp.push_back(nullptr);
  pid_t pid = -1;
  failed = ::posix_spawn(&pid, program.c_str(), &setup.actions, &setup.attributes, argv.data(), envp.data());
  if (failed)
    throw Error(label + ": cannot start the mesh importer '" + program + "' (" + settings.importer_origin +
                "): " + std::strerror(failed));
  return pid;
}

// --- reading -------------------------------------------------------------------------------------

struct Output {
  std::string reply;
  std::string errors;  // the last kStderrKept bytes
  bool timed_out = false;
  bool reply_too_long = false;
};

// Reads both pipes to their end, or until the deadline, or until the reply passes `max_reply` bytes.
Output read_output(Fd reply, Fd errors, Clock::time_point deadline, std::uint64_t max_reply,
                   const std::string& label) {
  Output out;
  pollfd fds[2] = {{reply.get(), POLLIN, 0}, {errors.get(), POLLIN, 0}};
  std::vector<char> buffer(1 << 16);
  while (fds[0].fd >= 0 || fds[1].fd >= 0) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) {
      out.timed_out = true;
      return out;
    }
    const int ready = ::poll(fds, 2, static_cast<int>(std::min<long long>(left, INT_MAX)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) throw Error(label + ": the mesh importer's output cannot be read: poll: " + std::strerror(errno));
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || fds[k].revents == 0) continue;
      const ssize_t n = ::read(fds[k].fd, buffer.data(), buffer.size());
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n <= 0) {  // end of file (or an error, which ends the stream the same way)
        (k == 0 ? reply : errors).reset();
        fds[k].fd = -1;
        continue;
      }
      std::string& text = k == 0 ? out.reply : out.errors;
      text.append(buffer.data(), static_cast<std::size_t>(n));
      if (k == 1 && text.size() > 2 * kStderrKept) text.erase(0, text.size() - kStderrKept);
      if (k == 0 && text.size() > max_reply) {
        out.reply_too_long = true;
        return out;
      }
    }
  }
  return out;
}

// The importer's last line on standard error, printable and short, as "; it said: '…'" (or nothing).
std::string last_words(const std::string& errors) {
  std::string text = errors;
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.pop_back();
  const std::size_t start = text.find_last_of('\n');
  std::string line = start == std::string::npos ? text : text.substr(start + 1);
  for (char& c : line)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) == 0x7f) c = '?';
  if (line.size() > 200) line = line.substr(0, 200) + "…";
  return line.empty() ? std::string() : "; it said: '" + line + "'";
}

std::string signal_name(int signal) {
  switch (signal) {
    case SIGABRT: return "SIGABRT";
    case SIGSEGV: return "SIGSEGV";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    case SIGILL: return "SIGILL";
    case SIGTRAP: return "SIGTRAP";
    case SIGSYS: return "SIGSYS";
    case SIGKILL: return "SIGKILL";
    case SIGTERM: return "SIGTERM";
    case SIGPIPE: return "SIGPIPE";
    case SIGXCPU: return "SIGXCPU";
    case SIGXFSZ: return "SIGXFSZ";
    default: return "signal " + std::to_string(signal);
  }
}

std::string mebibytes(std::uint64_t bytes) { return std::to_string(bytes / kMiB) + " MiB"; }

// The Error for an importer that ended with `status` (from waitpid) and wrote `output`.
[[noreturn]] void fail_by_status(const std::string& label, const IsolationSettings& settings, int status,
                                 const Output& output) {
  const std::string importer = what_importer();
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    if (signal == SIGXCPU)
      throw Error(label + ": " + importer + " used up its CPU time limit of " +
                  std::to_string(settings.limits.cpu_seconds) +
                  " s (IMPETUS_MESH_IMPORT_CPU_SECONDS) while reading the file and was stopped; the file is "
                  "malformed, or too large for the limit");
    if (signal == SIGKILL)
      throw Error(label + ": " + importer +
                  " was killed (signal 9, SIGKILL) while reading the file, by the system's out-of-memory killer "
                  "or another process" + last_words(output.errors));
    throw Error(label + ": " + importer + " crashed with signal " + std::to_string(signal) + " (" +
                signal_name(signal) +
                ") while reading the file; the file is malformed (the crash stayed in the importer's own "
                "process)" + last_words(output.errors));
  }
  const int code = WEXITSTATUS(status);
  if (code == kExitOutOfMemory)
    throw Error(label + ": " + importer + " ran out of memory while reading the file: it needed more than its limit of " +
                mebibytes(settings.limits.memory_bytes) +
                " (IMPETUS_MESH_IMPORT_MEMORY_MB); the file is malformed, or too large for the limit");
  if (code == kExitSetupFailed)
    throw Error(label + ": the mesh importer '" + settings.importer.string() +
                "' could not set up its limits or its reply" + last_words(output.errors));
  if (code == kExitUsage)
    throw Error(label + ": the mesh importer '" + settings.importer.string() +
                "' refused its command line: it is not from this build of Impetus" + last_words(output.errors));
  throw Error(label + ": " + importer + " exited with status " + std::to_string(code) +
              " without a complete reply" + last_words(output.errors));
}

}  // namespace

IsolationSettings isolation_settings(const fs::path& file, std::uintmax_t file_size) {
  IsolationSettings settings;
  if (const char* mode = std::getenv("IMPETUS_MESH_IMPORT"); mode != nullptr && *mode != '\0') {
    const std::string_view value(mode);
    if (value != "isolated" && value != "in-process")
      throw Error(file.string() + ": IMPETUS_MESH_IMPORT='" + std::string(value) +
                  "' is neither 'isolated' (the default) nor 'in-process'");
    settings.isolated = value == "isolated";
  }
  if (const char* path = std::getenv("IMPETUS_MESH_IMPORT_HELPER"); path != nullptr && *path != '\0') {
    settings.importer = path;
    settings.importer_origin = "set by IMPETUS_MESH_IMPORT_HELPER";
  } else {
    settings.importer = default_importer();
    settings.importer_origin = "looked for next to libimpetus_assets.so, in " + settings.importer.parent_path().string();
  }
  settings.limits.memory_bytes = kBaseMemoryBytes + kMemoryPerFileByte * file_size;
  if (const auto mib = positive_number(file, "IMPETUS_MESH_IMPORT_MEMORY_MB", "MiB"))
    settings.limits.memory_bytes = static_cast<std::uint64_t>(std::min(*mib, 1e12) * static_cast<double>(kMiB));
  settings.limits.cpu_seconds = kDefaultCpuSeconds;
  if (const auto seconds = positive_number(file, "IMPETUS_MESH_IMPORT_CPU_SECONDS", "seconds"))
    settings.limits.cpu_seconds = static_cast<std::uint64_t>(std::ceil(std::min(*seconds, 1e9)));
  settings.wall_seconds = kDefaultWallSeconds;
  if (const auto seconds = positive_number(file, "IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS", "seconds"))
    settings.wall_seconds = std::min(*seconds, 1e9);
  return settings;
}

ImportedMesh import_isolated(const fs::path& file, const ImportOptions& options, const IsolationSettings& settings) {
  const std::string label = file.string();
  if (settings.importer.empty() || ::access(settings.importer.c_str(), X_OK) != 0)
    throw Error(label + ": cannot import the mesh: the mesh importer program '" + settings.importer.string() +
                "' " + (settings.importer.empty() || errno == ENOENT ? "does not exist" : "cannot be run") + " (" +
                settings.importer_origin +
                "); reinstall Impetus, point IMPETUS_MESH_IMPORT_HELPER at the program, or set "
                "IMPETUS_MESH_IMPORT=in-process to import without isolation");
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(settings.wall_seconds));

  Pipe reply = make_pipe(label);
  Pipe errors = make_pipe(label);
  Child child(spawn_importer(settings, importer_arguments({file, options, settings.limits}), reply, errors, label));
  reply.write.reset();  // the child holds its copies; ours would keep the pipes from ever ending
  errors.write.reset();
  // A reply cannot be larger than the memory the importer built it in.
  const Output output =
      read_output(std::move(reply.read), std::move(errors.read), deadline, settings.limits.memory_bytes, label);

  int status = 0;
  std::optional<bool> ended;
  if (!output.timed_out && !output.reply_too_long) ended = child.wait_until(deadline, &status);
  if (!ended) {
    child.kill();
    child.wait(nullptr);
    if (output.reply_too_long)
      throw Error(label + ": " + what_importer() + " sent a reply longer than " +
                  mebibytes(settings.limits.memory_bytes) + " and was stopped");
    throw Error(label + ": " + what_importer() + " did not finish reading the file within " +
                number(settings.wall_seconds) +
                " s (IMPETUS_MESH_IMPORT_TIMEOUT_SECONDS) and was stopped; the file is malformed, or too large "
                "for the limit");
  }
  // *ended is false when the status is unknown (the host ignores SIGCHLD): then the reply decides.
  if (*ended && !(WIFEXITED(status) && WEXITSTATUS(status) == 0)) fail_by_status(label, settings, status, output);

  Reply decoded;
  try {
    decoded = decode_reply(output.reply);
  } catch (const ProtocolError& e) {
    throw Error(label + ": " + what_importer() + " sent a malformed reply: " + e.what() + last_words(output.errors));
  }
  if (!decoded.mesh) {
    // The importer's own message (assimp's reason, no triangles, …); it names the file, or is made to.
    if (decoded.error.rfind(label + ": ", 0) == 0) throw Error(decoded.error);
    throw Error(label + ": " + decoded.error);
  }
  decoded.mesh->file = file;
  return std::move(*decoded.mesh);
}

}  // namespace impetus::assets::detail
