#pragma once
// Running a shell command in the tests of the frictherm program (test_cli*.cpp, test_cli_mpi.cpp,
// test_cli_mpirun.cpp): its exit code and everything it printed.
#include <cstdio>
#include <string>

#include <sys/wait.h>

namespace frictherm::test {

struct Result {
  int code = -1;       // the exit code; -1 when the command could not start or ended by a signal
  std::string output;  // stdout and stderr together
};

/// Runs `cmd` with /bin/sh, its stderr joined to its stdout.
inline Result shell(const std::string& cmd) {
  Result r;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace frictherm::test
