// The importer process's preparations and reply (see importer_process.hpp). POSIX only.

#include "importer_process.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <new>

namespace impetus::assets::detail {
namespace {

// Called by operator new when an allocation fails: under RLIMIT_AS that is the memory limit. assimp
// catches std::exception around its readers, so a std::bad_alloc would come back as a vague read
// error, or be half-handled; exiting at once gives the library an exact diagnosis.
void out_of_memory() {
  constexpr char message[] = "impetus-mesh-import: out of memory (an allocation failed under the memory limit)\n";
  [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, message, sizeof message - 1);
  ::_exit(kExitOutOfMemory);
}

// Sets a limit, never above the hard limit this process inherited (which it could not raise).
bool set_limit(int resource, rlim_t soft, rlim_t hard, const char* name) {
  rlimit limit{};
  if (::getrlimit(resource, &limit) == 0 && limit.rlim_max != RLIM_INFINITY) {
    soft = std::min(soft, limit.rlim_max);
    hard = std::min(hard, limit.rlim_max);
  }
  limit = {soft, hard};
  if (::setrlimit(resource, &limit) == 0) return true;
  std::fprintf(stderr, "impetus-mesh-import: cannot set %s: %s\n", name, std::strerror(errno));
  return false;
}

}  // namespace

int enter_importer_process(const ImporterLimits& limits) {
#ifdef __linux__
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // the library's thread waits for us; if it dies, so do we
#endif
  const int reply = ::fcntl(STDOUT_FILENO, F_DUPFD_CLOEXEC, 3);
  if (reply < 0 || ::dup2(STDERR_FILENO, STDOUT_FILENO) < 0) {
    std::fprintf(stderr, "impetus-mesh-import: cannot set up the reply channel: %s\n", std::strerror(errno));
    return -1;
  }
  const auto memory = static_cast<rlim_t>(limits.memory_bytes);
  const auto cpu = static_cast<rlim_t>(limits.cpu_seconds);
  if (!set_limit(RLIMIT_CORE, 0, 0, "RLIMIT_CORE") || !set_limit(RLIMIT_AS, memory, memory, "RLIMIT_AS") ||
      !set_limit(RLIMIT_CPU, cpu, cpu + 1, "RLIMIT_CPU"))
    return -1;
  std::set_new_handler(out_of_memory);
  return reply;
}

bool write_reply(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

}  // namespace impetus::assets::detail
