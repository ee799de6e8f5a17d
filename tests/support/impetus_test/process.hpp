#pragma once
// Running a command as a user would, for the tests of the `impetus` tool: its exit status and everything
// it printed.
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace impetus::test {

struct CommandResult {
  int status = -1;  // exit status; -1 if it did not exit normally
  std::string out;  // stdout (and stderr, when joined)
};

/// Runs `command` through the shell and reads its stdout; stderr goes to `stderr_to` (a shell redirection
/// target: "&1" joins it to stdout, "/dev/null" drops it, a file name keeps it there).
inline CommandResult run_shell(const std::string& command, const std::string& stderr_to = "&1") {
  CommandResult r;
  FILE* pipe = popen((command + " 2>" + stderr_to).c_str(), "r");
  if (!pipe) return r;
  char buffer[4096];
  std::size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) r.out.append(buffer, n);
  const int raw = pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

}  // namespace impetus::test
